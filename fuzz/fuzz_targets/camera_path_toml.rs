//! A camera path (`config/paths/*.toml`) of any text: parses, or is refused with a `PathError`;
//! a parsed path is sampled along its length without a panic or a non-finite camera.
#![no_main]
use libfuzzer_sys::fuzz_target;

mod build_checks;

fuzz_target!(init: build_checks::probe(), |text: &str| {
    if let Ok(path) = terramp::path::CameraPath::parse(text, "fuzz.toml") {
        for k in 0..=8 {
            let camera = path.camera_at(f64::from(k) / 8.0, 60.0, 1.0);
            assert!(
                camera.position_m.is_finite()
                    || path.keys.iter().any(|k| k.at.iter().any(|v| v.abs() > 1e300))
            );
        }
        let _ = path.walk(0.0, 50.0, 16, 60.0, 1.0);
    }
});
