//! How it works: heights are built in passes over the DEM grid, each block by block or tile by
//! tile, so memory stays flat. The scan reads the whole grid once for what tiles cannot know
//! alone: the range of the valid heights, the voids (and, for a warped DEM, which of them lie
//! beyond the source's edge rather than in it), and the coarse summary the void fill falls back
//! on. The tile pass writes the height pack, filling each window's voids (`fill`) and rounding
//! every height to the dataset's step (`HeightStep`), so that the pack's codec stores integer
//! counts of steps instead of the warp's fractions. When there were voids, a last pass writes the
//! validity mask pack, reading again only the windows with voids.

use std::collections::HashSet;
use std::sync::Mutex;

use anyhow::{Context, Result, bail, ensure};
use indicatif::ProgressBar;
use rayon::prelude::*;
use terramp::dataset::{HeightLayer, LayerSpec, Pyramid, Staging, Window, write_layer};

use super::fill::{CoarseBuilder, VoidFill};
use super::raster::{GridRaster, SourceRaster};
use super::spill::SpilledGrid;

/// Samples per side of the blocks the scan reads.
const SCAN_BLOCK: u32 = 1024;
/// Blocks each thread warps before the scan takes them (bounds the scan's memory: 4 MiB a block).
const SCAN_BLOCKS_PER_THREAD: usize = 2;
pub const HEIGHT_PACK: &str = "height.pack";
pub const VALID_MASK_PACK: &str = "height_valid.pack";

/// The finest and coarsest steps heights may be rounded to, as powers of two (1/65536 m, 256 m).
const STEP_EXPONENTS: std::ops::RangeInclusive<i32> = -16..=8;
/// Steps per unit of an integer DEM by default: its values are whole units, and a bilinear warp
/// between them is worth a quarter unit more, not the f32 fraction's 24 bits (`docs/building.md`).
const DEFAULT_STEPS_PER_UNIT: f64 = 4.0;

/// What every height is rounded to before it is stored: a power of two of metres, or nothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeightStep {
    /// Metres; 0 keeps heights exactly as read.
    step_m: f64,
}

impl HeightStep {
    /// The step the user asked for: 0 (exact) or a power of two from 1/65536 to 256 m.
    pub fn new(step_m: f64) -> Result<Self> {
        let exponent = step_m.log2().round() as i32;
        ensure!(
            step_m == 0.0 || (STEP_EXPONENTS.contains(&exponent) && 2f64.powi(exponent) == step_m),
            "--height-step-m {step_m}: give 0 (heights exactly as read) or a power of two of metres from \
             1/65536 to 256 (… 0.125, 0.25, 0.5, 1, 2 …), so that every rounded height is exact in f32"
        );
        Ok(Self { step_m })
    }

    /// The default for `dem`: a quarter of its unit when its heights are integers (a warp's
    /// fractions of a unit are not data), exact when they are floating point.
    pub fn default_for(dem: &SourceRaster) -> Result<Self> {
        let integer = dem.band(1)?.band_type().is_integer();
        Self::new(if integer { 1.0 / DEFAULT_STEPS_PER_UNIT } else { 0.0 })
    }

    /// `height_m` rounded to the step (NaN stays NaN; never `-0.0`, which the codec cannot count).
    pub fn round(self, height_m: f32) -> f32 {
        if self.step_m == 0.0 {
            return height_m;
        }
        ((f64::from(height_m) / self.step_m).round() * self.step_m) as f32 + 0.0
    }

    /// Metres; 0 when heights are kept exactly as read.
    pub fn metres(self) -> f64 {
        self.step_m
    }

    /// The step for the manifest: `None` when heights are exact.
    pub fn step_m(self) -> Option<f32> {
        (self.step_m > 0.0).then_some(self.step_m as f32)
    }
}

