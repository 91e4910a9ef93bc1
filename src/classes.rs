//! How it works: a land-cover class table names the codes of one classification scheme
//! (`config/classes/*.toml`) and what grows on each: a list of species (a model, a height range, a
//! crown width, the altitudes and slopes it tolerates) and, per class, seed rules (a species and its
//! density in seeds per km²). The built-in tables are compiled in, so `--classes nlcd` works from
//! anywhere; a path to a TOML file of the same shape works too. Codes outside the table are not an
//! error: they mean "no class" (no seeds), and the builder counts them. Parsing validates the table
//! (unique codes and species, rules naming known species, every number in range) and names the
//! table, class and key of the first problem, so a typo never reaches the GPU.

use std::path::Path;

use serde::{Deserialize, Serialize};
use thiserror::Error;

use crate::dataset::ClassName;
use crate::gpu::layout;

/// Most species in one table (`layout::MAX_SPECIES`, as a count).
pub const MAX_SPECIES: usize = layout::MAX_SPECIES as usize;
/// Most seed rules in one class (`layout::MAX_SPECIES_PER_CLASS`, as a count).
pub const MAX_SPECIES_PER_CLASS: usize = layout::MAX_SPECIES_PER_CLASS as usize;
/// Largest density a rule may ask for, seeds per km² (one seed per 10 m²).
pub const MAX_PER_KM2: f32 = 100_000.0;

const BUILTIN: &[(&str, &str)] = &[
    ("nc", include_str!("../config/classes/nc.toml")),
    ("nlcd", include_str!("../config/classes/nlcd.toml")),
];

/// Why a class table could not be loaded; each names the table and the class, species or key at
/// fault.
#[derive(Debug, Error)]
pub enum ClassTableError {
    /// The name is neither a built-in table nor a file that could be read (the name, the I/O
    /// error).
    #[error("class table `{0}` is neither a built-in table ({builtins}) nor a readable file: {1}", builtins = builtin_names())]
    NotFound(String, std::io::Error),
    /// The text is not valid TOML, or not of the table's shape (an unknown key, a missing one, an
    /// unknown species `kind`).
    #[error("class table {origin}: {message}")]
    Parse {
        /// The `origin` given to `ClassTable::parse`: a built-in name or the file's path.
        origin: String,
        /// The TOML parser's message.
        message: String,
    },
    /// Two classes have the same code.
    #[error("class table {origin}: code {code} is listed twice")]
    Duplicate {
        /// The table, as in `Parse`.
        origin: String,
        /// The land-cover code listed twice.
        code: u8,
    },
    /// Two species have the same name.
    #[error("class table {origin}: species `{name}` is listed twice")]
    DuplicateSpecies {
        /// The table, as in `Parse`.
        origin: String,
        /// The species name listed twice.
        name: String,
    },
    /// The table lists more than `MAX_SPECIES` species.
    #[error("class table {origin}: {count} species, at most {max} allowed", max = MAX_SPECIES)]
    TooManySpecies {
        /// The table, as in `Parse`.
        origin: String,
        /// How many species it lists.
        count: usize,
    },
    /// A class has more than `MAX_SPECIES_PER_CLASS` seed rules.
    #[error("class table {origin}: class {code} ({class}) has {count} seed rules, at most {max} allowed", max = MAX_SPECIES_PER_CLASS)]
    TooManyRules {
        /// The table, as in `Parse`.
        origin: String,
        /// The class's land-cover code.
        code: u8,
        /// The class's name.
        class: String,
        /// How many seed rules it lists.
        count: usize,
    },
    /// A seed rule names a species the table does not have, or one its class already lists.
    #[error("class table {origin}: class {code} ({class}), seeds.species = `{species}`: {problem}")]
    BadRule {
        /// The table, as in `Parse`.
        origin: String,
        /// The class's land-cover code.
        code: u8,
        /// The class's name.
        class: String,
        /// The species the rule names.
        species: String,
        /// What is wrong with it, in words.
        problem: &'static str,
    },
    /// A species' number (height, radius, altitude, slope) or a rule's density is out of range.
    #[error("class table {origin}: {place}, `{key}` = {value}: must be {rule}")]
    OutOfRange {
        /// The table, as in `Parse`.
        origin: String,
        /// Where the key is, e.g. "species `pine`" or "class 5 (forest), species `pine`".
        place: String,
        /// The key, e.g. `height_m` or `per_km2`.
        key: &'static str,
        /// The offending value, as text.
        value: String,
        /// The range it must lie in, in words.
        rule: &'static str,
    },
}

