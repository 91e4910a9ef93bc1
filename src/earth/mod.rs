//! How it works: where a dataset lies on the Earth (issue 44). A dataset's points are (x, y) in
//! its metric CRS and a height; `EarthFrame`, recorded in the manifest by the builder (which has
//! GDAL and PROJ), says how they become Earth-centred, Earth-fixed positions on WGS 84 (ECEF,
//! EPSG:4978) with no projection library at run time:
//! 1. the projection's inverse (`projection`) on the CRS's own ellipsoid gives geodetic latitude
//!    and longitude in the CRS's datum;
//! 2. the datum's step to WGS 84 (`DatumShift`) as PROJ takes it for this CRS: none (the
//!    coordinates are taken as WGS 84's, as PROJ's default NAD83 → WGS 84 step, EPSG:1188, does),
//!    or a seven-parameter Helmert transformation of the datum's own Earth-centred positions;
//! 3. the height along the ellipsoid's normal (`ellipsoid`): the DEM's height plus the geoid's
//!    height above the ellipsoid there (`GeoidLattice`, sampled by the builder from PROJ's EGM96
//!    grid on a lattice over the dataset and interpolated bilinearly); the builder records what
//!    the heights are above (`heights`).
//!
//! The builder checks the frame it records against PROJ on a lattice over the dataset before it
//! writes it; `data-tools/tests/earth.rs` holds it within a centimetre of PROJ at 10,000 random
//! points of nc and zion. `local` turns those positions into the camera's local frame, exactly in
//! f64 and node by node as an f32 polynomial for the GPU.

pub mod ellipsoid;
pub mod geodesic;
pub mod gpu;
pub mod horizon;
pub mod local;
pub mod placing;
pub mod pose;
pub mod projection;

use glam::DVec3;
use serde::{Deserialize, Serialize};

pub use ellipsoid::Ellipsoid;
pub use projection::Projection;

/// A datum's step to WGS 84.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "snake_case")]
pub enum DatumShift {
    /// The datum's latitudes and longitudes taken as WGS 84's (a null transformation).
    None,
    /// A Helmert transformation of Earth-centred positions, position-vector convention
    /// (EPSG:9606; GDAL's TOWGS84): `p' = t + (1 + s) R p` with small rotations.
    Helmert {
        /// Translation, metres.
        translation_m: [f64; 3],
        /// Rotations about x, y, z, arc-seconds (position vector: positive anticlockwise seen
        /// from the axis's positive end, rotating the point).
        rotation_arcsec: [f64; 3],
        /// Scale difference, parts per million.
        scale_ppm: f64,
    },
}

impl DatumShift {
    /// WGS 84's Earth-centred position of the datum's own `p`.
    pub fn apply(&self, p: DVec3) -> DVec3 {
        match *self {
            Self::None => p,
            Self::Helmert { translation_m, rotation_arcsec, scale_ppm } => {
                let [rx, ry, rz] = rotation_arcsec.map(|a| (a / 3600.0).to_radians());
                let s = 1.0 + scale_ppm * 1e-6;
                let rotated = DVec3::new(
                    p.x - rz * p.y + ry * p.z,
                    rz * p.x + p.y - rx * p.z,
                    -ry * p.x + rx * p.y + p.z,
                );
                DVec3::from(translation_m) + s * rotated
            }
        }
    }
}

/// Fixed-point steps `EarthFrame::crs_m` takes to undo a datum's step: four leave 10⁻²⁰ of it.
const DATUM_INVERSE_STEPS: usize = 4;

/// How a dataset's CRS coordinates become positions on WGS 84 (the manifest's `[earth]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EarthFrame {
    /// The CRS's projection.
    pub projection: Projection,
    /// The CRS's datum's ellipsoid, on which the projection works.
    pub ellipsoid: Ellipsoid,
    /// The datum's step to WGS 84.
    pub to_wgs84: DatumShift,
    /// What the step is, for the record: the datum, and the operation PROJ chose for it.
    pub datum_note: String,
    /// What the dataset's heights are above, for the record.
    pub heights: String,
    /// The geoid the heights are above, over the dataset; absent: they are taken as heights
    /// above the ellipsoid.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geoid: Option<GeoidLattice>,
}

/// A geoid's height above the ellipsoid (its undulation) over a dataset: the nodes of the
/// geoid's own geographic grid that cover it, interpolated bilinearly in latitude and longitude as
/// PROJ interpolates the grid, so that within the dataset the two agree to the values' rounding.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GeoidLattice {
    /// Which geoid, and from where.
    pub name: String,
    /// Latitude and longitude of node (0, 0), the south-west one, degrees (the longitude may lie
    /// outside ±180 where the dataset crosses the antimeridian).
    pub south_west_deg: [f64; 2],
    /// Distance between nodes, degrees, in latitude and longitude alike.
    pub step_deg: f64,
    /// Nodes along a parallel and along a meridian (at least 2 each).
    pub size: [u32; 2],
    /// Undulation at each node, metres, rows from the south.
    pub undulation_m: Vec<f32>,
    /// The largest difference the builder found between the lattice's interpolation and PROJ's
    /// at its check points, metres.
    pub interpolation_error_m: f64,
}

