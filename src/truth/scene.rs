//! How it works: what the ground truth draws, on the CPU in f64. The seeds are the exact oracle's
//! (`reference::oracle::judge_seeds`) with the truth's culls: every seed the land cover grows at
//! full density (the settings' `seeds.density_scale` set to 1 by the caller) within one reach,
//! drawn as LOD 0 whatever its distance, culled only when its bounding sphere lies outside the
//! view; occlusion is for the image to say. Each becomes the `SeedRecord` pass 4 draws: its anchor
//! camera-relative (placed as the renderer places its grid, on the Earth or flat, in f64, then
//! rounded once), its jitter from the seed's hash as pass
//! 3 makes it, and its ground colour as pass 3 samples it (the bilinear imagery at the same
//! `GROUND_SAMPLES` hashed offsets within `seeds.ground_colour_radius_m`), but from the finest
//! imagery level, read
//! straight from the pack. Records are grouped by species (then address, rank) so each species is
//! one instanced draw.

use std::ops::Range;

use glam::DVec3;

use crate::config::Settings;
use crate::dataset::vegetation::vegetation_coverage;
use crate::dataset::{Dataset, PackError, imagery_texel_at};
use crate::earth::placing::ExactPlacing;
use crate::gpu::gpu_types::SeedRecord;
use crate::gpu::layout::{GROUND_SAMPLES, SpeciesLod};
use crate::reference::oracle::OracleSeed;
use crate::seeds::{SeedTables, pcg, seed_hash, unit};

/// The seeds drawn, in draw order (a record's index + 1 is its id in the truth's id buffer), and
/// each species' range of them.
pub struct TruthScene {
    /// The seeds, grouped by species, then by (address, rank).
    pub seeds: Vec<OracleSeed>,
    /// What pass 4 draws for each, same order.
    pub records: Vec<SeedRecord>,
    /// Per species (index into `SeedTables::species`), its range of `seeds`.
    pub species_ranges: Vec<(u32, Range<u32>)>,
}

impl TruthScene {
    /// The records of `seeds` seen from the camera `placing` places the grid from (any order in;
    /// grouped by species out).
    pub fn new(
        dataset: &Dataset,
        settings: &Settings,
        tables: &SeedTables,
        placing: &ExactPlacing,
        mut seeds: Vec<OracleSeed>,
    ) -> Result<Self, PackError> {
        seeds.sort_by_key(|s| (s.species, s.address, s.rank));
        let imagery = ImageryTexels::new(dataset, settings);
        let records = seeds
            .iter()
            .map(|s| record(settings, tables, placing, &imagery, s))
            .collect::<Result<Vec<_>, _>>()?;
        let mut species_ranges: Vec<(u32, Range<u32>)> = Vec::new();
        for (i, s) in seeds.iter().enumerate() {
            let i = i as u32;
            match species_ranges.last_mut() {
                Some((species, range)) if *species == s.species => range.end = i + 1,
                _ => species_ranges.push((s.species, i..i + 1)),
            }
        }
        Ok(Self { seeds, records, species_ranges })
    }
}

fn record(
    settings: &Settings,
    tables: &SeedTables,
    placing: &ExactPlacing,
    imagery: &ImageryTexels,
    seed: &OracleSeed,
) -> Result<SeedRecord, PackError> {
    // The oracle only returns seeds whose address fits i32 (it fails otherwise).
    let address = seed.address.map(|a| a as i32);
    let hash = seed_hash(address, seed.rank, settings.tlm.seed);
    let [x, y] = seed.position_grid_m;
    let anchor_m = DVec3::new(x, y, seed.ground_m - settings.seeds.sink_fraction * seed.height_m);
    let radius_per_height =
        tables.species.get(seed.species as usize).map_or(0.0, |s| f64::from(s.radius_per_height));
    Ok(SeedRecord {
        position_rel_m: placing.position_rel_m(anchor_m).as_vec3().to_array(),
        height_m: seed.height_m as f32,
        address,
        rank: seed.rank,
        species_lod: SpeciesLod { species: seed.species, lod: 0, last: 0, lcc_level: 0, height_level: 0 }
            .pack(),
        jitter: pcg(hash),
        ground_colour: imagery.ground_colour([x, y], hash)?,
        radius_m: (seed.height_m * radius_per_height) as f32,
        ground_m: seed.ground_m as f32,
    })
}

