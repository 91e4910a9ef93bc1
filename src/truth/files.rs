//! How it works: a truth on disk, one folder: `truth.png` (the box-filtered image), `seed_ids.u32`
//! and `depth.f32` (per sample, top row first, little-endian `u32` ids and `f32` reversed-Z
//! depths), `seeds.csv` (one row per seed drawn: its id, identity, species, place, size and the
//! samples showing it) and `truth.json` (sizes, supersampling, counts). The folder is written
//! beside its final place and put in place by `crate::publish`, so it is never half-written: the
//! earlier truth or the new one (or briefly absent where the exchange is unavailable).

use std::fmt::Write as _;
use std::io;
use std::path::Path;

use serde::Serialize;

use super::Truth;
use crate::reference::oracle::OracleCounts;

/// The image.
pub const IMAGE_FILE: &str = "truth.png";
/// Per sample, the seed id (index + 1 in `seeds.csv`; 0 none), `u32` little-endian.
pub const SEED_IDS_FILE: &str = "seed_ids.u32";
/// Per sample, reversed-Z depth, `f32` little-endian.
pub const DEPTH_FILE: &str = "depth.f32";
/// The seeds drawn.
pub const SEEDS_FILE: &str = "seeds.csv";
/// Sizes and counts.
pub const META_FILE: &str = "truth.json";

/// What `truth.json` holds.
#[derive(Serialize)]
struct Meta<'a> {
    schema: &'static str,
    width_px: u32,
    height_px: u32,
    supersample: u32,
    samples_width: u32,
    samples_height: u32,
    seeds_drawn: usize,
    seeds_visible: usize,
    counts: &'a OracleCounts,
}

impl Truth {
    /// Writes the truth into folder `dir` (replacing it whole).
    pub fn write(&self, dir: &Path) -> io::Result<()> {
        let staging = crate::publish::begin_staging(dir).map_err(|(_, e)| e)?;
        self.colour.save(staging.join(IMAGE_FILE)).map_err(io::Error::other)?;
        std::fs::write(staging.join(SEED_IDS_FILE), bytemuck::cast_slice(&self.seed_ids))?;
        std::fs::write(staging.join(DEPTH_FILE), bytemuck::cast_slice(&self.depth))?;
        let mut csv = String::from("id,cell_x,cell_y,rank,species,x_m,y_m,ground_m,height_m,samples\n");
        for (i, (s, n)) in self.seeds.iter().zip(&self.samples).enumerate() {
            let [x, y] = s.position_grid_m;
            let _ = writeln!(
                csv,
                "{},{},{},{},{},{x:.3},{y:.3},{:.3},{:.3},{n}",
                i + 1,
                s.address[0],
                s.address[1],
                s.rank,
                s.species,
                s.ground_m,
                s.height_m
            );
        }
        std::fs::write(staging.join(SEEDS_FILE), csv)?;
        let [w, h] = self.size_px;
        let meta = Meta {
            schema: "terramp-truth/1",
            width_px: w,
            height_px: h,
            supersample: self.supersample,
            samples_width: w * self.supersample,
            samples_height: h * self.supersample,
            seeds_drawn: self.seeds.len(),
            seeds_visible: self.samples.iter().filter(|&&n| n > 0).count(),
            counts: &self.counts,
        };
        let json = serde_json::to_string_pretty(&meta).map_err(io::Error::other)?;
        std::fs::write(staging.join(META_FILE), json + "\n")?;
        crate::publish::publish(&staging, dir).map_err(|(_, e)| e)
    }
}
