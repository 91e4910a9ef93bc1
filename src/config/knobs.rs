//! How it works: the knobs a person turns while flying (`terramp view`): the settings that trade
//! speed for accuracy, each with its range and whether a running renderer takes it at its next
//! frame (`Apply::Live`: it is read while the frame is prepared, into uniforms, the terrain's
//! selection or the streaming's wants) or must be remade (`Apply::Remake`: it sizes buffers or
//! builds the species tables, once, in `Renderer::new`). `tests/knobs.rs` holds the renderer to
//! that split: a live knob turned on a running renderer draws what a renderer made with it draws.
//!
//! A knob's value is an `f64` whatever its field's type; `layer` writes the knobs' fields back as
//! a TOML settings layer, so a view flown with turned knobs can be rendered again headless.

use std::ops::RangeInclusive;

use toml::{Table, Value};

use super::{Settings, time};

/// Where the time-of-day knob rests while no time is set.
const NO_TIME_SHOWN_H: f64 = 12.0;

/// When a running renderer takes a knob's new value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Apply {
    /// At the next frame: set `Renderer::settings` and render.
    Live,
    /// Only once the renderer is made again (`Renderer::remake`): it sizes GPU resources or
    /// builds tables once.
    Remake,
}

/// One setting a person can turn.
pub struct Knob {
    /// What it is, in words, for a label.
    pub label: &'static str,
    /// Its field in the settings files, dotted (`seeds.density_scale`).
    pub key: &'static str,
    /// The unit of its value, or "" when it has none.
    pub unit: &'static str,
    /// The values offered (the settings may hold others).
    pub range: RangeInclusive<f64>,
    /// Offered on a logarithmic scale.
    pub logarithmic: bool,
    /// Only whole numbers.
    pub integer: bool,
    /// When a running renderer takes it.
    pub apply: Apply,
    /// Its value in `settings`.
    pub get: fn(&Settings) -> f64,
    /// Sets it in `settings` (range-check the settings afterwards: `Settings::validate`).
    pub set: fn(&mut Settings, f64),
    /// Its whole field as TOML (an array for one distance of several).
    pub field: fn(&Settings) -> Value,
    /// What a panel says beside it in `settings`, where its value alone would mislead.
    pub note: fn(&Settings) -> Option<&'static str>,
}

fn floats<const N: usize>(values: [f64; N]) -> Value {
    Value::Array(values.iter().map(|&v| Value::Float(v)).collect())
}

/// A knob over an `f64` field: `$place` is the field (an element of an array, for one distance of
/// several), `$field` the whole field as TOML; `then` what setting it also does.
macro_rules! knob {
    ($label:literal, $key:literal, $unit:literal, $range:expr, $scale:ident, $apply:ident, |$s:ident| $place:expr, $field:expr $(, then $then:expr)?) => {
        Knob {
            label: $label,
            key: $key,
            unit: $unit,
            range: $range,
            logarithmic: Scale::$scale.logarithmic(),
            integer: false,
            apply: Apply::$apply,
            get: |$s| $place,
            set: |$s, value| {
                $place = value;
                $($then;)?
            },
            field: |$s| $field,
            note: |_| None,
        }
    };
}

/// How a slider spreads a knob's range.
enum Scale {
    Linear,
    Log,
}

impl Scale {
    const fn logarithmic(self) -> bool {
        matches!(self, Self::Log)
    }
}

