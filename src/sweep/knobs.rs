//! How it works: the points of a sweep. Each point is a preset plus, for every `--knob`, one of
//! its values: the points are the cartesian product of the presets and the knobs' values, in the
//! order given. A knob is a settings key with dots (`seeds.occlusion_tolerance_m`) and a list of
//! values separated by commas, commas inside brackets excepted (`tlm.radial_bands_m=[500,1000,2000],
//! [700,1400,3000]`). Each value becomes a one-key TOML layer over the preset (and over the user's
//! settings file), so it goes through the same key and range checks as any settings file; a value
//! that is not TOML (`fast`) is taken as a string. Settings that only make sense together are one
//! knob of several keys joined by `+`, each value their values joined by `+` in the same order
//! (`tlm.radial_bands_m+draw_seeds.reach_m=[700,1400,4000]+[200,700,1400,4000]`): the layers
//! are checked once all of them are laid.

use std::str::FromStr;

use crate::config::{PRESETS, Settings, SettingsError};

/// One `--knob key=v1,v2,...`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Knob {
    /// The settings key, with dots (`seeds.occlusion_tolerance_m`).
    pub key: String,
    /// Its values, each as TOML text (or a bare string), in the order given.
    pub values: Vec<String>,
}

impl FromStr for Knob {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let (key, values) = text
            .split_once('=')
            .ok_or_else(|| format!("`{text}`: expected KEY=V1,V2,... (e.g. seeds.frustum_epsilon=0,0.01)"))?;
        let key = key.trim();
        let keys: Vec<&str> = key.split('+').map(str::trim).collect();
        for k in &keys {
            let parts: Vec<&str> = k.split('.').collect();
            if parts.len() < 2
                || parts
                    .iter()
                    .any(|p| p.is_empty() || !p.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
            {
                return Err(format!("`{k}`: expected a settings key such as seeds.occlusion_tolerance_m"));
            }
        }
        let values = split_outside_brackets(values, ',');
        if values.is_empty() || values.iter().any(String::is_empty) {
            return Err(format!("`{text}`: every value must be non-empty"));
        }
        if let Some(v) = values.iter().find(|v| split_outside_brackets(v, '+').len() != keys.len()) {
            return Err(format!("`{v}`: {} keys need {} values joined by +", keys.len(), keys.len()));
        }
        Ok(Self { key: keys.join("+"), values })
    }
}

/// Splits at `separator` outside brackets, trimming each part.
fn split_outside_brackets(text: &str, separator: char) -> Vec<String> {
    let mut values = Vec::new();
    let (mut depth, mut current) = (0i32, String::new());
    for c in text.chars() {
        match c {
            '[' => depth += 1,
            ']' => depth -= 1,
            c if c == separator && depth == 0 => {
                values.push(current.trim().to_owned());
                current.clear();
                continue;
            }
            _ => {}
        }
        current.push(c);
    }
    values.push(current.trim().to_owned());
    values
}

/// The TOML layer that sets `key` (dotted) to `value`.
fn layer_text(key: &str, value: &str) -> String {
    let (table, leaf) = key.rsplit_once('.').unwrap_or(("", key));
    let line = format!("{leaf} = {value}\n");
    let line = match line.parse::<toml::Table>() {
        Ok(_) => line,
        Err(_) => format!("{leaf} = {}\n", toml::Value::String(value.to_owned())),
    };
    format!("[{table}]\n{line}")
}

/// A preset and the knob values that override it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Point {
    /// The preset the point starts from (`fast`, `balanced`, `accurate`).
    pub preset: String,
    /// (key, value) pairs, in the order of the `--knob` arguments.
    pub knobs: Vec<(String, String)>,
}

impl Point {
    /// `preset`, then ` key=value` for each knob.
    pub fn label(&self) -> String {
        let mut label = self.preset.clone();
        for (key, value) in &self.knobs {
            label.push_str(&format!(" {key}={value}"));
        }
        label
    }

