//! How it works: a warped DEM is read by every height pass (the scan, the tiles with their borders
//! and their voids' padded windows, the mask), and GDAL's warp of each window costs more than
//! everything else the builder does. The scan therefore keeps what it warped: every sample of the
//! grid as a raw `f32`, row by row (south row first, as windows are), in a file of the staging
//! folder that is unlinked as soon as it is opened, so the space is the operating system's to
//! take back however the build ends (finished, failed or killed), and nothing of it is ever
//! published. Reads and writes are positioned (`pread`/`pwrite`) through the page cache: any
//! thread at any time, no mapping, no lock.

use std::fs::{File, OpenOptions};
use std::os::unix::fs::FileExt;
use std::path::Path;

use anyhow::{Context, Result};
use terramp::dataset::Window;

/// The DEM's samples on the dataset grid, as the scan warped them.
pub struct SpilledGrid {
    file: File,
    size: [u32; 2],
}

impl SpilledGrid {
    /// An empty spill for a grid of `size` samples, at `path` (unlinked at once).
    pub fn create(path: &Path, size: [u32; 2]) -> Result<Self> {
        let what = || format!("{}: the warped DEM's spill file", path.display());
        let file =
            OpenOptions::new().read(true).write(true).create_new(true).open(path).with_context(what)?;
        std::fs::remove_file(path).with_context(what)?;
        file.set_len(u64::from(size[0]) * u64::from(size[1]) * 4).with_context(what)?;
        Ok(Self { file, size })
    }

    fn offset(&self, x: u32, y: u32) -> u64 {
        (u64::from(y) * u64::from(self.size[0]) + u64::from(x)) * 4
    }

    /// Stores the samples of `window`, which lies inside the grid.
    pub fn write(&self, window: Window, samples: &[f32]) -> Result<()> {
        for (row, y) in samples.chunks_exact(window.width as usize).zip(window.y0..) {
            self.file
                .write_all_at(bytemuck::cast_slice(row), self.offset(window.x0, y))
                .context("writing the warped DEM's spill file")?;
        }
        Ok(())
    }

    /// The samples of `window`, south row first; `NaN` where it reaches past the grid, as a warp
    /// of that window would give.
    pub fn read(&self, window: Window) -> Result<Vec<f32>, String> {
        let mut out = vec![f32::NAN; (window.width * window.height) as usize];
        let x1 = (window.x0 + window.width).min(self.size[0]);
        if window.x0 >= x1 {
            return Ok(out);
        }
        let inside = (x1 - window.x0) as usize;
        for (row, y) in out.chunks_exact_mut(window.width as usize).zip(window.y0..self.size[1]) {
            let bytes: &mut [u8] = bytemuck::cast_slice_mut(&mut row[..inside]);
            self.file
                .read_exact_at(bytes, self.offset(window.x0, y))
                .map_err(|e| format!("reading the warped DEM's spill file: {e}"))?;
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spill_gives_back_what_was_written_nan_past_the_grid_and_leaves_no_file() {
        let dir = std::env::temp_dir().join(format!("terramp-spill-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("dem.f32");
        let spill = SpilledGrid::create(&path, [5, 4]).unwrap();
        assert!(!path.exists(), "unlinked at once");
        let samples: Vec<f32> = (0..20).map(|i| i as f32).collect();
        spill.write(Window { x0: 0, y0: 0, width: 5, height: 2 }, &samples[..10]).unwrap();
        spill.write(Window { x0: 0, y0: 2, width: 5, height: 2 }, &samples[10..]).unwrap();
        let back = spill.read(Window { x0: 3, y0: 2, width: 3, height: 3 }).unwrap();
        let expected = [13.0, 14.0, f32::NAN, 18.0, 19.0, f32::NAN, f32::NAN, f32::NAN, f32::NAN];
        let bits = |v: &[f32]| v.iter().map(|h| h.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&back), bits(&expected));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
