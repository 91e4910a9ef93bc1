//! How it works: where the sun is, from a date and time and the place on the Earth under the
//! camera. `render.sun_time` (or `--time`) names a UTC instant; the camera's grid position, through
//! the dataset's `[earth]`, gives its WGS 84 latitude and longitude; NREL's Solar Position
//! Algorithm (Reda & Andreas 2004, through the `solar-positioning` crate, stated ±0.0003° over
//! years −2000 to 6000, ΔT estimated from the date) gives the sun's topocentric azimuth and
//! zenith there, without refraction (the atmosphere pass draws straight rays). That direction is
//! turned from the camera's east–north–up into Earth-centred axes and then into the frame's
//! camera-relative world (`LocalFrame::grid_aligned`, whose zenith is the camera's), so across a
//! large dataset the one direction meets each place's own vertical at that place's elevation.
//! Without a time, `[render] sun_azimuth_deg` and `sun_elevation_deg` place it (`light::sun_dir`).

use chrono::{DateTime, Utc};
use glam::DVec3;
use solar_positioning::{Location, SolarPositions, delta_t};

use crate::config::RenderSettings;
use crate::config::time::parse_instant;
use crate::dataset::Manifest;
use crate::earth::EarthFrame;
use crate::earth::ellipsoid::Ellipsoid;
use crate::earth::local::{LocalFrame, local_from_ecef};
use crate::light::sun_dir;

/// Why the sun could not be placed.
#[derive(Debug, thiserror::Error)]
pub enum SunError {
    /// `render.sun_time` is not a date and time this reads.
    #[error(
        "render.sun_time = {0:?} is not a date and time: write it as RFC 3339, e.g. \
         2026-06-21T17:30Z or 2026-06-21T13:30:00-04:00"
    )]
    Time(String),
    /// A time was given for a dataset that does not record where it lies.
    #[error(
        "render.sun_time places the sun over the Earth, and this dataset does not record where it \
         lies ([earth] in its manifest: rebuild it with terramp-data build)"
    )]
    NoEarth,
    /// The algorithm refused the instant or the place.
    #[error("the sun's position at {time}: {why}")]
    Position {
        /// The instant.
        time: String,
        /// The algorithm's words.
        why: String,
    },
}

/// Reads `text` as an instant: RFC 3339, seconds optional (`2026-06-21T17:30Z`).
pub fn parse_time(text: &str) -> Result<DateTime<Utc>, SunError> {
    parse_instant(text).ok_or_else(|| SunError::Time(text.to_owned()))
}

/// The sun's topocentric azimuth (degrees clockwise from true north) and zenith angle (degrees),
/// without refraction, at `time` over WGS 84 latitude `lat_deg`, longitude `lon_deg`, `height_m`
/// above sea level.
pub fn position_deg(
    time: &DateTime<Utc>,
    lat_deg: f64,
    lon_deg: f64,
    height_m: f64,
) -> Result<(f64, f64), SunError> {
    let fail =
        |e: solar_positioning::Error| SunError::Position { time: time.to_rfc3339(), why: e.to_string() };
    let delta_t_s = delta_t::estimate_from_date_like(time).map_err(fail)?;
    let location = Location { latitude: lat_deg, longitude: lon_deg };
    let position = SolarPositions::new().at(time, location, height_m, delta_t_s, None).map_err(fail)?;
    Ok((position.azimuth(), position.zenith_angle()))
}

/// Towards the sun at `time` from the camera at grid position `camera_crs_m` (CRS metres, height
/// above the datum) of a dataset placed by `earth`, in the frame's camera-relative world.
pub fn sun_dir_at(earth: &EarthFrame, camera_crs_m: DVec3, time: &DateTime<Utc>) -> Result<DVec3, SunError> {
    let frame = LocalFrame::grid_aligned(earth, camera_crs_m.x, camera_crs_m.y, camera_crs_m.z);
    let (lat, lon, height_m) = Ellipsoid::WGS84.geodetic(frame.eye_ecef_m);
    let (azimuth, zenith) = position_deg(time, lat.to_degrees(), lon.to_degrees(), height_m)?;
    let (azimuth, elevation) = (azimuth.to_radians(), (90.0 - zenith).to_radians());
    let east_north_up =
        DVec3::new(azimuth.sin() * elevation.cos(), azimuth.cos() * elevation.cos(), elevation.sin());
    let ecef = local_from_ecef(lat, lon).transpose() * east_north_up;
    Ok(frame.turn(ecef).normalize())
}