fn builtin_names() -> String {
    BUILTIN.iter().map(|(name, _)| *name).collect::<Vec<_>>().join(", ")
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
/// What a species is (`kind` in the table: "tree", "bush" or "rock"); pass 3 carries it to the
/// GPU with the species.
pub enum SpeciesKind {
    /// A tree (pass 3 hands the kind on as `SeedSpecies::kind`; sizes and slopes are the
    /// species' own).
    Tree,
    /// A bush or shrub: low vegetation.
    Bush,
    /// A rock or boulder: not vegetation.
    Rock,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
/// One thing that can grow (`[[species]]` in the table): its model, its size and where it grows.
pub struct Species {
    /// Unique within the table; the classes' seed rules refer to it by this name.
    pub name: String,
    /// Whether it is a tree, a bush or a rock; sent to the GPU with it (`SeedSpecies::kind`).
    pub kind: SpeciesKind,
    /// Model stem in ../shared/data/models (e.g. "Pine_1"), for the drawing pass.
    pub model: String,
    /// Range of the seed's height (its size), metres; each seed draws one from a hash.
    pub height_m: [f32; 2],
    /// Bounding-sphere radius per metre of height (crown width), for culling.
    pub radius_per_height: f32,
    /// Altitude range where it grows (the tree line), metres; default [-1e4, 1e4].
    #[serde(default = "any_altitude_m")]
    pub altitude_m: [f32; 2],
    /// Steepest ground it grows on, degrees (0..90).
    pub max_slope_deg: f32,
}

fn any_altitude_m() -> [f32; 2] {
    [-1.0e4, 1.0e4]
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
/// One species in a class and its density: how many of the pattern's seeds it takes, by rank.
pub struct SeedRule {
    /// The `Species::name` it grows.
    pub species: String,
    /// Seeds per km².
    pub per_km2: f32,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
/// One land-cover class (`[[class]]`): a code of the scheme and what grows there.
pub struct Class {
    /// The code the land-cover rasters use for this class.
    pub code: u8,
    /// Human-readable name, e.g. "forest"; recorded in the dataset's manifest.
    pub name: String,
    /// What grows on it, drawn in this order from each pattern's seed ranks (at most
    /// `MAX_SPECIES_PER_CLASS`); empty means no seeds.
    #[serde(default)]
    pub seeds: Vec<SeedRule>,
    /// Dense enough to be drawn as a forest far away (texcells): a forest sample is baked for it.
    #[serde(default)]
    pub texcells: bool,
}

/// A manifest's class list compares equal to a table's classes when codes and names match.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClassTable {
    /// The classification scheme, e.g. "nc" or "nlcd", as a dataset's land-cover layer names it.
    pub scheme: String,
    /// The code that means "no data" in the source rasters of this scheme.
    pub nodata_code: u8,
    /// The scheme's classes (`[[class]]`), codes unique; codes absent mean "no class", no seeds.
    #[serde(rename = "class")]
    pub classes: Vec<Class>,
    /// What can grow (`[[species]]`, at most `MAX_SPECIES`); pass 3 indexes them in this order.
    #[serde(default)]
    pub species: Vec<Species>,
}

impl ClassTable {
    /// A built-in table by name (`nc`, `nlcd`), else a TOML file at that path.
    pub fn load(name_or_path: &str) -> Result<Self, ClassTableError> {
        if let Some((_, text)) = BUILTIN.iter().find(|(name, _)| *name == name_or_path) {
            return Self::parse(text, name_or_path);
        }
        let text = std::fs::read_to_string(Path::new(name_or_path))
            .map_err(|e| ClassTableError::NotFound(name_or_path.to_owned(), e))?;
        Self::parse(&text, name_or_path)
    }

    /// Parses and validates a table's TOML text; `origin` (a name or path) labels the errors.
    pub fn parse(text: &str, origin: &str) -> Result<Self, ClassTableError> {
        let table: ClassTable = toml::from_str(text)
            .map_err(|e| ClassTableError::Parse { origin: origin.to_owned(), message: e.to_string() })?;
        table.validate(origin)?;
        Ok(table)
    }

    /// The table's codes and names, as a dataset's manifest records them.
    pub fn names(&self) -> Vec<ClassName> {
        self.classes.iter().map(|c| ClassName { code: c.code, name: c.name.clone() }).collect()
    }

    /// Whether `code` is one of the table's classes (otherwise it means "no class").
    pub fn contains(&self, code: u8) -> bool {
        self.classes.iter().any(|c| c.code == code)
    }

    /// The class with land-cover code `code`, if the table has one.
    pub fn class(&self, code: u8) -> Option<&Class> {
        self.classes.iter().find(|c| c.code == code)
    }

    /// Position of the species named `name` in `species`: its index in the GPU's species table.
    pub fn species_index(&self, name: &str) -> Option<usize> {
        self.species.iter().position(|s| s.name == name)
    }

    /// Total seeds per km² of the class (0 for unknown codes).
    pub fn density_per_km2(&self, code: u8) -> f32 {
        self.class(code).map_or(0.0, |c| c.seeds.iter().map(|r| r.per_km2).sum())
    }

    fn validate(&self, origin: &str) -> Result<(), ClassTableError> {
        let origin = origin.to_owned();
        let mut codes: Vec<u8> = self.classes.iter().map(|c| c.code).collect();
        codes.sort_unstable();
        if let Some(pair) = codes.windows(2).find(|pair| pair[0] == pair[1]) {
            return Err(ClassTableError::Duplicate { origin, code: pair[0] });
        }
        if self.species.len() > MAX_SPECIES {
            return Err(ClassTableError::TooManySpecies { origin, count: self.species.len() });
        }
        for (i, species) in self.species.iter().enumerate() {
            if self.species[..i].iter().any(|s| s.name == species.name) {
                return Err(ClassTableError::DuplicateSpecies { origin, name: species.name.clone() });
            }
            check_species(species).map_err(|(key, value, rule)| ClassTableError::OutOfRange {
                origin: origin.clone(),
                place: format!("species `{}`", species.name),
                key,
                value,
                rule,
            })?;
        }
        for class in &self.classes {
            if class.seeds.len() > MAX_SPECIES_PER_CLASS {
                return Err(ClassTableError::TooManyRules {
                    origin,
                    code: class.code,
                    class: class.name.clone(),
                    count: class.seeds.len(),
                });
            }
            for (i, rule) in class.seeds.iter().enumerate() {
                let bad_rule = |problem| ClassTableError::BadRule {
                    origin: origin.clone(),
                    code: class.code,
                    class: class.name.clone(),
                    species: rule.species.clone(),
                    problem,
                };
                if self.species_index(&rule.species).is_none() {
                    return Err(bad_rule("no species of that name in the table"));
                }
                if class.seeds[..i].iter().any(|r| r.species == rule.species) {
                    return Err(bad_rule("the class lists this species twice"));
                }
                if !(0.0..=MAX_PER_KM2).contains(&rule.per_km2) {
                    return Err(ClassTableError::OutOfRange {
                        origin: origin.clone(),
                        place: format!("class {} ({}), species `{}`", class.code, class.name, rule.species),
                        key: "per_km2",
                        value: rule.per_km2.to_string(),
                        rule: "0 to 100000 seeds per km²",
                    });
                }
            }
        }
        Ok(())
    }
}

/// The first key of a species out of range: (key, value, rule).
fn check_species(s: &Species) -> Result<(), (&'static str, String, &'static str)> {
    let [h0, h1] = s.height_m;
    let [a0, a1] = s.altitude_m;
    let checks: [(bool, &'static str, String, &'static str); 4] = [
        (
            h0 > 0.0 && h0 <= h1 && h1.is_finite(),
            "height_m",
            format!("{:?}", s.height_m),
            "[min, max] metres with 0 < min <= max",
        ),
        (
            s.radius_per_height > 0.0 && s.radius_per_height.is_finite(),
            "radius_per_height",
            s.radius_per_height.to_string(),
            "a positive number",
        ),
        (
            a0 <= a1 && a0.is_finite() && a1.is_finite(),
            "altitude_m",
            format!("{:?}", s.altitude_m),
            "[min, max] metres with min <= max",
        ),
        (
            (0.0..=90.0).contains(&s.max_slope_deg),
            "max_slope_deg",
            s.max_slope_deg.to_string(),
            "0 to 90 degrees",
        ),
    ];
    match checks.into_iter().find(|(ok, ..)| !ok) {
        Some((_, key, value, rule)) => Err((key, value, rule)),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
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
        for name in ["nc", "nlcd"] {
            let t = ClassTable::load(name).unwrap();
            assert!(!t.species.is_empty() && t.species.len() <= MAX_SPECIES, "{name}");
            for class in &t.classes {
                for rule in &class.seeds {
                    assert!(
                        t.species_index(&rule.species).is_some(),
                        "{name} {}: {}",
                        class.code,
                        rule.species
                    );
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
        assert!(
            err.contains("class 5 (forest)") && err.contains("`oak`") && err.contains("no species"),
            "{err}"
        );
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
        ] {
            let err = error(&table("", "").replace(from, to));
            assert!(err.contains("species `pine`") && err.contains(key) && err.contains("t.toml"), "{err}");
        }
        let err = error(&table("", "").replace("kind = \"tree\"", "kind = \"fern\""));
        assert!(err.contains("fern"), "{err}");
    }
}
