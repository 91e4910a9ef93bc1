use super::*;

fn with(text: &str) -> Result<Settings, SettingsError> {
    Settings::from_layers(&[("test.toml".into(), text.into())])
}

#[test]
fn defaults_and_every_preset_load() {
    let defaults = Settings::default();
    assert_eq!(Settings::preset("balanced").unwrap(), defaults);
    let fast = Settings::preset("fast").unwrap();
    let accurate = Settings::preset("accurate").unwrap();
    assert!(fast.terrain.triangle_px > defaults.terrain.triangle_px);
    assert!(accurate.terrain.triangle_px < defaults.terrain.triangle_px);
    assert!(matches!(Settings::preset("ludicrous"), Err(SettingsError::UnknownPreset(_))));
}

#[test]
fn user_layers_override_only_their_keys() {
    let s = with("[render]\nwidth = 64\nfov_deg = 90\n").unwrap();
    assert_eq!((s.render.width, s.render.fov_deg), (64, 90.0));
    assert_eq!(s.render.height, Settings::default().render.height);
}

#[test]
fn errors_name_the_key() {
    let unknown = with("[render]\nfovv = 3.0\n").unwrap_err().to_string();
    assert!(unknown.contains("render.fovv") && unknown.contains("test.toml"), "{unknown}");
    let wrong = with("[render]\nwidth = \"wide\"\n").unwrap_err().to_string();
    assert!(wrong.contains("render.width") && wrong.contains("integer"), "{wrong}");
    let range = with("[render]\nfov_deg = 180.0\n").unwrap_err().to_string();
    assert!(range.contains("render.fov_deg"), "{range}");
    let cells = with("[terrain]\nnode_cells = 48\n").unwrap_err().to_string();
    assert!(cells.contains("terrain.node_cells"), "{cells}");
    let adapter = with("[gpu]\nadapter = \"quantum\"\n").unwrap_err().to_string();
    assert!(adapter.contains("quantum"), "{adapter}");
    let syntax = with("[render\n").unwrap_err().to_string();
    assert!(syntax.contains("test.toml"), "{syntax}");
}

#[test]
fn seed_settings_are_range_checked() {
    let s = Settings::default().seeds;
    assert_eq!((s.seeds_per_pattern, s.capacity, s.class_table.as_str()), (2048, 262_144, ""));
    assert!((s.max_density_per_km2(256.0) - 31_250.0).abs() < 1e-6);
    let fast = Settings::preset("fast").unwrap().seeds;
    let accurate = Settings::preset("accurate").unwrap().seeds;
    assert!(fast.seeds_per_pattern < s.seeds_per_pattern && s.seeds_per_pattern < accurate.seeds_per_pattern);
    assert!(accurate.occlusion_tolerance_m < s.occlusion_tolerance_m);
    for (bad, key) in [
        ("seeds_per_pattern = 63", "seeds.seeds_per_pattern"),
        ("seeds_per_pattern = 65537", "seeds.seeds_per_pattern"),
        ("capacity = 0", "seeds.capacity"),
        ("capacity = 16777217", "seeds.capacity"),
        ("frustum_epsilon = 1.5", "seeds.frustum_epsilon"),
        ("frustum_epsilon = -0.1", "seeds.frustum_epsilon"),
        ("occlusion_tolerance_m = -1.0", "seeds.occlusion_tolerance_m"),
        ("occlusion_tolerance_per_km = -1.0", "seeds.occlusion_tolerance_per_km"),
        ("occlusion_refine_steps = 300", "seeds.occlusion_refine_steps"),
        ("reference_height_m = 0.0", "seeds.reference_height_m"),
        ("sink_fraction = 0.6", "seeds.sink_fraction"),
        ("ground_colour_radius_m = -2.0", "seeds.ground_colour_radius_m"),
        ("vegetation_bare = 0.5", "seeds.vegetation_bare"),
        ("vegetation_full = -0.2", "seeds.vegetation_bare"),
        ("vegetation_bare = -1.5", "seeds.vegetation_bare"),
        ("vegetation_full = 1.5", "seeds.vegetation_bare"),
        ("class_table = 3", "seeds.class_table"),
    ] {
        let err = with(&format!("[seeds]\n{bad}\n")).unwrap_err().to_string();
        assert!(err.contains(key), "{bad}: {err}");
    }
    let s = with("[seeds]\nclass_table = \"nlcd\"\nsink_fraction = 0\n").unwrap().seeds;
    assert_eq!((s.class_table.as_str(), s.sink_fraction), ("nlcd", 0.0));
}

