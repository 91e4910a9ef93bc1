//! Where tests place datasets on the Earth: CRSs as the builder records them.

use terramp::earth::{EarthFrame, Ellipsoid, Projection};

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