impl GeoidLattice {
    /// The undulation at latitude `lat` and longitude `lon` (radians), metres: bilinear between
    /// the four nodes around it (the nearest edge's beyond the lattice).
    pub fn undulation_at(&self, lat: f64, lon: f64) -> f64 {
        let [w, h] = self.size.map(|n| n.max(2) as usize);
        let at = |c: usize, r: usize| f64::from(self.undulation_m.get(r * w + c).copied().unwrap_or(0.0));
        let [south, west] = self.south_west_deg;
        let span_deg = (w - 1) as f64 * self.step_deg;
        let mut east_of_west = (lon.to_degrees() - west).rem_euclid(360.0);
        // West of the lattice (nearer its west edge than its east one, going round): its west edge.
        if east_of_west > span_deg + 0.5 * (360.0 - span_deg) {
            east_of_west = 0.0;
        }
        let u = (east_of_west / self.step_deg).clamp(0.0, (w - 1) as f64);
        let v = ((lat.to_degrees() - south) / self.step_deg).clamp(0.0, (h - 1) as f64);
        let (c, r) = ((u as usize).min(w - 2), (v as usize).min(h - 2));
        let (fu, fv) = (u - c as f64, v - r as f64);
        let s = at(c, r) * (1.0 - fu) + at(c + 1, r) * fu;
        let n = at(c, r + 1) * (1.0 - fu) + at(c + 1, r + 1) * fu;
        s * (1.0 - fv) + n * fv
    }
}

impl EarthFrame {
    /// A frame with `projection` on `ellipsoid`, its datum taken as WGS 84's (no step) and its
    /// heights as heights above the ellipsoid (no geoid).
    pub fn ellipsoidal(projection: Projection, ellipsoid: Ellipsoid, datum_note: &str) -> Self {
        Self {
            projection,
            ellipsoid,
            to_wgs84: DatumShift::None,
            datum_note: datum_note.to_owned(),
            heights: "the ellipsoid".to_owned(),
            geoid: None,
        }
    }

    /// Geodetic latitude and longitude (radians) in the CRS's datum of CRS point (`x_m`, `y_m`).
    pub fn geodetic(&self, x_m: f64, y_m: f64) -> (f64, f64) {
        self.projection.inverse(&self.ellipsoid, x_m, y_m)
    }

    /// The WGS 84 Earth-centred position (ECEF, EPSG:4978) of CRS point (`x_m`, `y_m`) at
    /// `height_m` along the normal.
    pub fn ecef_m(&self, x_m: f64, y_m: f64, height_m: f64) -> DVec3 {
        let (lat, lon) = self.geodetic(x_m, y_m);
        self.ecef_geodetic_m(lat, lon, height_m + self.undulation_at(lat, lon))
    }

    /// The geoid's undulation at CRS point (`x_m`, `y_m`), metres (0 without one).
    pub fn undulation_m(&self, x_m: f64, y_m: f64) -> f64 {
        let (lat, lon) = self.geodetic(x_m, y_m);
        self.undulation_at(lat, lon)
    }

    /// The WGS 84 Earth-centred position of CRS point (`x_m`, `y_m`) at `height_m` above the
    /// datum's ellipsoid (no geoid added).
    pub fn ecef_above_ellipsoid_m(&self, x_m: f64, y_m: f64, height_m: f64) -> DVec3 {
        let (lat, lon) = self.geodetic(x_m, y_m);
        self.ecef_geodetic_m(lat, lon, height_m)
    }

    fn undulation_at(&self, lat: f64, lon: f64) -> f64 {
        self.geoid.as_ref().map_or(0.0, |g| g.undulation_at(lat, lon))
    }

    fn ecef_geodetic_m(&self, lat: f64, lon: f64, height_m: f64) -> DVec3 {
        match self.to_wgs84 {
            // PROJ's null step takes the coordinates as WGS 84's: on WGS 84's ellipsoid.
            DatumShift::None => Ellipsoid::WGS84.ecef_m(lat, lon, height_m),
            shift => shift.apply(self.ellipsoid.ecef_m(lat, lon, height_m)),
        }
    }

    /// The CRS point (x, y and a height above the datum) whose WGS 84 Earth-centred position is
    /// `ecef_m`: `ecef_m`'s inverse, exact at any distance (the datum's step undone by fixed-point
    /// steps: a Helmert step is the identity to 10⁻⁵, so each leaves that share of the miss).
    pub fn crs_m(&self, ecef_m: DVec3) -> DVec3 {
        let (lat, lon, height_m) = match self.to_wgs84 {
            DatumShift::None => Ellipsoid::WGS84.geodetic(ecef_m),
            shift => {
                let mut own = ecef_m;
                for _ in 0..DATUM_INVERSE_STEPS {
                    own += ecef_m - shift.apply(own);
                }
                self.ellipsoid.geodetic(own)
            }
        };
        let [x_m, y_m] = self.projection.forward(&self.ellipsoid, lat, lon);
        DVec3::new(x_m, y_m, height_m - self.undulation_at(lat, lon))
    }
}

