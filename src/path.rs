//! How it works: a camera path is a list of keyframes in the dataset CRS (metres, height above the
//! datum; compass heading and pitch in degrees), read from TOML (`config/paths/*.toml`); a
//! keyframe may instead be given on the Earth (`lonlat`, `heading_deg`), which the dataset places
//! in its CRS as the path is read (`CameraPath::load_placed`). Positions
//! follow a uniform Catmull-Rom spline through the keys, so the flight passes
//! exactly through each key with a continuous velocity; headings turn the short way round. A
//! flight of `n` frames samples the path at `n` evenly spaced parameters from the first key to
//! the last.

use std::path::Path;

use glam::DVec3;
use serde::Deserialize;
use thiserror::Error;

use crate::camera::Camera;

/// Why a camera path could not be loaded; each names the file.
#[derive(Debug, Error)]
pub enum PathError {
    /// The path file could not be read.
    #[error("{path}: {source}")]
    Read {
        /// The file's path, as given.
        path: String,
        /// The I/O error from reading it.
        source: std::io::Error,
    },
    /// The text is not valid TOML, or not a list of `[[key]]` keyframes (an unknown or missing key).
    #[error("{path}: {message}")]
    Parse {
        /// The file's path, or the name given to `CameraPath::parse`.
        path: String,
        /// The TOML parser's message.
        message: String,
    },
    /// The file has no keyframe.
    #[error("{path}: a path needs at least one keyframe")]
    Empty {
        /// The file, as in `Parse`.
        path: String,
    },
    /// A keyframe holds NaN or an infinity.
    #[error("{path}: keyframe {index} has a value that is not a finite number")]
    NotFinite {
        /// The file, as in `Parse`.
        path: String,
        /// The keyframe's position in the file, from 0.
        index: usize,
    },
    /// A keyframe given on the Earth could not be placed in the dataset's CRS.
    #[error("{path}: keyframe {index}: {message}")]
    Place {
        /// The file, as in `Parse`.
        path: String,
        /// The keyframe's position in the file, from 0.
        index: usize,
        /// Why.
        message: String,
    },
}

/// Why a keyframe on the Earth is refused where no dataset places it.
const ON_EARTH: &str = "given on the Earth (`lonlat`): only a dataset that records where it lies places it";

/// Spline samples per key when `CameraPath::walk` measures the arc length.
const WALK_SAMPLES_PER_KEY: f64 = 4096.0;

/// One pose the flight passes through (`[[key]]` in the file).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Keyframe {
    /// Position in the dataset CRS: east, north, height above the datum, metres.
    pub at: [f64; 3],
    /// Compass heading, degrees clockwise from north; the flight turns the short way to the next.
    pub yaw_deg: f64,
    /// Elevation of the view above the horizon, degrees (negative looks down).
    pub pitch_deg: f64,
}

/// A keyframe given on the Earth (`lonlat`, `heading_deg`, `pitch_deg`, `above_ground`), before a
/// dataset places it in its CRS (`CameraPath::parse_placed`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EarthKey {
    /// WGS 84 longitude and latitude, degrees, and a height, metres: above the ellipsoid, or
    /// above the ground with `above_ground`.
    pub lonlat: [f64; 3],
    /// Compass heading from true north, degrees.
    pub heading_deg: f64,
    /// Elevation of the view above the horizon, degrees.
    pub pitch_deg: f64,
    /// Whether the height is above the dataset's ground rather than the ellipsoid.
    pub above_ground: bool,
}

