//! How it works: heights are built in passes over the DEM grid, each block by block or tile by
//! tile, so memory stays flat. The scan reads the whole grid once for what tiles cannot know
//! alone: the range of the valid heights, the voids (and, for a warped DEM, which of them lie
//! beyond the source's edge rather than in it), and the coarse summary the void fill falls back
//! on. The tile pass writes the height pack, filling each window's voids (`fill`). When there were
//! voids, a last pass writes the validity mask pack, reading again only the windows with voids.

use std::collections::HashSet;
use std::sync::Mutex;

use anyhow::{Context, Result, bail};
use indicatif::ProgressBar;
use terramp::dataset::{HeightLayer, LayerSpec, Staging, Window, write_layer};

use super::fill::{CoarseBuilder, VoidFill};
use super::raster::GridRaster;

/// Samples per side of the blocks the scan reads.
const SCAN_BLOCK: u32 = 1024;
pub const HEIGHT_PACK: &str = "height.pack";
pub const VALID_MASK_PACK: &str = "height_valid.pack";

/// What the scan learns about the DEM on the dataset grid.
pub struct HeightScan {
    pub range_m: [f32; 2],
    /// Voids inside the source's footprint: nodata in the source itself.
    pub source_voids: u64,
    /// Voids outside it: grid samples the source does not reach (corners of a reprojected DEM).
    pub beyond_edge: u64,
    /// The fill, when there is anything to fill.
    pub fill: Option<VoidFill>,
}

/// Where the scan learns whether a void lies in the source or beyond its edge.
pub enum Footprint {
    /// The grid is the source's own: every void is the source's nodata.
    Whole,
    /// The source has no nodata: every void lies beyond its edge.
    NoNodata,
    /// The DEM read as if it had no nodata: `NaN` there means beyond the edge.
    Coverage(GridRaster),
}

/// Reads the whole DEM grid once, block by block.
pub fn scan(dem: &GridRaster, footprint: &Footprint, progress: &ProgressBar) -> Result<HeightScan> {
    let size = dem.grid.size;
    let blocks = size.map(|n| n.div_ceil(SCAN_BLOCK));
    progress.set_length(u64::from(blocks[0] * blocks[1]));
    let mut coarse = CoarseBuilder::new(size);
    let (mut range_m, mut source_voids, mut beyond_edge) = ([f32::INFINITY, f32::NEG_INFINITY], 0, 0);
    for by in 0..blocks[1] {
        for bx in 0..blocks[0] {
            let (x0, y0) = (bx * SCAN_BLOCK, by * SCAN_BLOCK);
            let window =
                Window { x0, y0, width: SCAN_BLOCK.min(size[0] - x0), height: SCAN_BLOCK.min(size[1] - y0) };
            let heights = dem
                .read_f32(window)
                .map_err(anyhow::Error::msg)
                .with_context(|| format!("scanning the DEM {}", dem.path.display()))?;
            let mut voids = Vec::new();
            for (k, &height_m) in heights.iter().enumerate() {
                let (x, y) = (x0 + k as u32 % window.width, y0 + k as u32 / window.width);
                if height_m.is_nan() {
                    voids.push(k);
                } else {
                    coarse.add(x, y, height_m);
                    range_m = [range_m[0].min(height_m), range_m[1].max(height_m)];
                }
            }
            let in_source = count_in_source(&voids, window, footprint)?;
            source_voids += in_source;
            beyond_edge += voids.len() as u64 - in_source;
            progress.inc(1);
        }
    }
    let Some(coarse) = coarse.finish() else {
        bail!("{}: the DEM holds no valid height at all", dem.path.display());
    };
    let fill = (source_voids + beyond_edge > 0).then(|| VoidFill::new(size, coarse, range_m));
    Ok(HeightScan { range_m, source_voids, beyond_edge, fill })
}

/// How many of the `voids` (indices into `window`) lie inside the source's footprint.
fn count_in_source(voids: &[usize], window: Window, footprint: &Footprint) -> Result<u64> {
    Ok(match footprint {
        _ if voids.is_empty() => 0,
        Footprint::Whole => voids.len() as u64,
        Footprint::NoNodata => 0,
        Footprint::Coverage(coverage) => {
            let covered = coverage
                .read_f32(window)
                .map_err(anyhow::Error::msg)
                .context("scanning the DEM's footprint")?;
            voids.iter().filter(|&&k| !covered[k].is_nan()).count() as u64
        }
    })
}

/// Writes the height pack (and the validity mask pack when the DEM had voids).
pub fn write(
    dem: &GridRaster,
    scan: &HeightScan,
    spacing_m: f64,
    staging: &Staging,
    bars: [&ProgressBar; 2],
) -> Result<HeightLayer> {
    let spec = LayerSpec::heights(dem.grid.size);
    // The windows the height pass found void-free: the mask pass (same pyramid, so the same
    // windows) writes ones there without reading, and so warps only the windows with voids again.
    let void_free = Mutex::new(HashSet::new());
    let heights = |window: Window| -> Result<Vec<f32>, String> {
        let heights = dem.read_f32(window)?;
        match &scan.fill {
            Some(fill) if heights.iter().any(|h| h.is_nan()) => {
                Ok(fill.fill(window, &dem.read_f32(fill.padded(window))?))
            }
            _ => {
                void_free.lock().map_err(|_| "a height thread panicked")?.insert(window);
                Ok(heights)
            }
        }
    };
    write_layer(&staging.path(HEIGHT_PACK), &spec, heights, bars[0]).context("writing the height pack")?;
    let valid_mask_pack = if scan.fill.is_some() {
        // Decimation keeps the mask exact at every level: a coarse sample is a fine one.
        let mask_spec = LayerSpec::valid_mask(dem.grid.size);
        let valid = |window: Window| -> Result<Vec<u8>, String> {
            if void_free.lock().map_err(|_| "a mask thread panicked")?.contains(&window) {
                return Ok(vec![1; (window.width * window.height) as usize]);
            }
            Ok(dem.read_f32(window)?.iter().map(|h| u8::from(!h.is_nan())).collect())
        };
        write_layer(&staging.path(VALID_MASK_PACK), &mask_spec, valid, bars[1])
            .context("writing the validity mask pack")?;
        Some(VALID_MASK_PACK.to_owned())
    } else {
        bars[1].finish_and_clear();
        None
    };
    Ok(HeightLayer {
        pack: HEIGHT_PACK.to_owned(),
        spacing_m,
        pyramid: spec.pyramid,
        min_m: scan.range_m[0],
        max_m: scan.range_m[1],
        // Every sample the mask marks 0: the source's voids and the grid beyond its edge alike.
        filled_samples: scan.source_voids + scan.beyond_edge,
        valid_mask_pack,
    })
}