/// The knobs, in the order a panel shows them: what is drawn, how far, how fine, then the weather.
#[rustfmt::skip]
pub const KNOBS: &[Knob] = &[
    knob!("density scale", "seeds.density_scale", "×", 0.02..=1.0, Log, Remake,
        |s| s.seeds.density_scale, Value::Float(s.seeds.density_scale)),
    knob!("mesh reach", "draw_seeds.reach_m", "m", 0.0..=5000.0, Linear, Live,
        |s| s.draw_seeds.reach_m[0], floats(s.draw_seeds.reach_m)),
    knob!("seed reach", "draw_seeds.reach_m", "m", 100.0..=20000.0, Log, Live,
        |s| s.draw_seeds.reach_m[3], floats(s.draw_seeds.reach_m)),
    knob!("radial band 1", "tlm.radial_bands_m", "m", 100.0..=20000.0, Log, Live,
        |s| s.tlm.radial_bands_m[0], floats(s.tlm.radial_bands_m)),
    knob!("radial band 2", "tlm.radial_bands_m", "m", 100.0..=20000.0, Log, Live,
        |s| s.tlm.radial_bands_m[1], floats(s.tlm.radial_bands_m)),
    knob!("radial band 3", "tlm.radial_bands_m", "m", 100.0..=20000.0, Log, Live,
        |s| s.tlm.radial_bands_m[2], floats(s.tlm.radial_bands_m)),
    knob!("seed occlusion tolerance", "seeds.occlusion_tolerance_m", "m", 0.0..=100.0, Linear, Live,
        |s| s.seeds.occlusion_tolerance_m, Value::Float(s.seeds.occlusion_tolerance_m)),
    knob!("seed occlusion tolerance per km", "seeds.occlusion_tolerance_per_km", "m/km", 0.0..=100.0, Linear, Live,
        |s| s.seeds.occlusion_tolerance_per_km, Value::Float(s.seeds.occlusion_tolerance_per_km)),
    knob!("TLM occlusion tolerance", "tlm.occlusion_tolerance_m", "m", 0.0..=500.0, Linear, Live,
        |s| s.tlm.occlusion_tolerance_m, Value::Float(s.tlm.occlusion_tolerance_m)),
    Knob {
        label: "TLM cells per ring side",
        key: "tlm.cells",
        unit: "",
        range: 8.0..=256.0,
        logarithmic: true,
        integer: true,
        apply: Apply::Remake,
        get: |s| f64::from(s.tlm.cells),
        // Even, as the TLM's rings need.
        set: |s, v| s.tlm.cells = (v / 2.0).round() as u32 * 2,
        field: |s| Value::Integer(i64::from(s.tlm.cells)),
        note: |_| None,
    },
    knob!("terrain triangle size", "terrain.triangle_px", "px", 1.0..=64.0, Log, Live,
        |s| s.terrain.triangle_px, Value::Float(s.terrain.triangle_px)),
    knob!("imagery LOD bias", "imagery.lod_bias", "levels", -2.0..=2.0, Linear, Live,
        |s| s.imagery.lod_bias, Value::Float(s.imagery.lod_bias)),
    knob!("wind speed", "wind.speed_m_s", "m/s", 0.0..=super::MAX_WIND_M_S, Linear, Live,
        |s| s.wind.speed_m_s, Value::Float(s.wind.speed_m_s)),
    knob!("cloud cover", "clouds.coverage", "", 0.0..=1.0, Linear, Live,
        |s| s.clouds.coverage, Value::Float(s.clouds.coverage)),
    // The sun by its two angles, or by the time of day over the dataset's place on the Earth:
    // turning an angle lets the angles place it again.
    knob!("sun elevation", "render.sun_elevation_deg", "°", -20.0..=90.0, Linear, Live,
        |s| s.render.sun_elevation_deg, Value::Float(s.render.sun_elevation_deg), then s.render.sun_time.clear()),
    knob!("sun azimuth", "render.sun_azimuth_deg", "°", 0.0..=360.0, Linear, Live,
        |s| s.render.sun_azimuth_deg, Value::Float(s.render.sun_azimuth_deg), then s.render.sun_time.clear()),
    Knob {
        label: "time of day",
        key: "render.sun_time",
        unit: "h UTC",
        // To a quarter to midnight: a day's last instant is the next day's first.
        range: 0.0..=23.75,
        logarithmic: false,
        integer: false,
        apply: Apply::Live,
        get: |s| time::time_of_day_h(&s.render.sun_time).unwrap_or(NO_TIME_SHOWN_H),
        set: |s, hours| s.render.sun_time = time::at_time_of_day(&s.render.sun_time, hours),
        field: |s| Value::String(s.render.sun_time.clone()),
        note: |s| time::parse_instant(&s.render.sun_time).is_none().then_some("unset: the angles place the sun"),
    },
    knob!("exposure", "display.ev100", "EV100", 4.0..=18.0, Linear, Live,
        |s| s.display.ev100, Value::Float(s.display.ev100)),
];

