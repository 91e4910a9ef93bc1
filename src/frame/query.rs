//! How it works: the host's questions about the ground, answered on the CPU from the data the GPU
//! draws, with no GPU round trip and the same answer every time. Two grounds are asked about: the
//! finest data's (`ground_at`: the finest mesh's triangle over a point, what seeds stand on and
//! a camera is lifted above), and the one the last frame drew (`drawn_ground`: each drawn node
//! rebuilt from the instance and the height tile its vertex shader read, morph and Earth placing
//! included; what a pick must meet, and what a camera should not sink through at the current
//! level of detail). The land cover at a point is its source texel's class. The plants near a
//! point are the seeded world's, judged by the exact oracle from the host's camera (the same
//! patterns, classes, rules and reach as pass 3): every plant the view grows there, or only
//! those pass 3 keeps.

use std::collections::HashMap;
use std::sync::Arc;

use glam::{DVec2, DVec3};

use super::{RenderError, Renderer};
use crate::camera::Camera;
use crate::dataset::lcc::LCC_SOURCE_LEVEL;
use crate::reference::oracle::{Culls, OracleSeed, seeds_within};
use crate::reference::terrain::{DrawnGround, DrawnQuadrant};

/// The finest data's ground at a grid point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundAt {
    /// Height above the datum, metres.
    pub height_m: f64,
    /// The unit normal of the finest mesh's triangle there, in grid axes (z up).
    pub normal: DVec3,
}

/// A plant standing near a point (`Renderer::plants_near`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plant {
    /// Its ring-0 cell: with its rank, its identity, as pass 3's records name it
    /// (`SeedRecord::address`, `rank`).
    pub address: [i64; 2],
    /// Its rank in the cell's pattern.
    pub rank: u32,
    /// Its species' variant: an index into `ClassTable::species` (its model).
    pub species: u32,
    /// Where it stands: grid x and y, and the drawn ground's height there (its trunk sinks below
    /// it by `seeds.sink_fraction` of its height), metres.
    pub position_grid_m: DVec3,
    /// Its height, metres.
    pub height_m: f64,
    /// The radius of its bounding sphere (crown and trunk), metres: its species' radius per metre
    /// of height, times its height.
    pub radius_m: f64,
    /// Its draw LOD from this camera (0 nearest: meshes).
    pub lod: u32,
}

/// Which plants `plants_near` answers with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Plants {
    /// Every plant the view grows there, seen or not (for collision): class, rules and reach.
    Grown,
    /// Those pass 3 keeps from this camera: also inside the view and not hidden by the ground.
    Selected,
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
        let viewport = [self.settings.render.width, self.settings.render.height];
        Ok(Some(DrawnGround::new(&quadrants, &last.terrain, (last.clip_from_rel_m, viewport))))
    }

    /// The plants within `radius_m` of grid point `centre_grid_m` as the view from `camera` grows
    /// them (its density, classes and reach by size; a seed fading out at the end of its reach
    /// counts while it is drawn at all), or only those pass 3 keeps; sorted by (address, rank).
    /// Judged exactly on the CPU (f64), from the dataset's packs: no GPU round trip. `None`
    /// without land cover.
    pub fn plants_near(
        &self,
        camera: &Camera,
        centre_grid_m: [f64; 2],
        radius_m: f64,
        plants: Plants,
    ) -> Result<Option<Vec<Plant>>, RenderError> {
        let Some(inputs) = self.oracle_inputs(camera) else { return Ok(None) };
        let culls = match plants {
            Plants::Grown => Culls::GROWN,
            Plants::Selected => Culls::SELECTION,
        };
        let seeds = seeds_within(&inputs, culls, DVec2::from(centre_grid_m), radius_m)?;
        let radius_per_height = |s: &OracleSeed| {
            inputs.tables.species.get(s.species as usize).map_or(0.0, |k| f64::from(k.radius_per_height))
        };
        Ok(Some(
            seeds
                .iter()
                .map(|s| Plant {
                    address: s.address,
                    rank: s.rank,
                    species: s.species,
                    position_grid_m: DVec2::from(s.position_grid_m).extend(s.ground_m),
                    height_m: s.height_m,
                    radius_m: s.height_m * radius_per_height(s),
                    lod: s.lod,
                })
                .collect(),
        ))
    }
}
