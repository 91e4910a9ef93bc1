//! How it works: the synthetic dataset's three layers, each a spec and a source that evaluates the
//! world at the texels of any window, and the manifest that describes them. `synthesize` writes
//! them in one process; `parts` cuts them into partitions. Both take the heights' range from the
//! written pack's top tile, whose range spans every sample beneath it.

use std::path::Path;

use indicatif::ProgressBar;

use super::{
    CLASS_SCHEME, CRS_DEFINITION, IMAGERY_PER_SPACING, LANDCOVER_NODATA, LANDCOVER_PER_SPACING, MAX_SIZE,
    Painter, SynthError, SynthParams, Terrain,
};
use crate::classes::ClassTable;
use crate::dataset::lcc::{LccCoding, lcc_pyramid, scan_codes};
use crate::dataset::{
    CellLayer, Crs, FORMAT_VERSION, HeightLayer, LandcoverLayer, LayerSpec, Manifest, Pack, Texel, Window,
};

/// File name of the height layer's pack in the dataset folder.
pub const HEIGHT_PACK: &str = "height.pack";
/// File name of the imagery layer's pack in the dataset folder.
pub const IMAGERY_PACK: &str = "imagery.pack";
/// File name of the land-cover layer's pack in the dataset folder.
pub const LANDCOVER_PACK: &str = "landcover.pack";

/// The layers of one synthetic dataset: what each stores and where its texels come from.
pub struct Layers {
    params: SynthParams,
    terrain: Terrain,
    painter: Painter,
    /// The heights' spec.
    pub height: LayerSpec,
    /// The imagery's spec.
    pub imagery: LayerSpec,
    /// Texels of the land cover's source grid (the LCC quadtree's level 1).
    pub class_texels: [u32; 2],
}

impl Layers {
    /// The parameters the layers were made from.
    pub fn params(&self) -> &SynthParams {
        &self.params
    }

    /// The layers `params` describe, after checking them.
    pub fn new(params: &SynthParams) -> Result<Self, SynthError> {
        let &SynthParams { size, spacing_m, origin_m, water_level_m, .. } = params;
        if !(1..=MAX_SIZE).contains(&size) {
            return Err(SynthError::Size(size));
        }
        if !(spacing_m.is_finite() && spacing_m > 0.0) {
            return Err(SynthError::Spacing(spacing_m));
        }
        if !(origin_m.iter().all(|v| v.is_finite()) && water_level_m.is_finite()) {
            return Err(SynthError::NotFinite(origin_m, water_level_m));
        }
        let terrain = params.terrain();
        Ok(Self {
            painter: Painter::new(params.seed, &terrain),
            terrain,
            params: params.clone(),
            height: LayerSpec::heights([size; 2]),
            imagery: LayerSpec::imagery([size * IMAGERY_PER_SPACING; 2]),
            class_texels: [size * LANDCOVER_PER_SPACING; 2],
        })
    }

    fn texel_m(&self) -> f64 {
        self.params.spacing_m / f64::from(IMAGERY_PER_SPACING)
    }

    fn class_m(&self) -> f64 {
        self.params.spacing_m / f64::from(LANDCOVER_PER_SPACING)
    }

    /// Height samples of window `w`, metres.
    pub fn heights(&self, w: Window) -> Result<Vec<f32>, String> {
        let spacing_m = self.params.spacing_m;
        Ok(grid(w, |i, j| self.terrain.height_m(f64::from(i) * spacing_m, f64::from(j) * spacing_m) as f32))
    }

    /// Imagery texels of window `w`, sRGB.
    pub fn paint(&self, w: Window) -> Result<Vec<[u8; 4]>, String> {
        Ok(self.painter.paint_window(&self.terrain, w, self.params.spacing_m, self.texel_m()))
    }

    /// Land-cover codes of window `w` of the source grid.
    pub fn classify(&self, w: Window) -> Result<Vec<u8>, String> {
        Ok(cells(w, self.params.spacing_m, self.class_m(), |x_m, y_m| self.terrain.ground(x_m, y_m).class))
    }

    /// The land cover's coding: a palette of the codes that occur, from one pass over them.
    pub fn coding(&self, progress: &ProgressBar) -> Result<LccCoding, SynthError> {
        let classify = |w: Window| self.classify(w);
        Ok(LccCoding::for_codes(scan_codes(self.class_texels, &classify, progress)?.present())?)
    }

    /// The heights' range, from the top tile of the height pack at `path`.
    pub fn height_range(&self, path: &Path) -> Result<[f32; 2], SynthError> {
        let pack = Pack::open(path)?;
        let top = pack.tile_count().saturating_sub(1);
        Ok(pack.tile_range(top)?.unwrap_or([0.0; 2]))
    }

    /// The manifest of these layers, the land cover coded by `coding`.
    pub fn manifest(&self, [min_m, max_m]: [f32; 2], coding: LccCoding) -> Result<Manifest, SynthError> {
        let table = ClassTable::load(CLASS_SCHEME)?;
        let SynthParams { size, seed, spacing_m, origin_m, water_level_m, .. } = self.params;
        let cell_layer = |pack: &str, texel_m: f64, spec: &LayerSpec, format: &str| CellLayer {
            pack: pack.into(),
            texel_m,
            pyramid: spec.pyramid,
            mips: spec.mips,
            format: format.into(),
            source: format!("synthetic (seed {seed})"),
        };
        Ok(Manifest {
            format_version: FORMAT_VERSION,
            name: "synthetic".into(),
            crs: Crs {
                definition: CRS_DEFINITION.into(),
                note: format!(
                    "terramp-data synth: size {size}, seed {seed}, spacing {spacing_m} m, water level {water_level_m} m"
                ),
            },
            origin_m,
            height: HeightLayer {
                pack: HEIGHT_PACK.into(),
                spacing_m,
                pyramid: self.height.pyramid,
                min_m,
                max_m,
                step_m: None,
                filled_samples: 0,
                valid_mask_pack: None,
            },
            imagery: Some(cell_layer(IMAGERY_PACK, self.texel_m(), &self.imagery, "rgba8 srgb")),
            landcover: Some(LandcoverLayer {
                layer: CellLayer {
                    pack: LANDCOVER_PACK.into(),
                    texel_m: 0.5 * self.class_m(),
                    pyramid: lcc_pyramid(self.class_texels),
                    mips: 1,
                    format: coding.format_name(),
                    source: format!("synthetic (seed {seed})"),
                },
                coding,
                classes: table.names(),
                scheme: table.scheme,
                nodata_code: LANDCOVER_NODATA,
            }),
            vegetation: None,
            earth: None,
        })
    }
}

/// The window's texels from `f(i, j)`, south row first.
fn grid<T: Texel>(w: Window, f: impl Fn(u32, u32) -> T) -> Vec<T> {
    let mut out = Vec::with_capacity(w.width as usize * w.height as usize);
    for j in w.y0..w.y0 + w.height {
        out.extend((w.x0..w.x0 + w.width).map(|i| f(i, j)));
    }
    out
}

/// The window's cell texels from `f(x_m, y_m)` at their centres in grid space, where cells of
/// `texel_m` tile the DEM's pixel area from half a `spacing_m` south-west of sample (0, 0).
fn cells<T: Texel>(w: Window, spacing_m: f64, texel_m: f64, f: impl Fn(f64, f64) -> T) -> Vec<T> {
    let centre = |i: u32| (f64::from(i) + 0.5) * texel_m - 0.5 * spacing_m;
    grid(w, |i, j| f(centre(i), centre(j)))
}