/// Level-0 imagery texels straight from the dataset's pack.
struct ImageryTexels<'a> {
    dataset: &'a Dataset,
    /// Texel edge, metres, and the grid-space offset of texel (0, 0)'s corner; `None` without imagery.
    frame: Option<(f64, f64)>,
    radius_texels: f64,
}

impl<'a> ImageryTexels<'a> {
    fn new(dataset: &'a Dataset, settings: &Settings) -> Self {
        let frame = dataset.manifest.imagery.as_ref().map(|meta| {
            // Cell layers cover the DEM's pixel-area extent: half a height spacing beyond grid space.
            (meta.texel_m, 0.5 * dataset.manifest.height.spacing_m)
        });
        let radius_texels = frame.map_or(0.0, |(texel_m, _)| settings.seeds.ground_colour_radius_m / texel_m);
        Self { dataset, frame, radius_texels }
    }

    /// Linear RGB and coverage of level-0 texel `t`.
    fn texel(&self, t: [u32; 2]) -> Result<[f64; 4], PackError> {
        let Some(layer) = &self.dataset.imagery else { return Ok([0.0; 4]) };
        let (tile, index) = imagery_texel_at(t);
        let bytes = layer.tile_texels(tile)?;
        let at = 4 * index;
        let rgba = bytes.get(at..at + 4).unwrap_or(&[0; 4]);
        let linear = super::srgb_to_linear;
        let alpha = f32::from(rgba[3]) / 255.0;
        let coverage = match self.dataset.manifest.vegetation {
            Some(_) => f64::from(vegetation_coverage(alpha)),
            None => f64::from(alpha),
        };
        Ok([linear(rgba[0]), linear(rgba[1]), linear(rgba[2]), coverage])
    }

    /// Pass 3's ground colour, from level 0: the mean of the bilinear imagery at `GROUND_SAMPLES`
    /// hashed points around grid point `p`, packed as unorm8 (WGSL's `pack4x8unorm`).
    fn ground_colour(&self, p: [f64; 2], hash: u32) -> Result<u32, PackError> {
        let (Some((texel_m, offset_m)), Some(layer)) = (self.frame, &self.dataset.imagery) else {
            return Ok(0);
        };
        let last = layer.pyramid.size.map(|n| i64::from(n) - 1);
        let centre = p.map(|v| (v + offset_m) / texel_m);
        let mut sum = [0.0f64; 4];
        let mut h = hash;
        for _ in 0..GROUND_SAMPLES {
            h = pcg(h);
            let offset = [h, pcg(h)].map(|v| (f64::from(unit(v)) * 2.0 - 1.0) * self.radius_texels);
            // Texel centres lie half a texel in.
            let q = [0, 1].map(|a| centre[a] + offset[a] - 0.5);
            let below = q.map(f64::floor);
            for k in 0..4 {
                let d = [k & 1, k >> 1];
                let t: [u32; 2] = std::array::from_fn(|a| (below[a] as i64 + d[a]).clamp(0, last[a]) as u32);
                let w: f64 = (0..2)
                    .map(|a| if d[a] == 1 { q[a] - below[a] } else { 1.0 - (q[a] - below[a]) })
                    .product();
                for (s, c) in sum.iter_mut().zip(self.texel(t)?) {
                    *s += w * c;
                }
            }
        }
        Ok(sum.iter().enumerate().fold(0, |word, (c, v)| {
            let mean = v / f64::from(GROUND_SAMPLES);
            word | (((mean.clamp(0.0, 1.0) * 255.0).round() as u32) << (8 * c))
        }))
    }
}
