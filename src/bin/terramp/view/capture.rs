//! How it works: what the viewer writes. F12 saves the 3D frame (without the overlay) as
//! `shot_NNNN.png` beside `shot_NNNN.toml`: a settings file (the user's `--settings` file with
//! every knob's value and the viewport written over it, `config::knobs::layer`) whose header
//! gives the `terramp render` line that renders the same view headless from it. P records the
//! flown path: a keyframe every `KEY_INTERVAL_S` seconds of flight, written when P is pressed
//! again as `path_NNNN.toml` in the `config/paths/` format that `fly` and `profile` read (keys
//! equally spaced in time, as `fly` spaces its frames along them). Files are numbered past the
//! highest already in the folder, so nothing is overwritten.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::config::knobs;

/// Seconds of flight between recorded keyframes.
pub const KEY_INTERVAL_S: f64 = 1.0;

/// The `terramp render` line of a view, with `settings_file` if the view needs one.
pub fn render_line(
    dataset: &Path,
    preset: &str,
    settings_file: Option<&Path>,
    camera: &Camera,
    time_s: f64,
    out: &Path,
) -> String {
    let p = camera.position_m;
    let settings = settings_file.map(|f| format!(" --settings {}", f.display())).unwrap_or_default();
    format!(
        "terramp render --dataset {} --preset {preset}{settings} --camera {:.3},{:.3},{:.3},{:.3},{:.3} --fov {} --time-s {time_s:.3} --out {}",
        dataset.display(),
        p.x,
        p.y,
        p.z,
        camera.yaw_deg,
        camera.pitch_deg,
        camera.fov_deg,
        out.display()
    )
}

/// The next free `{stem}_NNNN.{ext}` in `dir` (past the highest number there).
fn next_numbered(dir: &Path, stem: &str, ext: &str) -> Result<PathBuf> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let prefix = format!("{stem}_");
    let highest = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter_map(|name| name.strip_prefix(&prefix)?.split('.').next()?.parse::<u32>().ok())
        .max();
    let n = highest.map_or(1, |h| h + 1);
    Ok(dir.join(format!("{stem}_{n:04}.{ext}")))
}

/// What a screenshot needs besides the image.
pub struct Shot<'a> {
    pub dataset: &'a Path,
    pub preset: &'a str,
    /// The user's `--settings` file, whose keys the shot's settings keep.
    pub user_settings: Option<&'a Path>,
    pub settings: &'a Settings,
    pub camera: &'a Camera,
    pub time_s: f64,
}

/// Writes `image` and its settings file into `dir`; returns the image's path and the render line.
pub fn screenshot(dir: &Path, image: &image::RgbaImage, shot: &Shot) -> Result<(PathBuf, String)> {
    let png = next_numbered(dir, "shot", "png")?;
    let toml_path = png.with_extension("toml");
    let base = match shot.user_settings {
        Some(file) => {
            let text =
                std::fs::read_to_string(file).with_context(|| format!("reading {}", file.display()))?;
            toml::from_str(&text).with_context(|| format!("{}: not a settings table", file.display()))?
        }
        None => toml::Table::new(),
    };
    let layer = knobs::layer(shot.settings, base);
    let headless = png.with_file_name(format!(
        "{}_headless.png",
        png.file_stem().and_then(|s| s.to_str()).unwrap_or("shot")
    ));
    let line = render_line(shot.dataset, shot.preset, Some(&toml_path), shot.camera, shot.time_s, &headless);
    let text = format!(
        "# terramp view: the settings of {} (preset {}, the knobs as they were set).\n\
         # The same view, headless:\n#   {line}\n\n{}",
        png.display(),
        shot.preset,
        toml::to_string(&layer).context("writing the shot's settings")?
    );
    image.save(&png).with_context(|| format!("writing {}", png.display()))?;
    std::fs::write(&toml_path, text).with_context(|| format!("writing {}", toml_path.display()))?;
    Ok((png, line))
}

/// A path being recorded.
#[derive(Debug, Default)]
pub struct Recording {
    keys: Vec<Camera>,
    since_key_s: f64,
}

impl Recording {
    /// Keyframes so far.
    pub fn len(&self) -> usize {
        self.keys.len()
    }