/// `base` (a settings layer, or empty) with every knob's field set to its value in `settings`,
/// and the viewport's size: a layer that, over the same preset, gives `settings` back as far as
/// the knobs and the viewport go.
pub fn layer(settings: &Settings, mut base: Table) -> Table {
    let viewport = [
        ("render.width", Value::Integer(i64::from(settings.render.width))),
        ("render.height", Value::Integer(i64::from(settings.render.height))),
    ];
    let knobs = KNOBS.iter().map(|k| (k.key, (k.field)(settings)));
    for (key, value) in viewport.into_iter().chain(knobs) {
        let (section, name) = key.split_once('.').unwrap_or(("", key));
        let table = base.entry(section).or_insert_with(|| Value::Table(Table::new()));
        if !table.is_table() {
            *table = Value::Table(Table::new());
        }
        if let Value::Table(table) = table {
            table.insert(name.to_owned(), value);
        }
    }
    base
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_knob_sets_what_it_gets_and_its_range_holds_valid_settings() {
        for knob in KNOBS {
            for value in [*knob.range.start(), *knob.range.end()] {
                let mut settings = Settings::default();
                (knob.set)(&mut settings, value);
                assert_eq!((knob.get)(&settings), value, "{}", knob.label);
            }
            let mut settings = Settings::default();
            let middle = (knob.range.start() + knob.range.end()) / 2.0;
            (knob.set)(&mut settings, middle);
            // One distance of several must keep their order; every other knob is free in its range.
            if !(knob.field)(&settings).is_array() {
                settings.validate().unwrap_or_else(|e| panic!("{}: {e}", knob.label));
            }
        }
    }

    #[test]
    fn the_time_of_day_places_the_sun_until_an_angle_is_turned() {
        let knob = |label: &str| KNOBS.iter().find(|k| k.label == label).unwrap();
        let (time, elevation) = (knob("time of day"), knob("sun elevation"));
        let mut settings = Settings::default();
        settings.render.sun_time = "2026-06-21T13:30-04:00".into();
        assert_eq!(((time.get)(&settings), (time.note)(&settings)), (17.5, None));
        (time.set)(&mut settings, 6.25);
        assert_eq!(settings.render.sun_time, "2026-06-21T06:15:00Z");
        (elevation.set)(&mut settings, 30.0);
        assert_eq!(settings.render.sun_time, "");
        assert!((time.note)(&settings).is_some());
    }

    #[test]
    fn the_layer_gives_the_knobs_and_the_viewport_back_over_the_same_preset() {
        let mut turned = Settings::preset("fast").unwrap();
        for knob in KNOBS {
            let value = if knob.integer { 40.0 } else { (knob.get)(&turned) * 0.5 + 0.25 };
            (knob.set)(&mut turned, value);
        }
        turned.render.width = 333;
        let user: Table = toml::from_str("[render]\nfov_deg = 50.0\n").unwrap();
        let text = toml::to_string(&layer(&turned, user)).unwrap();
        let again = Settings::from_layers(&[
            ("preset fast".into(), crate::config::PRESETS[0].1.into()),
            ("shot".into(), text),
        ])
        .unwrap();
        for knob in KNOBS {
            assert_eq!((knob.get)(&again), (knob.get)(&turned), "{}", knob.label);
        }
        assert_eq!((again.render.width, again.render.fov_deg), (333, 50.0));
    }
}