/// Frames the unit tests place points with.
#[cfg(test)]
pub(crate) mod test_frames {
    use super::{EarthFrame, Ellipsoid, Projection};

    /// nc's State Plane (EPSG:32119: Lambert Conformal Conic on GRS 80), NAD83 taken as WGS 84 as
    /// PROJ's default step does, heights above the ellipsoid (the ground's shape the ellipsoid's).
    pub(crate) fn nc() -> EarthFrame {
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

    /// The local azimuthal equidistant frame the builder gives GLOBE's tile G: centred at 25° N
    /// 45° E on WGS 84, heights above the ellipsoid.
    pub(crate) fn globe() -> EarthFrame {
        EarthFrame::ellipsoidal(
            Projection::AzimuthalEquidistant {
                lat_origin_deg: 25.0,
                lon_origin_deg: 45.0,
                false_easting_m: 0.0,
                false_northing_m: 0.0,
            },
            Ellipsoid::WGS84,
            "WGS 84",
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_helmert_step_moves_and_turns_as_the_convention_says() {
        let p = DVec3::new(6_378_137.0, 0.0, 0.0);
        let shift =
            DatumShift::Helmert { translation_m: [1.0, 2.0, 3.0], rotation_arcsec: [0.0; 3], scale_ppm: 0.0 };
        assert_eq!(shift.apply(p), p + DVec3::new(1.0, 2.0, 3.0));
        // A position-vector rotation of 1″ about z carries a point on the x axis towards +y.
        let turn =
            DatumShift::Helmert { translation_m: [0.0; 3], rotation_arcsec: [0.0, 0.0, 1.0], scale_ppm: 0.0 };
        let moved = turn.apply(p);
        assert!((moved.y - 6_378_137.0 * (1.0f64 / 3600.0).to_radians()).abs() < 1e-6, "{moved}");
        let scale =
            DatumShift::Helmert { translation_m: [0.0; 3], rotation_arcsec: [0.0; 3], scale_ppm: 1.0 };
        assert!((scale.apply(p).x - p.x * 1.000_001).abs() < 1e-6);
        assert_eq!(DatumShift::None.apply(p), p);
    }

    /// `crs_m` undoes `ecef_m` within 10 µm on nc's State Plane through a Helmert step and a
    /// geoid, and on an azimuthal equidistant frame out to 9,000 km from its centre (where the
    /// geodesic's own round trip leaves 2 µm).
    #[test]
    fn the_crs_point_of_a_position_is_where_it_came_from() {
        let mut helmert = test_frames::nc();
        helmert.to_wgs84 = DatumShift::Helmert {
            translation_m: [-8.0, 160.0, 176.0],
            rotation_arcsec: [0.3, -0.2, 0.5],
            scale_ppm: 1.2,
        };
        helmert.geoid = Some(GeoidLattice {
            name: "test".into(),
            south_west_deg: [33.0, -81.0],
            step_deg: 1.0,
            size: [4, 4],
            undulation_m: (0..16).map(|i| -30.0 - i as f32).collect(),
            interpolation_error_m: 0.0,
        });
        let aeqd = test_frames::globe();
        for (frame, points) in [
            (
                helmert,
                [[600_000.0, 180_000.0, 100.0], [400_000.0, 300_000.0, -20.0], [900_000.0, 0.0, 2_000.0]],
            ),
            (aeqd, [[0.0, 0.0, 0.0], [-5e6, 3e6, 8_000.0], [9e6, -1e6, -400.0]]),
        ] {
            for p in points.map(DVec3::from) {
                let back = frame.crs_m(frame.ecef_m(p.x, p.y, p.z));
                assert!((back - p).length() < 1e-5, "{p} came back as {back}");
            }
        }
    }

    #[test]
    fn a_geoid_lattice_interpolates_between_its_nodes_and_holds_beyond_them() {
        let g = GeoidLattice {
            name: "test".into(),
            south_west_deg: [10.0, 179.5],
            step_deg: 0.25,
            size: [3, 2],
            undulation_m: vec![0.0, 1.0, 2.0, 10.0, 11.0, 12.0],
            interpolation_error_m: 0.0,
        };
        let at = |lat: f64, lon: f64| g.undulation_at(lat.to_radians(), lon.to_radians());
        assert!(at(10.0, 179.5).abs() < 1e-9);
        assert!((at(10.25, -180.0) - 12.0).abs() < 1e-9, "across the antimeridian");
        assert!((at(10.0625, 179.875) - (1.5 + 2.5)).abs() < 1e-9);
        // Beyond the lattice: its edge.
        assert!(at(0.0, 179.5).abs() < 1e-9);
        assert!((at(20.0, -170.0) - 12.0).abs() < 1e-9);
        assert!((at(10.25, 170.0) - 10.0).abs() < 1e-9, "west of it: its west edge");
    }
}
