//! How it works: a camera as a user writes it, placed in a dataset. Three forms:
//! - `X,Y,Z,YAW,PITCH[,ROLL]`: the dataset's CRS (metres, Z above its datum), heading from the
//!   grid's north, pitch and roll (degrees), as `Camera::parse_pose` reads it;
//! - `lonlat:LON,LAT,H,HEADING,PITCH`: WGS 84 degrees, H metres above WGS 84's ellipsoid, heading
//!   from true north (`earth::pose::GeoPose`, through the manifest's `[earth]`);
//! - `lonlat-ground:LON,LAT,H,HEADING,PITCH`: the same, H metres above the dataset's ground there
//!   (its finest level; beyond the dataset, its nearest edge sample's).

use thiserror::Error;

use super::Dataset;
use super::pack::PackError;
use crate::camera::{Camera, CameraError};
use crate::earth::pose::{CrsPose, GeoPose, PoseError};

/// Why a camera cannot be placed in a dataset.
#[derive(Debug, Error)]
pub enum CameraPoseError {
    /// Not one of the three forms.
    #[error(
        "camera {0:?}: expected X,Y,Z,YAW,PITCH[,ROLL], lonlat:LON,LAT,H,HEADING,PITCH or lonlat-ground:LON,LAT,H,HEADING,PITCH"
    )]
    Parse(String),
    /// A pose on the Earth for a dataset whose manifest does not say where it lies.
    #[error(
        "the dataset {0:?} does not record where it lies on the Earth (a local CRS, or built before the \
         manifest's [earth]): give the camera as X,Y,Z,YAW,PITCH, or build the dataset again"
    )]
    NotOnEarth(String),
    /// The pose has no place in the dataset's CRS.
    #[error(transparent)]
    Pose(#[from] PoseError),
    /// The ground under the pose could not be read.
    #[error("the ground under the camera: {0}")]
    Ground(#[from] PackError),
    /// The camera is invalid.
    #[error(transparent)]
    Camera(#[from] CameraError),
}

impl Dataset {
    /// The camera `text` gives (one of the module's three forms), with `fov_deg` and `near_m`.
    pub fn camera_from(&self, text: &str, fov_deg: f64, near_m: f64) -> Result<Camera, CameraPoseError> {
        let parse_error = || CameraPoseError::Parse(text.into());
        let Some((form, numbers)) = text.split_once(':') else {
            return Camera::parse_pose(text, fov_deg, near_m).map_err(|e| match e {
                CameraError::Parse(_) => parse_error(),
                e => e.into(),
            });
        };
        let above_ground = match form.trim() {
            "lonlat" => false,
            "lonlat-ground" => true,
            _ => return Err(parse_error()),
        };
        let values: Vec<f64> = numbers
            .split(',')
            .map(|v| v.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| parse_error())?;
        let [lon_deg, lat_deg, height_m, heading_deg, pitch_deg] = values[..] else {
            return Err(parse_error());
        };
        let crs = self
            .place_on_earth(&GeoPose { lon_deg, lat_deg, height_m, heading_deg, pitch_deg }, above_ground)?;
        let camera = Camera {
            position_m: crs.position_m,
            yaw_deg: crs.yaw_deg,
            pitch_deg: crs.pitch_deg,
            roll_deg: 0.0,
            fov_deg,
            near_m,
        };
        camera.validate()?;
        Ok(camera)
    }

    /// `pose` in this dataset's CRS, its height taken above the ground there when `above_ground`
    /// (else above WGS 84's ellipsoid).
    pub fn place_on_earth(&self, pose: &GeoPose, above_ground: bool) -> Result<CrsPose, CameraPoseError> {
        let earth = self
            .manifest
            .earth
            .as_ref()
            .ok_or_else(|| CameraPoseError::NotOnEarth(self.manifest.name.clone()))?;
        let at = GeoPose { height_m: if above_ground { 0.0 } else { pose.height_m }, ..*pose };
        let mut crs = at.in_crs(earth)?;
        if above_ground {
            let [x, y] = self.manifest.origin_m;
            crs.position_m.z = self.height_at(crs.position_m.x - x, crs.position_m.y - y, 0)? + pose.height_m;
        }
        Ok(crs)
    }
}