    /// The knobs as `key=value;key=value`.
    pub fn knobs_text(&self) -> String {
        self.knobs.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(";")
    }

    /// The defaults, the preset, the user's layer `user` (origin, TOML text) if any, then the knobs.
    pub fn settings(&self, user: Option<&(String, String)>) -> Result<Settings, SettingsError> {
        let (_, preset_text) = PRESETS
            .iter()
            .find(|(name, _)| *name == self.preset)
            .ok_or_else(|| SettingsError::UnknownPreset(self.preset.clone()))?;
        let mut layers = vec![(format!("preset {}", self.preset), (*preset_text).to_owned())];
        layers.extend(user.cloned());
        for (key, value) in &self.knobs {
            let origin = format!("--knob {key}={value}");
            for (k, v) in key.split('+').zip(split_outside_brackets(value, '+')) {
                layers.push((origin.clone(), layer_text(k, &v)));
            }
        }
        Settings::from_layers(&layers)
    }
}

/// Every preset with every combination of the knobs' values, presets outermost.
pub fn points(presets: &[String], knobs: &[Knob]) -> Vec<Point> {
    let mut points: Vec<Point> =
        presets.iter().map(|preset| Point { preset: preset.clone(), knobs: Vec::new() }).collect();
    for knob in knobs {
        points = points
            .iter()
            .flat_map(|p| {
                knob.values.iter().map(move |v| {
                    let mut knobs = p.knobs.clone();
                    knobs.push((knob.key.clone(), v.clone()));
                    Point { preset: p.preset.clone(), knobs }
                })
            })
            .collect();
    }
    points
}

