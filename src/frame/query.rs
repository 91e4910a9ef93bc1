//! How it works: the host's questions about the ground, answered on the CPU from the data the GPU
//! draws, with no GPU round trip and the same answer every time. Two grounds are asked about: the
//! finest data's (`ground_at`: the finest mesh's triangle over a point, what seeds stand on and
//! a camera is lifted above), and the one the last frame drew (`drawn_ground`: each drawn node
//! rebuilt from the instance and the height tile its vertex shader read, morph and Earth placing
//! included; what a pick must meet, and what a camera should not sink through at the current
//! level of detail). The land cover at a point is its source texel's class.

use std::collections::HashMap;
use std::sync::Arc;

use glam::DVec3;

use super::{RenderError, Renderer};
use crate::dataset::lcc::LCC_SOURCE_LEVEL;
use crate::reference::terrain::{DrawnGround, DrawnQuadrant};

/// The finest data's ground at a grid point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundAt {
    /// Height above the datum, metres.
    pub height_m: f64,
    /// The unit normal of the finest mesh's triangle there, in grid axes (z up).
    pub normal: DVec3,
}

impl Renderer {
    /// The ground at grid point (`x_m`, `y_m`) on the finest data: the height and normal of the
    /// finest mesh's triangle over it (`dataset::surface`), clamped to the dataset. Reads at most
    /// four height tiles from the packs.
    pub fn ground_at(&self, x_m: f64, y_m: f64) -> Result<GroundAt, RenderError> {
        let (height_m, slope) = self.dataset.ground_at(x_m, y_m, 0)?;
        let spacing_m = self.dataset.manifest.height.spacing_m;
        let normal = DVec3::new(-slope[0] / spacing_m, -slope[1] / spacing_m, 1.0).normalize();
        Ok(GroundAt { height_m, normal })
    }

    /// The land-cover class (its source code) at grid point (`x_m`, `y_m`), clamped to the
    /// layer; `None` where the dataset has no land cover, or no class there.
    pub fn land_cover_at(&self, x_m: f64, y_m: f64) -> Result<Option<u8>, RenderError> {
        let (Some(layer), Some(coding)) = (&self.dataset.manifest.landcover, self.dataset.lcc_coding())
        else {
            return Ok(None);
        };
        let texel_m = layer.layer.texel_m;
        let q = [x_m, y_m].map(|v| (v / texel_m).floor().max(0.0) as u32);
        let index = self.dataset.landcover_index(LCC_SOURCE_LEVEL, q)?;
        Ok(coding.code_of(index))
    }

    /// The ground the last frame drew, rebuilt on the CPU for picks (`DrawnGround::pick_pixel`,
    /// `pick`) and heights (`at_grid`); `None` before the first frame. Reads the height tiles the
    /// frame's nodes read (each once); answers about that frame until it is asked again.
    pub fn drawn_ground(&self) -> Result<Option<DrawnGround>, RenderError> {
        let Some(last) = &self.last else { return Ok(None) };
        let mut tiles = HashMap::new();
        let mut quadrants = Vec::new();
        let b = &last.batches;
        for q in 0..4 {
            for ((node, earth), source) in b.by_quadrant[q].iter().zip(&b.earth[q]).zip(&b.sources[q]) {
                let tile = match tiles.get(&source.tile) {
                    Some(tile) => Arc::clone(tile),
                    None => {
                        let tile = Arc::new(self.dataset.height_tile(source.tile)?);
                        tiles.insert(source.tile, Arc::clone(&tile));
                        tile
                    }
                };
                quadrants.push(DrawnQuadrant {
                    node: *node,
                    earth: *earth,
                    quadrant: q,
                    origin_grid_m: source.origin_grid_m,
                    tile,
                });
            }
        }
        let placing = self.placing.exact(last.camera_grid_m);
        let viewport = [self.settings.render.width, self.settings.render.height];
        Ok(Some(DrawnGround::new(&quadrants, &last.terrain, placing, (last.clip_from_rel_m, viewport))))
    }
}