    /// `dt_s` more seconds of flight, now at `camera`: a keyframe when the interval is up (and
    /// the first one at once).
    pub fn advance(&mut self, dt_s: f64, camera: &Camera) {
        self.since_key_s += dt_s;
        if self.keys.is_empty() || self.since_key_s >= KEY_INTERVAL_S {
            self.keys.push(*camera);
            self.since_key_s = 0.0;
        }
    }

    /// Ends the recording at `camera` and writes it into `dir`; `None` if nothing moved.
    pub fn finish(mut self, dir: &Path, camera: &Camera) -> Result<Option<PathBuf>> {
        if self.keys.last() != Some(camera) {
            self.keys.push(*camera);
        }
        if self.keys.len() < 2 {
            return Ok(None);
        }
        let file = next_numbered(dir, "path", "toml")?;
        std::fs::write(&file, path_toml(&self.keys))
            .with_context(|| format!("writing {}", file.display()))?;
        Ok(Some(file))
    }
}

/// `keys` as a camera path file (`config/paths/*.toml`).
fn path_toml(keys: &[Camera]) -> String {
    let mut text = format!(
        "# Flown in terramp view: a keyframe every {KEY_INTERVAL_S} s. Fly it with\n\
         # `terramp fly --path FILE` or time it with `terramp profile --path FILE`.\n"
    );
    for c in keys {
        let p = c.position_m;
        text += &format!(
            "\n[[key]]\nat = [{:.3}, {:.3}, {:.3}]\nyaw_deg = {:.3}\npitch_deg = {:.3}\n",
            p.x, p.y, p.z, c.yaw_deg, c.pitch_deg
        );
    }
    text
}

#[cfg(test)]
mod tests {
    use glam::DVec3;
    use terramp::path::CameraPath;

    use super::*;

    fn camera(x: f64, yaw_deg: f64) -> Camera {
        Camera {
            position_m: DVec3::new(x, 2.0, 300.0),
            yaw_deg,
            pitch_deg: -10.0,
            roll_deg: 0.0,
            fov_deg: 60.0,
            near_m: 0.1,
        }
    }

    #[test]
    fn a_recorded_path_is_read_back_by_fly_through_its_keyframes() {
        let dir = std::env::temp_dir().join(format!("terramp-view-path-{}", std::process::id()));
        let mut rec = Recording::default();
        for i in 0..25 {
            rec.advance(0.1, &camera(f64::from(i), f64::from(i) * 2.0));
        }
        assert_eq!(rec.len(), 3, "the first frame, then one a second");
        let last = camera(30.0, 50.0);
        let file = rec.finish(&dir, &last).unwrap().unwrap();
        assert!(file.ends_with("path_0001.toml"));
        let path = CameraPath::load(&file).unwrap();
        assert_eq!(path.keys.len(), 4);
        let end = path.camera_at(1.0, 60.0, 0.1);
        assert!((end.position_m - last.position_m).length() < 1e-3);
        assert!(Recording::default().finish(&dir, &last).unwrap().is_none());
        let again = Recording { keys: vec![camera(0.0, 0.0)], since_key_s: 0.0 }.finish(&dir, &last).unwrap();
        assert!(again.unwrap().ends_with("path_0002.toml"), "never over an earlier file");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_screenshots_settings_give_the_knobs_back_and_its_header_the_render_line() {
        let dir = std::env::temp_dir().join(format!("terramp-view-shot-{}", std::process::id()));
        let mut settings = Settings::preset("fast").unwrap();
        settings.terrain.triangle_px = 3.5;
        settings.render.width = 64;
        let cam = camera(5.0, 30.0);
        let shot = Shot {
            dataset: Path::new("data/default"),
            preset: "fast",
            user_settings: None,
            settings: &settings,
            camera: &cam,
            time_s: 2.5,
        };
        let (png, line) = screenshot(&dir, &image::RgbaImage::new(64, 36), &shot).unwrap();
        assert!(png.ends_with("shot_0001.png"));
        let text = std::fs::read_to_string(png.with_extension("toml")).unwrap();
        assert!(text.contains(&format!("#   {line}")));
        assert!(
            line.contains("--camera 5.000,2.000,300.000,30.000,-10.000") && line.contains("--time-s 2.500")
        );
        let toml_path = png.with_extension("toml");
        let again = Settings::load("fast", Some(&toml_path)).unwrap();
        assert_eq!((again.terrain.triangle_px, again.render.width), (3.5, 64));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
