//! How it works: the imagery's alpha channel carries a vegetation index beside the imagery's
//! coverage, so that the index streams, caches, filters and is sampled with the imagery at no
//! cost of its own (every pass that reads the imagery reads it): 0 where the source has no data,
//! else 1 plus the index mapped from [−1, 1] onto 0 to `VEGETATION_CODE_STEPS` (254). A filtered
//! alpha decodes to the filtered index; any alpha above 0 is data (`vegetation_coverage`). A
//! dataset's manifest says whether its alpha is coded so (`Manifest::vegetation`); BC1's one bit
//! of alpha cannot hold it.
//!
//! The index is NDVI, (NIR − red) / (NIR + red), from the imagery's near-infrared band beside its
//! red one: bare soil, roads and roofs lie near 0 or below, grass and crops around 0.3, closed
//! forest 0.5 and above.

use crate::gpu::layout::VEGETATION_CODE_STEPS;
pub use crate::gpu::layout::{vegetation_coverage, vegetation_index};

/// The index name `Manifest::vegetation` records for NDVI.
pub const NDVI: &str = "ndvi";

/// NDVI of a near-infrared and a red value (any unit, the same for both); `None` where it is not
/// defined (no data, both 0).
pub fn ndvi(nir: f64, red: f64) -> Option<f64> {
    let sum = nir + red;
    (sum.is_finite() && sum.abs() > f64::EPSILON).then(|| ((nir - red) / sum).clamp(-1.0, 1.0))
}

/// The alpha that codes `index` (clamped to [−1, 1]) for a texel with data: 1 to 255.
pub fn encode(index: f64) -> u8 {
    let unit = ((index.clamp(-1.0, 1.0) + 1.0) * 0.5 * f64::from(VEGETATION_CODE_STEPS)).round();
    1 + unit as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip_within_half_a_step_and_data_is_never_0() {
        let step = 2.0 / f64::from(VEGETATION_CODE_STEPS);
        for k in -100..=100 {
            let index = f64::from(k) / 100.0;
            let alpha = encode(index);
            assert!(alpha >= 1, "index {index} coded as no data");
            let back = f64::from(vegetation_index(f32::from(alpha) / 255.0));
            assert!((back - index).abs() <= 0.5 * step + 1e-6, "{index} → {alpha} → {back}");
            assert_eq!(vegetation_coverage(f32::from(alpha) / 255.0), 1.0);
        }
        assert_eq!((encode(-5.0), encode(5.0)), (1, 255));
        assert_eq!(vegetation_coverage(0.0), 0.0);
    }

    #[test]
    fn ndvi_is_defined_where_the_bands_are() {
        assert_eq!(ndvi(0.5, 0.1).map(|v| (v * 1e6).round() / 1e6), Some(0.666667));
        assert_eq!(ndvi(0.1, 0.5).map(|v| (v * 1e6).round() / 1e6), Some(-0.666667));
        assert_eq!(ndvi(0.0, 0.0), None);
        assert_eq!(ndvi(f64::NAN, 0.2), None);
    }
}