/// Each preset as it is, then each preset of `from` (every one of `presets` when empty) with one
/// knob set to one of its values, knob by knob: one series per knob, the others left at the
/// preset's (what a front over many knobs needs: their product would be thousands of points).
pub fn series(presets: &[String], from: &[String], knobs: &[Knob]) -> Vec<Point> {
    let alone = presets.iter().map(|preset| Point { preset: preset.clone(), knobs: Vec::new() });
    let from = if from.is_empty() { presets } else { from };
    let varied = knobs.iter().flat_map(|knob| {
        knob.values.iter().flat_map(move |v| {
            from.iter().map(move |preset| Point {
                preset: preset.clone(),
                knobs: vec![(knob.key.clone(), v.clone())],
            })
        })
    });
    alone.chain(varied).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn series_vary_one_knob_at_a_time() {
        let presets = ["fast".to_owned(), "accurate".to_owned()];
        let knobs: Vec<Knob> =
            ["seeds.density_scale=0.25,0.5,1", "tlm.cells=16"].iter().map(|k| k.parse().unwrap()).collect();
        let labels: Vec<String> = series(&presets, &[], &knobs).iter().map(Point::label).collect();
        assert_eq!(
            labels,
            [
                "fast",
                "accurate",
                "fast seeds.density_scale=0.25",
                "accurate seeds.density_scale=0.25",
                "fast seeds.density_scale=0.5",
                "accurate seeds.density_scale=0.5",
                "fast seeds.density_scale=1",
                "accurate seeds.density_scale=1",
                "fast tlm.cells=16",
                "accurate tlm.cells=16"
            ]
        );
        // The product instead crosses them: 2 presets × 3 × 1.
        assert_eq!(points(&presets, &knobs).len(), 6);
        // Series from one preset only, the others measured as they are.
        let from = ["accurate".to_owned()];
        let labels: Vec<String> = series(&presets, &from, &knobs[1..]).iter().map(Point::label).collect();
        assert_eq!(labels, ["fast", "accurate", "accurate tlm.cells=16"]);
    }

    #[test]
    fn knobs_parse_with_arrays_and_strings() {
        let k: Knob = "seeds.occlusion_tolerance_m=0.5, 1,2".parse().unwrap();
        assert_eq!(
            (k.key.as_str(), k.values.clone()),
            ("seeds.occlusion_tolerance_m", vec!["0.5".into(), "1".into(), "2".into()])
        );
        let k: Knob = "tlm.radial_bands_m=[500,1000,2000],[700, 1400, 3000]".parse().unwrap();
        assert_eq!(k.values, ["[500,1000,2000]", "[700, 1400, 3000]"]);
        assert!("seeds".parse::<Knob>().is_err());
        assert!("frustum_epsilon=0".parse::<Knob>().is_err());
        assert!("seeds.frustum_epsilon=0,".parse::<Knob>().is_err());
        // Keys that go together: as many values per point, joined by +.
        let k: Knob =
            "tlm.radial_bands_m+draw_seeds.reach_m=[700,1400,4000]+[200,700,1400,4000]".parse().unwrap();
        assert_eq!((k.key.as_str(), k.values.len()), ("tlm.radial_bands_m+draw_seeds.reach_m", 1));
        assert!("tlm.cells+seeds.density_scale=32".parse::<Knob>().is_err());
        let s = Point { preset: "balanced".into(), knobs: vec![(k.key, k.values[0].clone())] }
            .settings(None)
            .unwrap();
        assert_eq!((s.tlm.radial_bands_m[2], s.draw_seeds.reach_m[3]), (4000.0, 4000.0));
        // Each alone would be refused (a reach beyond the last band); together they are checked once.
        let alone = Point {
            preset: "balanced".into(),
            knobs: vec![("draw_seeds.reach_m".into(), "[200,700,1400,4000]".into())],
        };
        assert!(alone.settings(None).is_err());
    }

    #[test]
    fn points_are_the_product_and_settings_apply_in_order() {
        let presets = vec!["fast".to_owned(), "accurate".to_owned()];
        let knobs: Vec<Knob> = ["seeds.frustum_epsilon=0,0.05", "terrain.triangle_px=3"]
            .iter()
            .map(|k| k.parse().unwrap())
            .collect();
        let points = points(&presets, &knobs);
        let labels: Vec<String> = points.iter().map(Point::label).collect();
        assert_eq!(
            labels,
            [
                "fast seeds.frustum_epsilon=0 terrain.triangle_px=3",
                "fast seeds.frustum_epsilon=0.05 terrain.triangle_px=3",
                "accurate seeds.frustum_epsilon=0 terrain.triangle_px=3",
                "accurate seeds.frustum_epsilon=0.05 terrain.triangle_px=3",
            ]
        );
        let user = (
            "user.toml".to_owned(),
            "[terrain]\ntriangle_px = 5.0\n[draw_seeds]\nimpostors = \"x\"\n".to_owned(),
        );
        let s = points[3].settings(Some(&user)).unwrap();
        assert_eq!(
            (s.seeds.frustum_epsilon, s.terrain.triangle_px, s.draw_seeds.impostors.as_str()),
            (0.05, 3.0, "x")
        );
        assert_eq!(s.seeds.seeds_per_pattern, Settings::preset("accurate").unwrap().seeds.seeds_per_pattern);
        assert_eq!(points[3].knobs_text(), "seeds.frustum_epsilon=0.05;terrain.triangle_px=3");
        // A value that is not TOML is a string; a string where a number belongs names the key.
        let k = Point { preset: "balanced".into(), knobs: vec![("seeds.class_table".into(), "nlcd".into())] };
        assert_eq!(k.settings(None).unwrap().seeds.class_table, "nlcd");
        let bad =
            Point { preset: "balanced".into(), knobs: vec![("seeds.frustum_epsilon".into(), "wide".into())] };
        let err = bad.settings(None).unwrap_err().to_string();
        assert!(err.contains("seeds.frustum_epsilon"), "{err}");
        let typo =
            Point { preset: "balanced".into(), knobs: vec![("seeds.frustum_epsilonn".into(), "0".into())] };
        assert!(typo.settings(None).unwrap_err().to_string().contains("frustum_epsilonn"));
        assert!(Point { preset: "ludicrous".into(), knobs: vec![] }.settings(None).is_err());
    }
}