/// A keyframe as the file writes it: in the dataset CRS (`at`, `yaw_deg`) or on the Earth
/// (`lonlat`, `heading_deg`, and `above_ground`, false by default).
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
struct KeyOnFile {
    at: Option<[f64; 3]>,
    yaw_deg: Option<f64>,
    lonlat: Option<[f64; 3]>,
    heading_deg: Option<f64>,
    #[serde(default)]
    above_ground: bool,
    pitch_deg: f64,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PathFile {
    key: Vec<KeyOnFile>,
}

/// A camera flight: keyframes joined by a Catmull-Rom spline, sampled by `camera_at`.
#[derive(Debug, Clone, PartialEq)]
pub struct CameraPath {
    /// The keyframes in flight order, at least one; equally spaced in the path's parameter.
    pub keys: Vec<Keyframe>,
}

/// Places a keyframe given on the Earth in the dataset's CRS, or says why it cannot.
pub type PlaceKey<'a> = &'a mut dyn FnMut(&EarthKey) -> Result<Keyframe, String>;

impl CameraPath {
    /// Reads and checks a path file (`config/paths/*.toml`) of keyframes in the dataset CRS.
    pub fn load(path: &Path) -> Result<Self, PathError> {
        Self::load_placed(path, &mut |_| Err(ON_EARTH.to_owned()))
    }

    /// Reads and checks a path file whose keyframes may be given on the Earth, each placed by
    /// `place`.
    pub fn load_placed(path: &Path, place: PlaceKey) -> Result<Self, PathError> {
        let name = path.display().to_string();
        let text =
            std::fs::read_to_string(path).map_err(|source| PathError::Read { path: name.clone(), source })?;
        Self::parse_placed(&text, &name, place)
    }

    /// Parses and checks a path's TOML text of keyframes in the dataset CRS; `name` labels the
    /// errors.
    pub fn parse(text: &str, name: &str) -> Result<Self, PathError> {
        Self::parse_placed(text, name, &mut |_| Err(ON_EARTH.to_owned()))
    }

    /// Parses and checks a path's TOML text, keyframes given on the Earth placed by `place`.
    pub fn parse_placed(text: &str, name: &str, place: PlaceKey) -> Result<Self, PathError> {
        let file: PathFile = toml::from_str(text)
            .map_err(|e| PathError::Parse { path: name.to_owned(), message: e.to_string() })?;
        if file.key.is_empty() {
            return Err(PathError::Empty { path: name.to_owned() });
        }
        let mut keys = Vec::with_capacity(file.key.len());
        for (index, k) in file.key.into_iter().enumerate() {
            let numbers = k.at.into_iter().chain(k.lonlat).flatten().chain(k.yaw_deg).chain(k.heading_deg);
            if !numbers.chain([k.pitch_deg]).all(f64::is_finite) {
                return Err(PathError::NotFinite { path: name.to_owned(), index });
            }
            let key = match (k.at, k.yaw_deg, k.lonlat, k.heading_deg, k.above_ground) {
                (Some(at), Some(yaw_deg), None, None, false) => {
                    Keyframe { at, yaw_deg, pitch_deg: k.pitch_deg }
                }
                (None, None, Some(lonlat), Some(heading_deg), above_ground) => {
                    let earth = EarthKey { lonlat, heading_deg, pitch_deg: k.pitch_deg, above_ground };
                    place(&earth).map_err(|message| PathError::Place {
                        path: name.to_owned(),
                        index,
                        message,
                    })?
                }
                _ => {
                    let message = format!(
                        "keyframe {index}: give `at` and `yaw_deg` (the dataset CRS) or `lonlat` and \
                         `heading_deg` (on the Earth, with `above_ground` if the height is above the ground), \
                         and `pitch_deg`"
                    );
                    return Err(PathError::Parse { path: name.to_owned(), message });
                }
            };
            keys.push(key);
        }
        Ok(Self { keys })
    }

    /// The camera at `t` in [0, 1] along the path (clamped).
    pub fn camera_at(&self, t: f64, fov_deg: f64, near_m: f64) -> Camera {
        let last = self.keys.len() - 1;
        let s = t.clamp(0.0, 1.0) * last as f64;
        let i = (s.floor() as usize).min(last.saturating_sub(1));
        let f = s - i as f64;
        let key = |k: isize| self.keys[k.clamp(0, last as isize) as usize];
        let i = i as isize;
        let (k0, k1, k2, k3) = (key(i - 1), key(i), key(i + 1), key(i + 2));
        let position = catmull_rom(k0.at.into(), k1.at.into(), k2.at.into(), k3.at.into(), f);
        let turn = (k2.yaw_deg - k1.yaw_deg + 540.0).rem_euclid(360.0) - 180.0;
        Camera {
            position_m: position,
            yaw_deg: (k1.yaw_deg + turn * f).rem_euclid(360.0),
            pitch_deg: k1.pitch_deg + (k2.pitch_deg - k1.pitch_deg) * f,
            roll_deg: 0.0,
            fov_deg,
            near_m,
        }
    }

