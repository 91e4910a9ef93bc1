use super::*;

const SPECIES: &str = "[[species]]\nname = \"pine\"\nkind = \"tree\"\nmodel = \"Pine_1\"\n\
    height_m = [6.0, 12.0]\nradius_per_height = 0.65\nmax_slope_deg = 40.0\n";

/// A one-class table with the pine species, `species_extra` appended to the species and
/// `rules` as the class's seed rules.
fn table(species_extra: &str, rules: &str) -> String {
    format!(
        "scheme = \"x\"\nnodata_code = 0\n{SPECIES}{species_extra}\n\
         [[class]]\ncode = 5\nname = \"forest\"\nseeds = [{rules}]\n"
    )
}

fn error(text: &str) -> String {
    ClassTable::parse(text, "t.toml").unwrap_err().to_string()
}

#[test]
fn builtins_parse() {
    let nc = ClassTable::load("nc").unwrap();
    assert_eq!(nc.classes.len(), 7);
    assert!(nc.contains(6) && !nc.contains(8));
    let nlcd = ClassTable::load("nlcd").unwrap();
    assert!(nlcd.contains(41) && nlcd.contains(95) && !nlcd.contains(255));
    assert_eq!(nc.names()[4], ClassName { code: 5, name: "forest".into() });
    assert_eq!(nc.names().len(), nc.classes.len());
}

#[test]
fn builtin_rules_name_known_species_and_respect_the_ecology() {
    for name in ["nc", "nlcd", "nc-generated"] {
        let t = ClassTable::load(name).unwrap();
        assert!(!t.species.is_empty() && t.species.len() <= MAX_SPECIES, "{name}");
        for class in &t.classes {
            for rule in &class.seeds {
                assert!(t.species_index(&rule.species).is_some(), "{name} {}: {}", class.code, rule.species);
            }
        }
        for s in &t.species {
            let max_slope = match s.kind {
                SpeciesKind::Tree => 40.0,
                SpeciesKind::Bush => 50.0,
                SpeciesKind::Rock => 70.0,
            };
            assert!(s.max_slope_deg <= max_slope, "{name}: {}", s.name);
        }
    }
    let nc = ClassTable::load("nc").unwrap();
    let kinds = |t: &ClassTable, code| -> Vec<SpeciesKind> {
        let rules = &t.class(code).unwrap().seeds;
        rules.iter().map(|r| t.species[t.species_index(&r.species).unwrap()].kind).collect()
    };
    assert!(nc.density_per_km2(5) >= 10_000.0, "{}", nc.density_per_km2(5));
    assert_eq!(nc.density_per_km2(6), 0.0);
    assert_eq!(nc.density_per_km2(200), 0.0);
    assert!(!kinds(&nc, 1).contains(&SpeciesKind::Tree));
    let nlcd = ClassTable::load("nlcd").unwrap();
    for code in [11, 12, 22, 23, 24, 81, 82, 95] {
        assert!(kinds(&nlcd, code).iter().all(|&k| k == SpeciesKind::Bush), "nlcd {code}");
    }
    for code in [41, 42, 43] {
        assert!(nlcd.density_per_km2(code) >= 10_000.0, "nlcd {code}");
    }
    let conifer_line = nlcd.species.iter().filter(|s| s.model.starts_with("Pine"));
    assert!(conifer_line.clone().count() > 0);
    assert!(conifer_line.into_iter().all(|s| (3000.0..=3800.0).contains(&s.altitude_m[1])));
}

#[test]
fn a_valid_table_reads_back() {
    let t = ClassTable::parse(&table("", "{ species = \"pine\", per_km2 = 900.0 }"), "t.toml").unwrap();
    assert_eq!(t.species_index("pine"), Some(0));
    assert_eq!(t.species_index("oak"), None);
    assert_eq!(t.species[0].altitude_m, [-1.0e4, 1.0e4]);
    assert_eq!(t.species[0].kind, SpeciesKind::Tree);
    assert_eq!(t.density_per_km2(5), 900.0);
    assert_eq!(t.class(5).unwrap().seeds[0].species, "pine");
}

#[test]
fn errors_name_the_problem() {
    let err = ClassTable::load("/no/such/table.toml").unwrap_err().to_string();
    assert!(err.contains("nc, nlcd"), "{err}");
    let dup = "scheme = \"x\"\nnodata_code = 0\n[[class]]\ncode = 3\nname = \"a\"\n[[class]]\ncode = 3\nname = \"b\"\n";
    assert!(matches!(ClassTable::parse(dup, "dup"), Err(ClassTableError::Duplicate { code: 3, .. })));
    let typo = "scheme = \"x\"\nnodata_code = 0\nclases = []\n";
    let err = ClassTable::parse(typo, "typo").unwrap_err().to_string();
    assert!(err.contains("clases"), "{err}");
}

