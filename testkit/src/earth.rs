//! Where tests place datasets on the Earth: CRSs as the builder records them.

use terramp::dataset::Dataset;
use terramp::earth::{EarthFrame, Ellipsoid, Projection};
use terramp::synth::SynthParams;

use crate::synth_dataset_with;

/// nc's State Plane (EPSG:32119: Lambert Conformal Conic on GRS 80), NAD83 taken as WGS 84 as
/// PROJ's default step does, heights above the ellipsoid.
pub fn nc_state_plane() -> EarthFrame {
    EarthFrame::ellipsoidal(
        Projection::LambertConformalConic2Sp {
            lat_origin_deg: 33.75,
            lon_origin_deg: -79.0,
            parallel_1_deg: 36.0 + 10.0 / 60.0,
            parallel_2_deg: 34.0 + 20.0 / 60.0,
            false_easting_m: 609_601.22,
            false_northing_m: 0.0,
        },
        Ellipsoid::GRS80,
        "NAD83 (EPSG:32119), taken as WGS 84",
    )
}

/// A synthetic dataset of `size`² samples `spacing_m` apart (world `seed`), its south-west corner
/// at nc's CRS point (600, 180) km, placed on the Earth there (its manifest given nc's State
/// Plane as its `[earth]`).
pub fn synth_on_nc(size: u32, spacing_m: f64, seed: u64) -> Dataset {
    let params =
        SynthParams { size, seed, spacing_m, origin_m: [600_000.0, 180_000.0], ..Default::default() };
    #[allow(clippy::unwrap_used, reason = "test support: a dataset that cannot open fails the test")]
    let mut dataset = Dataset::open(&synth_dataset_with(&params)).unwrap();
    dataset.manifest.earth = Some(nc_state_plane());
    dataset
}