    /// Up to `count` cameras along the path from parameter `t0`, each `step_m` metres of flight
    /// beyond the one before (arc length, measured on a fine sampling of the spline), with their
    /// parameters: a flight at a steady speed, as consecutive frames see it. Fewer when the path
    /// ends first; one when it does not move (a single key, or `step_m` not positive).
    pub fn walk(&self, t0: f64, step_m: f64, count: usize, fov_deg: f64, near_m: f64) -> Vec<(f64, Camera)> {
        let t0 = t0.clamp(0.0, 1.0);
        let mut out = vec![(t0, self.camera_at(t0, fov_deg, near_m))];
        if count <= 1 || step_m.is_nan() || step_m <= 0.0 {
            out.truncate(count.max(1));
            return out;
        }
        // Fine enough that a chord is the arc to well under a millimetre on any sensible path.
        let dt = 1.0 / (self.keys.len() as f64 * WALK_SAMPLES_PER_KEY);
        let (mut t, mut travelled_m, mut next_m) = (t0, 0.0, step_m);
        let mut at = out[0].1.position_m;
        while out.len() < count && t < 1.0 {
            let t1 = (t + dt).min(1.0);
            let p1 = self.camera_at(t1, fov_deg, near_m).position_m;
            let chord_m = (p1 - at).length();
            while out.len() < count && travelled_m + chord_m >= next_m && chord_m > 0.0 {
                let t_step = t + (t1 - t) * (next_m - travelled_m) / chord_m;
                out.push((t_step, self.camera_at(t_step, fov_deg, near_m)));
                next_m += step_m;
            }
            (t, at, travelled_m) = (t1, p1, travelled_m + chord_m);
        }
        out
    }
}

fn catmull_rom(p0: DVec3, p1: DVec3, p2: DVec3, p3: DVec3, t: f64) -> DVec3 {
    let (t2, t3) = (t * t, t * t * t);
    0.5 * (2.0 * p1
        + (p2 - p0) * t
        + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * t2
        + (3.0 * p1 - p0 - 3.0 * p2 + p3) * t3)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO_KEYS: &str = "[[key]]\nat = [0.0, 0.0, 100.0]\nyaw_deg = 350.0\npitch_deg = -10.0\n\
                            [[key]]\nat = [1000.0, 0.0, 300.0]\nyaw_deg = 10.0\npitch_deg = -30.0\n";

    #[test]
    fn passes_through_keys_and_turns_the_short_way() {
        let path = CameraPath::parse(TWO_KEYS, "test").unwrap();
        let start = path.camera_at(0.0, 60.0, 0.1);
        let end = path.camera_at(1.0, 60.0, 0.1);
        assert_eq!(start.position_m, DVec3::new(0.0, 0.0, 100.0));
        assert!((end.position_m - DVec3::new(1000.0, 0.0, 300.0)).length() < 1e-9);
        let middle = path.camera_at(0.5, 60.0, 0.1);
        assert!(
            (middle.yaw_deg - 0.0).abs() < 1e-9 || (middle.yaw_deg - 360.0).abs() < 1e-9,
            "{}",
            middle.yaw_deg
        );
        assert!((middle.pitch_deg + 20.0).abs() < 1e-9);
        assert!((middle.position_m.x - 500.0).abs() < 1e-9);
    }

    #[test]
    fn a_walk_steps_evenly_along_the_arc_and_stops_at_the_end() {
        let path = CameraPath::parse(TWO_KEYS, "test").unwrap();
        let walk = path.walk(0.25, 2.5, 16, 60.0, 0.1);
        assert_eq!(walk.len(), 16);
        for pair in walk.windows(2) {
            let step_m = (pair[1].1.position_m - pair[0].1.position_m).length();
            assert!((step_m - 2.5).abs() < 1e-3, "{step_m}");
            assert!(pair[1].0 > pair[0].0);
        }
        // To the end of the path and no further: the last step stops within a step of it.
        let end = path.camera_at(1.0, 60.0, 0.1).position_m;
        let to_end = path.walk(0.99, 5.0, 100, 60.0, 0.1);
        let last = to_end.last().unwrap();
        assert!(to_end.len() > 1 && to_end.len() < 100 && last.0 <= 1.0, "{}", to_end.len());
        assert!((end - last.1.position_m).length() < 5.0);
        assert_eq!(path.walk(0.5, 0.0, 5, 60.0, 0.1).len(), 1);
        assert!(path.walk(0.5, 1.0, 0, 60.0, 0.1).len() == 1);
    }

    #[test]
    fn a_single_key_is_a_still_camera() {
        let one = "[[key]]\nat = [5.0, 6.0, 7.0]\nyaw_deg = 0.0\npitch_deg = 0.0\n";
        let path = CameraPath::parse(one, "one").unwrap();
        assert_eq!(path.camera_at(0.7, 60.0, 0.1).position_m, DVec3::new(5.0, 6.0, 7.0));
        assert_eq!(path.walk(0.2, 1.0, 8, 60.0, 0.1).len(), 1);
    }

    #[test]
    fn keys_on_the_earth_are_placed_by_the_dataset() {
        let text = "[[key]]\nat = [5.0, 6.0, 7.0]\nyaw_deg = 10.0\npitch_deg = 0.0\n\
                    [[key]]\nlonlat = [-78.6, 35.7, 900.0]\nheading_deg = 90.0\npitch_deg = -5.0\nabove_ground = true\n";
        let mut seen = Vec::new();
        let path = CameraPath::parse_placed(text, "earth", &mut |key| {
            seen.push(*key);
            Ok(Keyframe {
                at: [1.0, 2.0, key.lonlat[2]],
                yaw_deg: key.heading_deg - 1.0,
                pitch_deg: key.pitch_deg,
            })
        })
        .unwrap();
        assert_eq!(
            seen,
            [EarthKey {
                lonlat: [-78.6, 35.7, 900.0],
                heading_deg: 90.0,
                pitch_deg: -5.0,
                above_ground: true
            }]
        );
        assert_eq!(path.keys[1], Keyframe { at: [1.0, 2.0, 900.0], yaw_deg: 89.0, pitch_deg: -5.0 });
        assert_eq!(path.keys[0].at, [5.0, 6.0, 7.0]);
        // Without a dataset to place them, refused with the keyframe named.
        let refused = CameraPath::parse(text, "earth").unwrap_err();
        assert!(matches!(refused, PathError::Place { index: 1, .. }), "{refused}");
        let failed =
            CameraPath::parse_placed(text, "earth", &mut |_| Err("beyond the CRS".into())).unwrap_err();
        assert!(failed.to_string().contains("keyframe 1: beyond the CRS"), "{failed}");
        // Both forms at once, or half of one, is neither.
        let both =
            "[[key]]\nat = [0.0, 0.0, 0.0]\nyaw_deg = 0.0\nlonlat = [0.0, 0.0, 0.0]\npitch_deg = 0.0\n";
        let half = "[[key]]\nlonlat = [0.0, 0.0, 0.0]\npitch_deg = 0.0\n";
        for text in [both, half] {
            let e = CameraPath::parse_placed(text, "mixed", &mut |_| unreachable!()).unwrap_err();
            assert!(e.to_string().contains("give `at` and `yaw_deg`"), "{e}");
        }
    }

    #[test]
    fn bad_paths_are_clear_errors() {
        assert!(matches!(CameraPath::parse("key = []", "empty"), Err(PathError::Empty { .. })));
        let typo = "[[key]]\nat = [0.0, 0.0, 0.0]\nyaw = 0.0\npitch_deg = 0.0\n";
        assert!(CameraPath::parse(typo, "typo").unwrap_err().to_string().contains("yaw"));
        let nan = "[[key]]\nat = [nan, 0.0, 0.0]\nyaw_deg = 0.0\npitch_deg = 0.0\n";
        assert!(matches!(CameraPath::parse(nan, "nan"), Err(PathError::NotFinite { index: 0, .. })));
    }
}