/// What the scan learns about the DEM on the dataset grid.
pub struct HeightScan {
    pub range_m: [f32; 2],
    /// Voids inside the source's footprint: nodata in the source itself.
    pub source_voids: u64,
    /// Voids outside it: grid samples the source does not reach (corners of a reprojected DEM).
    pub beyond_edge: u64,
    /// The fill, when there is anything to fill.
    pub fill: Option<VoidFill>,
    /// The warped DEM as the scan read it, which the tile passes read instead of warping again
    /// (`None` for a DEM on its own grid, read as it is). Dropping it frees its disk.
    pub spill: Option<SpilledGrid>,
}

impl HeightScan {
    /// What the tile passes read: the scan's spill when there is one, voids filled, `step` kept.
    pub fn source<'a>(&'a self, dem: &'a GridRaster, step: HeightStep) -> HeightSource<'a> {
        HeightSource { dem, spill: self.spill.as_ref(), fill: self.fill.as_ref(), step }
    }
}

/// The heights as the dataset stores them, window by window: the DEM's samples (from the scan's
/// spill, or read again), voids filled, every height rounded to the step. Any window gives a
/// sample the same value, so a partition's windows agree with the single build's tiles.
pub struct HeightSource<'a> {
    pub dem: &'a GridRaster,
    /// The warped DEM as the scan kept it, read instead of warping again.
    pub spill: Option<&'a SpilledGrid>,
    /// The fill, when the DEM has voids.
    pub fill: Option<&'a VoidFill>,
    pub step: HeightStep,
}

impl HeightSource<'_> {
    /// The DEM's samples of `window` (`NaN` for voids and past the grid).
    fn samples(&self, window: Window) -> Result<Vec<f32>, String> {
        match self.spill {
            Some(spill) => spill.read(window),
            None => self.dem.read_f32(window),
        }
    }

    /// The stored heights of `window`, and whether it had no void.
    pub fn heights(&self, window: Window) -> Result<(Vec<f32>, bool), String> {
        let samples = self.samples(window)?;
        let void_free = !samples.iter().any(|h| h.is_nan());
        let heights = match self.fill {
            Some(fill) if !void_free => fill.fill(window, &self.samples(fill.padded(window))?),
            _ => samples,
        };
        Ok((heights.into_iter().map(|h| self.step.round(h)).collect(), void_free))
    }

    /// The validity mask of `window`: 1 where the DEM has a sample, 0 for its voids.
    pub fn valid(&self, window: Window) -> Result<Vec<u8>, String> {
        Ok(self.samples(window)?.iter().map(|h| u8::from(!h.is_nan())).collect())
    }
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