#[test]
fn species_and_rule_errors_name_table_class_and_key() {
    let err = error(&table(SPECIES, ""));
    assert!(err.contains("t.toml") && err.contains("`pine` is listed twice"), "{err}");
    let err = error(&table("", "{ species = \"oak\", per_km2 = 1.0 }"));
    assert!(err.contains("class 5 (forest)") && err.contains("`oak`") && err.contains("no species"), "{err}");
    let twice = "{ species = \"pine\", per_km2 = 1.0 }, { species = \"pine\", per_km2 = 2.0 }";
    assert!(error(&table("", twice)).contains("twice"));
    let err = error(&table("", "{ species = \"pine\", per_km2 = 100001.0 }"));
    assert!(err.contains("class 5 (forest)") && err.contains("per_km2"), "{err}");
    assert!(error(&table("", "{ species = \"pine\", per_km2 = -1.0 }")).contains("per_km2"));

    let many: String =
        (0..5).map(|i| SPECIES.replace("\"pine\"", &format!("\"p{i}\""))).collect::<Vec<_>>().join("");
    let rules: Vec<String> = (0..5).map(|i| format!("{{ species = \"p{i}\", per_km2 = 1.0 }}")).collect();
    let err = error(&table(&many, &rules.join(", ")));
    assert!(err.contains("class 5 (forest)") && err.contains("5 seed rules"), "{err}");
    let seventeen: String = (0..MAX_SPECIES)
        .map(|i| SPECIES.replace("\"pine\"", &format!("\"q{i}\"")))
        .collect::<Vec<_>>()
        .join("");
    assert!(error(&table(&seventeen, "")).contains("17 species"));

    for (from, to, key) in [
        ("height_m = [6.0, 12.0]", "height_m = [0.0, 12.0]", "height_m"),
        ("height_m = [6.0, 12.0]", "height_m = [13.0, 12.0]", "height_m"),
        ("radius_per_height = 0.65", "radius_per_height = 0.0", "radius_per_height"),
        ("max_slope_deg = 40.0", "max_slope_deg = 91.0", "max_slope_deg"),
        ("max_slope_deg = 40.0", "max_slope_deg = -1.0", "max_slope_deg"),
        ("max_slope_deg = 40.0", "max_slope_deg = 40.0\naltitude_m = [3000.0, 100.0]", "altitude_m"),
        ("max_slope_deg = 40.0", "max_slope_deg = 40.0\nground_blend = 1.5", "ground_blend"),
        ("max_slope_deg = 40.0", "max_slope_deg = 40.0\ncrown_shading = -0.1", "crown_shading"),
    ] {
        let err = error(&table("", "").replace(from, to));
        assert!(err.contains("species `pine`") && err.contains(key) && err.contains("t.toml"), "{err}");
    }
    let err = error(&table("", "").replace("kind = \"tree\"", "kind = \"fern\""));
    assert!(err.contains("fern"), "{err}");
}

#[test]
fn a_species_with_models_becomes_its_variants_in_order() {
    let oak = SPECIES
        .replace("\"pine\"", "\"oak\"")
        .replace("model = \"Pine_1\"", "models = [\"A\", \"B\", \"C\"]");
    let rules = "{ species = \"oak\", per_km2 = 5.0 }, { species = \"pine\", per_km2 = 1.0 }";
    let t = ClassTable::parse(&table(&oak, rules), "t.toml").unwrap();
    let drawn: Vec<_> =
        t.species.iter().map(|s| (s.name.as_str(), s.model.as_str(), s.variant, s.variants)).collect();
    assert_eq!(drawn, [("pine", "Pine_1", 0, 1), ("oak", "A", 0, 3), ("oak", "B", 1, 3), ("oak", "C", 2, 3)]);
    assert!(
        t.species[1..].iter().all(|s| s.height_m == t.species[1].height_m && s.kind == SpeciesKind::Tree)
    );
    assert_eq!(t.species_index("oak"), Some(1));
    // Every variant counts against the GPU's species table.
    let many = format!("models = [{}]", vec!["\"A\""; MAX_SPECIES].join(", "));
    let err = error(&table(&oak.replace("models = [\"A\", \"B\", \"C\"]", &many), ""));
    assert!(err.contains("17 species") && err.contains("each of a species' models counted"), "{err}");
    // A model given both ways, or none.
    for models in ["model = \"A\"\nmodels = [\"B\"]", "models = []", ""] {
        let err = error(&table(&oak.replace("models = [\"A\", \"B\", \"C\"]", models), ""));
        assert!(err.contains("species `oak`") && err.contains("one of the two"), "{models}: {err}");
    }
}

#[test]
fn a_class_says_how_many_draw_lods_its_seeds_use() {
    let rules = "{ species = \"pine\", per_km2 = 900.0 }";
    let all = ClassTable::parse(&table("", rules), "t.toml").unwrap();
    assert_eq!(all.class(5).unwrap().seed_lods, layout::SEED_LODS, "the default: every band");
    let near = ClassTable::parse(&format!("{}seed_lods = 2\n", table("", rules)), "t.toml").unwrap();
    assert_eq!(near.class(5).unwrap().seed_lods, 2);

    for lods in [0, layout::SEED_LODS + 1] {
        let err = error(&format!("{}seed_lods = {lods}\n", table("", rules)));
        assert!(
            err.contains("class 5 (forest)") && err.contains("seed_lods") && err.contains("t.toml"),
            "{err}"
        );
    }
    // Texcells take over where the last band ends: a texcell class stopping its seeds sooner
    // would leave a bare ring between the two.
    let err = error(&format!("{}texcells = true\nseed_lods = 3\n", table("", rules)));
    assert!(err.contains("seed_lods") && err.contains("texcells"), "{err}");
    let dense = ClassTable::parse(&format!("{}texcells = true\n", table("", rules)), "t.toml").unwrap();
    assert!(dense.class(5).unwrap().texcells);
}

#[test]
fn a_species_says_how_much_ground_colour_and_crown_shading_it_takes() {
    let t = ClassTable::parse(&table("", ""), "t.toml").unwrap();
    assert_eq!((t.species[0].ground_blend, t.species[0].crown_shading), (DEFAULT_GROUND_BLEND, 0.0));
    let shaded = table("", "")
        .replace("max_slope_deg = 40.0", "max_slope_deg = 40.0\nground_blend = 0.5\ncrown_shading = 0.4");
    let t = ClassTable::parse(&shaded, "t.toml").unwrap();
    assert_eq!((t.species[0].ground_blend, t.species[0].crown_shading), (0.5, 0.4));
}
