//! How it works: a camera given on the Earth (issue 44, item 4): WGS 84 longitude, latitude and
//! height above the ellipsoid, a heading from true north and a pitch above the horizon, turned
//! into the dataset's own terms (a CRS position with its height above the dataset's datum, and a
//! heading from the grid's north), through the frame the manifest records and nothing else.
//!
//! The position is the CRS point whose Earth-centred position (`EarthFrame::ecef_m`: projection,
//! datum step, geoid) is the pose's: a first guess by the projection's forward formulas on the
//! CRS's ellipsoid and the geoid's undulation there, then Newton steps on the exact mapping, its
//! Jacobian the node mapping's (`EcefNode`); two or three steps reach a micrometre. The heading
//! turns by the angle between true north and the grid's north at that point (the meridians'
//! convergence, and the projection's skew where it has one), which the renderer's camera frame
//! (`LocalFrame::grid_aligned`) undoes; the pitch stays, as both measure it from the ellipsoid's
//! horizontal.

use glam::{DMat3, DVec3};
use thiserror::Error;

use super::local::{EcefNode, grid_turn_rad};
use super::{EarthFrame, Ellipsoid};

/// A pose on the Earth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GeoPose {
    /// Longitude, degrees east (WGS 84).
    pub lon_deg: f64,
    /// Latitude, degrees north (WGS 84).
    pub lat_deg: f64,
    /// Height above WGS 84's ellipsoid, metres.
    pub height_m: f64,
    /// Compass heading from true north, degrees clockwise.
    pub heading_deg: f64,
    /// Pitch above the horizon, degrees.
    pub pitch_deg: f64,
}

/// A pose in a dataset's own terms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CrsPose {
    /// CRS x and y, metres, and the height above the dataset's datum (its geoid where it has one).
    pub position_m: DVec3,
    /// Heading from the grid's north, degrees clockwise.
    pub yaw_deg: f64,
    /// Pitch above the horizon, degrees.
    pub pitch_deg: f64,
}

/// Why a pose on the Earth has no place in a dataset's CRS.
#[derive(Debug, Error, PartialEq)]
pub enum PoseError {
    /// A number is out of its range or not finite.
    #[error("{0} {1} is out of range ({2})")]
    Range(&'static str, f64, &'static str),
    /// The CRS cannot reach the place (beyond the projection's domain).
    #[error("the dataset's CRS does not reach longitude {lon_deg}°, latitude {lat_deg}°")]
    Unreachable {
        /// The place's longitude.
        lon_deg: f64,
        /// The place's latitude.
        lat_deg: f64,
    },
}

/// Newton steps taken at most; each one squares the miss (metres relative to the Earth's size).
const MAX_STEPS: usize = 8;
/// A miss this small (metres) ends the steps.
const CLOSE_M: f64 = 1e-6;

impl GeoPose {
    /// The pose in the terms of the dataset whose frame is `earth`.
    pub fn in_crs(&self, earth: &EarthFrame) -> Result<CrsPose, PoseError> {
        let checks = [
            ("longitude", self.lon_deg, (-180.0..=180.0).contains(&self.lon_deg), "-180 to 180"),
            ("latitude", self.lat_deg, (-90.0..=90.0).contains(&self.lat_deg), "-90 to 90"),
            ("height", self.height_m, self.height_m.is_finite(), "finite metres"),
            ("heading", self.heading_deg, self.heading_deg.is_finite(), "finite degrees"),
            ("pitch", self.pitch_deg, (-90.0..=90.0).contains(&self.pitch_deg), "-90 to 90"),
        ];
        if let Some((name, value, _, range)) = checks.into_iter().find(|c| !c.2) {
            return Err(PoseError::Range(name, value, range));
        }
        let unreachable = PoseError::Unreachable { lon_deg: self.lon_deg, lat_deg: self.lat_deg };
        let (lat, lon) = (self.lat_deg.to_radians(), self.lon_deg.to_radians());
        let target = Ellipsoid::WGS84.ecef_m(lat, lon, self.height_m);
        let [x, y] = earth.projection.forward(&earth.ellipsoid, lat, lon);
        let undulation_m = earth.geoid.as_ref().map_or(0.0, |g| g.undulation_at(lat, lon));
        let mut crs = DVec3::new(x, y, self.height_m - undulation_m);
        for _ in 0..MAX_STEPS {
            if !crs.is_finite() {
                return Err(unreachable);
            }
            let node = EcefNode::at(earth, crs);
            let miss = target - node.origin_m;
            if miss.length() < CLOSE_M {
                break;
            }
            let jacobian = DMat3::from_cols(node.d_x, node.d_y, node.d_h);
            crs += jacobian.inverse() * miss;
        }
        if !crs.is_finite() || (earth.ecef_m(crs.x, crs.y, crs.z) - target).length() > 1e3 * CLOSE_M {
            return Err(unreachable);
        }
        // The grid's north lies as far anticlockwise of true north as its x direction does of
        // east: a heading from true north is that much more from the grid's.
        let turn_deg = grid_turn_rad(earth, crs.x, crs.y, crs.z).to_degrees();
        let yaw_deg = (self.heading_deg + turn_deg).rem_euclid(360.0);
        Ok(CrsPose { position_m: crs, yaw_deg, pitch_deg: self.pitch_deg })
    }
}

#[cfg(test)]
#[path = "pose_tests.rs"]
mod tests;