/// The frame's sun: from `render.sun_time` where it is set (over `earth`, from the camera at
/// `camera_crs_m`), else from the settings' angles.
pub fn frame_sun_dir(
    render: &RenderSettings,
    earth: Option<&EarthFrame>,
    camera_crs_m: DVec3,
) -> Result<DVec3, SunError> {
    if render.sun_time.trim().is_empty() {
        return Ok(sun_dir(render));
    }
    let time = parse_time(&render.sun_time)?;
    sun_dir_at(earth.ok_or(SunError::NoEarth)?, camera_crs_m, &time)
}

/// Whether `render.sun_time` can place the sun over the dataset of `manifest` (at its origin):
/// a renderer checks once, before any frame.
pub fn check(render: &RenderSettings, manifest: &Manifest) -> Result<(), SunError> {
    let [x, y] = manifest.origin_m;
    frame_sun_dir(render, manifest.earth.as_ref(), DVec3::new(x, y, 0.0)).map(|_| ())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::earth::test_frames;

    #[test]
    fn the_spa_papers_worked_example() {
        // Reda & Andreas (2004), table A5.1: 17 October 2003, 12:30:30 at UTC−7, 39.742476° N
        // 105.1786° W, 1,830.14 m, ΔT 67 s, 820 mbar and 11 °C for refraction: topocentric zenith
        // 50.11162°, azimuth 194.34024°. With refraction as the paper's, the crate's zenith; ours
        // leaves refraction out, which lowers the sun by the paper's own correction there.
        let time = solar_positioning::time::JulianDate::from_utc(2003, 10, 17, 19, 30, 30.0, 67.0).unwrap();
        let place = Location { latitude: 39.742476, longitude: -105.1786 };
        let refraction = solar_positioning::RefractionCorrection::new(820.0, 11.0).unwrap();
        let spa = SolarPositions::new();
        let paper = spa.at_from_julian(time, place, 1830.14, Some(refraction)).unwrap();
        assert!((paper.zenith_angle() - 50.11162).abs() < 1e-5, "{}", paper.zenith_angle());
        assert!((paper.azimuth() - 194.34024).abs() < 1e-5, "{}", paper.azimuth());
        let utc = parse_time("2003-10-17T12:30:30-07:00").unwrap();
        let (azimuth, zenith) = position_deg(&utc, 39.742476, -105.1786, 1830.14).unwrap();
        // ΔT estimated from the date instead of the paper's 67 s: a few seconds of the Earth's
        // turn, 0.01° at most.
        assert!((azimuth - 194.34024).abs() < 0.01, "{azimuth}");
        let unrefracted = spa.at_from_julian(time, place, 1830.14, None).unwrap().zenith_angle();
        assert!((zenith - unrefracted).abs() < 0.01 && zenith > 50.11162, "{zenith} against {unrefracted}");
    }

    #[test]
    fn a_time_it_cannot_read_is_named() {
        // How times read is `config::time`'s test; here, that a bad one is named as the setting.
        assert!(parse_time("2026-06-21T17:30Z").is_ok());
        for bad in ["", "noon", "2026-06-21 17:30"] {
            let error = parse_time(bad).unwrap_err();
            assert!(matches!(&error, SunError::Time(t) if t == bad), "{bad}");
            assert!(error.to_string().contains("render.sun_time"), "{error}");
        }
    }

    #[test]
    fn across_a_large_dataset_the_sun_meets_each_place_at_its_own_elevation() {
        // GLOBE's frame: the camera over the centre, a place 2,000 km east. The one direction
        // the frame holds, against the far place's own vertical (turned into the camera's frame),
        // is the elevation SPA gives there: the sun's parallax over 2,000 km is 0.0008°.
        let earth = test_frames::globe();
        let time = parse_time("2026-06-21T09:00Z").unwrap();
        let camera = DVec3::new(0.0, 0.0, 10_000.0);
        let sun = sun_dir_at(&earth, camera, &time).unwrap();
        let frame = LocalFrame::grid_aligned(&earth, camera.x, camera.y, camera.z);
        for far in [DVec3::new(2_000_000.0, 0.0, 0.0), DVec3::new(0.0, -1_500_000.0, 0.0)] {
            let ecef = earth.ecef_m(far.x, far.y, far.z);
            let (lat, lon, _) = Ellipsoid::WGS84.geodetic(ecef);
            let up_there = frame.turn(local_from_ecef(lat, lon).transpose() * DVec3::Z);
            let (_, zenith) = position_deg(&time, lat.to_degrees(), lon.to_degrees(), 0.0).unwrap();
            let seen = 90.0 - sun.dot(up_there).clamp(-1.0, 1.0).acos().to_degrees();
            assert!(
                (seen - (90.0 - zenith)).abs() < 0.005,
                "{far}: {seen}° against SPA's {}°",
                90.0 - zenith
            );
            let here = 90.0 - sun.z.acos().to_degrees();
            assert!(
                (seen - here).abs() > 5.0,
                "the far place sees the sun as the camera does: {seen}° {here}°"
            );
        }
    }
}