/// Reads the whole DEM grid once, block by block, a few blocks per thread side by side (each
/// warped through its thread's reader) and taken in order, so the result does not depend on the
/// threads. Into `spill`, when given, goes every sample read, for the tile passes.
pub fn scan(
    dem: &GridRaster,
    footprint: &Footprint,
    spill: Option<SpilledGrid>,
    progress: &ProgressBar,
) -> Result<HeightScan> {
    let size = dem.grid.size;
    let blocks = size.map(|n| n.div_ceil(SCAN_BLOCK));
    progress.set_length(u64::from(blocks[0] * blocks[1]));
    let windows: Vec<Window> = (0..blocks[1])
        .flat_map(|by| (0..blocks[0]).map(move |bx| (bx * SCAN_BLOCK, by * SCAN_BLOCK)))
        .map(|(x0, y0)| Window {
            x0,
            y0,
            width: SCAN_BLOCK.min(size[0] - x0),
            height: SCAN_BLOCK.min(size[1] - y0),
        })
        .collect();
    let read = |window: Window| -> Result<(Vec<f32>, u64, u64)> {
        let heights = dem
            .read_f32(window)
            .map_err(anyhow::Error::msg)
            .with_context(|| format!("scanning the DEM {}", dem.path.display()))?;
        if let Some(spill) = &spill {
            spill.write(window, &heights)?;
        }
        let voids: Vec<usize> = (0..heights.len()).filter(|&k| heights[k].is_nan()).collect();
        let in_source = count_in_source(&voids, window, footprint)?;
        progress.inc(1);
        Ok((heights, in_source, voids.len() as u64 - in_source))
    };
    let mut coarse = CoarseBuilder::new(size);
    let (mut range_m, mut source_voids, mut beyond_edge) = ([f32::INFINITY, f32::NEG_INFINITY], 0, 0);
    for chunk in windows.chunks(SCAN_BLOCKS_PER_THREAD * rayon::current_num_threads().max(1)) {
        let blocks: Vec<_> = chunk.par_iter().map(|&window| read(window)).collect();
        for (window, block) in chunk.iter().zip(blocks) {
            let (heights, in_source, beyond) = block?;
            for (k, &height_m) in heights.iter().enumerate() {
                if !height_m.is_nan() {
                    let (x, y) = (window.x0 + k as u32 % window.width, window.y0 + k as u32 / window.width);
                    coarse.add(x, y, height_m);
                    range_m = [range_m[0].min(height_m), range_m[1].max(height_m)];
                }
            }
            source_voids += in_source;
            beyond_edge += beyond;
        }
    }
    let Some(coarse) = coarse.finish() else {
        bail!("{}: the DEM holds no valid height at all", dem.path.display());
    };
    let fill = (source_voids + beyond_edge > 0).then(|| VoidFill::new(size, coarse, range_m));
    Ok(HeightScan { range_m, source_voids, beyond_edge, fill, spill })
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
    step: HeightStep,
    spacing_m: f64,
    staging: &Staging,
    bars: [&ProgressBar; 2],
) -> Result<HeightLayer> {
    let spec = LayerSpec::heights(dem.grid.size);
    let source = scan.source(dem, step);
    // The windows the height pass found void-free: the mask pass (same pyramid, so the same
    // windows) writes ones there without reading, and so warps only the windows with voids again.
    let void_free = Mutex::new(HashSet::new());
    let heights = |window: Window| -> Result<Vec<f32>, String> {
        let (heights, whole) = source.heights(window)?;
        if whole {
            void_free.lock().map_err(|_| "a height thread panicked")?.insert(window);
        }
        Ok(heights)
    };
    write_layer(&staging.path(HEIGHT_PACK), &spec, heights, bars[0]).context("writing the height pack")?;
    let valid_mask_pack = if scan.fill.is_some() {
        // Decimation keeps the mask exact at every level: a coarse sample is a fine one.
        let mask_spec = LayerSpec::valid_mask(dem.grid.size);
        let valid = |window: Window| -> Result<Vec<u8>, String> {
            if void_free.lock().map_err(|_| "a mask thread panicked")?.contains(&window) {
                return Ok(vec![1; (window.width * window.height) as usize]);
            }
            source.valid(window)
        };
        write_layer(&staging.path(VALID_MASK_PACK), &mask_spec, valid, bars[1])
            .context("writing the validity mask pack")?;
        true
    } else {
        bars[1].finish_and_clear();
        false
    };
    let filled = scan.source_voids + scan.beyond_edge;
    Ok(height_layer(spec.pyramid, spacing_m, scan.range_m, step, filled, valid_mask_pack))
}

/// The manifest's height layer: `range_m` of the valid heights as read, `filled` samples (the
/// source's voids and the grid beyond its edge alike, which the mask, when written, marks 0).
pub fn height_layer(
    pyramid: Pyramid,
    spacing_m: f64,
    range_m: [f32; 2],
    step: HeightStep,
    filled: u64,
    valid_mask_pack: bool,
) -> HeightLayer {
    HeightLayer {
        pack: HEIGHT_PACK.to_owned(),
        spacing_m,
        pyramid,
        // Rounding keeps order, so the rounded extremes bound every rounded height.
        min_m: step.round(range_m[0]),
        max_m: step.round(range_m[1]),
        step_m: step.step_m(),
        filled_samples: filled,
        valid_mask_pack: valid_mask_pack.then(|| VALID_MASK_PACK.to_owned()),
    }
}