#[test]
fn draw_reaches_are_checked_against_the_tlm_bands() {
    let d = Settings::default();
    assert_eq!(d.draw_seeds.reach_m, [800.0, 1000.0, 1400.0, 3000.0]);
    assert_eq!((d.tlm.occlusion_tolerance_per_km, d.draw_seeds.fade_fraction), (0.0, 0.1));
    for (bad, rule) in [
        ("[draw_seeds]\nreach_m = [120.0, 700.0, 600.0, 3000.0]\n", "increasing"),
        ("[draw_seeds]\nreach_m = [120.0, 700.0, 1400.0, 3500.0]\n", "tlm.radial_bands_m"),
        ("[draw_seeds]\nfade_fraction = 0.6\n", "0 to 0.5"),
        ("[tlm]\nocclusion_tolerance_per_km = -1.0\n", "0 or more"),
    ] {
        let err = with(bad).unwrap_err().to_string();
        assert!(err.contains(rule), "{bad}: {err}");
    }
    let fast = Settings::preset("fast").unwrap();
    assert_eq!((fast.tlm.radial_bands_m[2], fast.draw_seeds.reach_m[3]), (2000.0, 2000.0));
}

#[test]
fn keys_of_earlier_releases_name_their_replacements() {
    let old = with("[tlm]\nradial_lod_m = [700.0, 1400.0, 3000.0]\n").unwrap_err().to_string();
    assert!(old.contains("tlm.radial_bands_m") && old.contains("draw_seeds.reach_m"), "{old}");
    assert!(old.contains("test.toml") && old.contains("`tlm.radial_lod_m`"), "{old}");
    for (key, new) in [
        ("mesh_m = 60.0", "draw_seeds.reach_m"),
        ("fade_fraction = 0.1", "draw_seeds.fade_fraction"),
        ("impostors = \"x\"", "draw_seeds.impostors"),
    ] {
        let err = with(&format!("[seeds]\n{key}\n")).unwrap_err().to_string();
        assert!(err.contains(new), "{key}: {err}");
    }
}

#[test]
fn builtin_class_tables_fit_every_preset() {
    for (preset, _) in PRESETS {
        let s = Settings::preset(preset).unwrap();
        let max_per_km2 = s.seeds.max_density_per_km2(s.tlm.cell_m);
        for name in ["nc", "nlcd"] {
            let table = crate::classes::ClassTable::load(name).unwrap();
            for class in &table.classes {
                let density = f64::from(table.density_per_km2(class.code));
                assert!(density <= max_per_km2, "{preset}: {name} {} {density} > {max_per_km2}", class.code);
            }
        }
    }
}

#[test]
fn the_wind_is_still_by_default_and_its_ranges_are_checked() {
    let d = Settings::default().wind;
    assert_eq!(d.speed_m_s, 0.0, "the accuracy tests and the trade run in still air");
    assert_eq!(d.time_of_frame_s(90), 90.0 / d.frame_rate_hz);
    for (bad, key) in [
        ("speed_m_s = -1.0", "wind.speed_m_s"),
        ("speed_m_s = 41.0", "wind.speed_m_s"),
        ("frame_rate_hz = 0.0", "wind.frame_rate_hz"),
        ("from_deg = nan", "wind.from_deg"),
    ] {
        let err = with(&format!("[wind]\n{bad}\n")).unwrap_err().to_string();
        assert!(err.contains(key), "{bad}: {err}");
    }
    let w = with("[wind]\nspeed_m_s = 12\nfrom_deg = 90\n").unwrap().wind;
    assert!(w.speed_m_s == 12.0 && w.from_deg == 90.0);
}

/// `config/demo.toml` draws the demo's trees for any command over the default dataset: the class
/// table the demo picks for its scheme (nc, `tests/synth.rs` checks), and the folder it bakes them
/// into by default.
#[test]
fn the_demo_settings_name_the_demos_class_table_and_impostors() {
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("config/demo.toml");
    let s = Settings::load("balanced", Some(&file)).unwrap();
    assert_eq!(Some(s.seeds.class_table.as_str()), crate::classes::ClassTable::generated_for("nc"));
    assert_eq!(s.draw_seeds.impostors, "data/impostors");
}

#[test]
fn the_display_takes_ev100_in_range_and_names_its_curves() {
    let d = Settings::default().display;
    assert_eq!((d.ev100, d.tone_curve), (15.0, ToneCurve::Agx));
    let aces = with("[display]\ntone_curve = \"aces\"\nev100 = 9.5\n").unwrap().display;
    assert_eq!((aces.ev100, aces.tone_curve), (9.5, ToneCurve::Aces));
    for bad in ["ev100 = 30.0", "ev100 = -11.0", "ev100 = nan"] {
        let e = with(&format!("[display]\n{bad}\n")).unwrap_err().to_string();
        assert!(e.contains("display.ev100") && e.contains("-10 to 24"), "{bad}: {e}");
    }
    let unknown = with("[display]\ntone_curve = \"filmic\"\n").unwrap_err().to_string();
    assert!(unknown.contains("filmic") && unknown.contains("agx"), "{unknown}");
}
