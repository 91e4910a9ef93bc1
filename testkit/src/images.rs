//! Image metrics for tests (the library's, which the speed trade reports) and golden images:
//! references kept beside the tests, each checked with a control frame that must fail it.

use std::path::Path;

use terramp::gpu::Gpu;

use crate::data::target_tmp_dir;
use crate::setup::lavapipe_only;

pub use terramp::reference::image_metrics::{psnr_db, ssim};

/// PSNR of `a` against `b` over RGB, dB (infinite when equal); images of different sizes fail.
pub fn psnr(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    psnr_db(a, b).unwrap()
}

/// How many pixels of `a` and `b` differ at all.
pub fn differing_pixels(a: &image::RgbaImage, b: &image::RgbaImage) -> usize {
    a.pixels().zip(b.pixels()).filter(|(p, q)| p != q).count()
}

/// How far below a golden test's tolerance its control frame must fall, dB: far enough that the
/// tolerance could not pass what the control changes, however the rasteriser rounds.
pub const CONTROL_MARGIN_DB: f64 = 10.0;

/// A golden image: a reference frame kept beside the tests, and the PSNR a render must reach.
#[derive(Debug, Clone, Copy)]
pub struct Golden<'a> {
    /// The folder the reference's `name` is relative to (a crate's `tests/`).
    pub tests_dir: &'a Path,
    /// The reference's path under `tests_dir`, e.g. `reference/nc_240x135.png`.
    pub name: &'a str,
    /// The PSNR a render must reach against it, dB.
    pub min_db: f64,
}

impl Golden<'_> {
    /// Checks `image` against the reference (same size, PSNR at least `min_db`) and `control`, a
    /// frame that differs in what the test exists to catch, against it too: the control must stay
    /// `CONTROL_MARGIN_DB` below the tolerance, or the tolerance could not see the difference.
    /// Both frames are first written to `<target>/tmp/golden/` (the frame under the reference's
    /// file name), where `scripts/bless_references.sh` takes them after an intended change of the
    /// look: blessing is that separate command, never a test run. Returns both PSNRs, dB.
    ///
    /// The references are lavapipe's frames, and the tolerance leaves room for its own rounding
    /// only: on another adapter (`gpu`, what rendered `image`) the comparison is skipped, loudly
    /// (`lavapipe_only`), and `None` returned.
    pub fn check(
        &self,
        gpu: &Gpu,
        image: &image::RgbaImage,
        control: &image::RgbaImage,
    ) -> Option<(f64, f64)> {
        let file = Path::new(self.name).file_name().unwrap();
        let kept = target_tmp_dir().join("golden");
        std::fs::create_dir_all(&kept).unwrap();
        image.save(kept.join(file)).unwrap();
        control.save(kept.join(format!("control-{}", file.to_string_lossy()))).unwrap();
        if !lavapipe_only(
            gpu,
            &format!("the golden image {} (a lavapipe frame, {} dB)", self.name, self.min_db),
        ) {
            return None;
        }
        let reference = image::open(self.tests_dir.join(self.name)).unwrap().to_rgba8();
        let (db, control_db) = (psnr(image, &reference), psnr(control, &reference));
        println!("{}: {db:.1} dB against the reference, control {control_db:.1} dB", self.name);
        assert!(
            db >= self.min_db,
            "the render differs from {}: PSNR {db:.1} dB < {} dB (the frame is in {}: after an intended \
             change, scripts/bless_references.sh makes it the reference)",
            self.name,
            self.min_db,
            kept.display()
        );
        assert!(
            control_db <= self.min_db - CONTROL_MARGIN_DB,
            "{}'s control frame is {control_db:.1} dB from it: the {} dB tolerance cannot tell them apart",
            self.name,
            self.min_db
        );
        Some((db, control_db))
    }
}
