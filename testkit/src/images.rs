//! Image metrics for tests (the library's, which the speed trade reports) and golden-image
//! comparison against references kept beside the tests.

use std::path::Path;

pub use terramp::reference::image_metrics::{psnr_db, ssim};

/// PSNR of `a` against `b` over RGB, dB (infinite when equal); images of different sizes fail.
pub fn psnr(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    psnr_db(a, b).unwrap()
}

/// Compares `image` with the reference `<tests>/<name>` (PSNR at least `min_db`), or rewrites the
/// reference when `TERRAMP_BLESS=1`. A mismatch saves the image in `keep_dir` for inspection.
pub fn check_reference(
    image: &image::RgbaImage,
    tests: &Path,
    name: &str,
    min_db: f64,
    keep_dir: &Path,
) -> f64 {
    let path = tests.join(name);
    if std::env::var("TERRAMP_BLESS").is_ok_and(|v| v == "1") {
        image.save(&path).unwrap();
        return f64::INFINITY;
    }
    let reference = image::open(&path).unwrap().to_rgba8();
    let db = psnr(image, &reference);
    println!("{name}: {db:.1} dB against the reference");
    if db < min_db {
        let actual = keep_dir.join("actual.png");
        image.save(&actual).unwrap();
        panic!("the render differs from {name}: PSNR {db:.1} dB < {min_db} dB (saved {})", actual.display());
    }
    db
}
