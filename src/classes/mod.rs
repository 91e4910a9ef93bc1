//! How it works: a land-cover class table names the codes of one classification scheme
//! (`config/classes/*.toml`) and what grows on each: a list of species (a model, or several
//! variants of it, a height range, a crown width, the altitudes and slopes it tolerates) and, per
//! class, seed rules (a species and its density in seeds per km²). A species with `models = [..]`
//! becomes one entry of `species` per model, consecutive and alike but for the model, so that every
//! consumer indexes one model per entry as pass 3's records do; the rules name the first, and pass
//! 3 moves each seed to one of its species' variants by its hash (`seeds::seed_variant`). The
//! built-in tables are compiled in, so `--classes nlcd` works from anywhere; a path to a TOML file of the same shape works too. Codes outside the table are not an
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
    ("nc", include_str!("../../config/classes/nc.toml")),
    ("nlcd", include_str!("../../config/classes/nlcd.toml")),
    ("nc-generated", include_str!("../../config/classes/nc_generated.toml")),
];

/// Suffix of the built-in table that grows a scheme's classes with generated trees.
const GENERATED_SUFFIX: &str = "-generated";

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
    /// The table lists more than `MAX_SPECIES` species, each variant counted.
    #[error("class table {origin}: {count} species, each of a species' models counted, at most {max} allowed", max = MAX_SPECIES)]
    TooManySpecies {
        /// The table, as in `Parse`.
        origin: String,
        /// How many species it lists, each variant counted.
        count: usize,
    },
    /// A species names no model, or names it both ways (`model` and `models`).
    #[error(
        "class table {origin}: species `{name}`: give its model as `model = \"..\"` or its variants as `models = [..]`, one of the two"
    )]
    Models {
        /// The table, as in `Parse`.
        origin: String,
        /// The species.
        name: String,
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

#[derive(Debug, Clone, PartialEq)]
/// One thing that can grow, with one model: a `[[species]]` of the table, or one of its variants
/// (`models = [..]`), which follow it in `ClassTable::species` with the same name and numbers.
pub struct Species {
    /// Unique within the table but for the variants, which share it; the classes' seed rules
    /// refer to the species by it.
    pub name: String,
    /// Whether it is a tree, a bush or a rock; sent to the GPU with it (`SeedSpecies::kind`).
    pub kind: SpeciesKind,
    /// Model stem (e.g. "Pine_1" in ../shared/data/models, or a generated `tree-...`), for the
    /// drawing pass.
    pub model: String,
    /// Which of its species' models this is, 0 the first (the one the rules' index names).
    pub variant: u32,
    /// How many models its species has (1: no variants).
    pub variants: u32,
    /// Range of the seed's height (its size), metres; each seed draws one from a hash.
    pub height_m: [f32; 2],
    /// Bounding-sphere radius per metre of height (crown width), for culling; of the widest of
    /// the variants.
    pub radius_per_height: f32,
    /// Altitude range where it grows (the tree line), metres; default [-1e4, 1e4].
    pub altitude_m: [f32; 2],
    /// Steepest ground it grows on, degrees (0..90).
    pub max_slope_deg: f32,
    /// How much its foliage follows the photograph's colour under a seed (pass 3's sample), 0 to
    /// 1 (Amara et al.'s colour follow-up, a ratio transfer: at 1 its foliage seen from above has
    /// the photograph's local mean and keeps its own detail; at 0 its model's colours); its bark
    /// keeps its own. Default `DEFAULT_GROUND_BLEND`.
    pub ground_blend: f32,
    /// How much darker a plant is low in its crown and on its side away from the sun, 0 (flat) to
    /// 1 (black at the bottom of the shaded side): the luminosity by position inside the object.
    pub crown_shading: f32,
}

/// `Species::ground_blend` where a table does not say.
pub const DEFAULT_GROUND_BLEND: f32 = 1.0;

fn default_ground_blend() -> f32 {
    DEFAULT_GROUND_BLEND
}

/// A `[[species]]` as the table writes it: `Species` with its model or its variants' models.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct SpeciesText {
    name: String,
    kind: SpeciesKind,
    #[serde(default)]
    model: Option<String>,
    #[serde(default)]
    models: Vec<String>,
    height_m: [f32; 2],
    radius_per_height: f32,
    #[serde(default = "any_altitude_m")]
    altitude_m: [f32; 2],
    max_slope_deg: f32,
    #[serde(default = "default_ground_blend")]
    ground_blend: f32,
    #[serde(default)]
    crown_shading: f32,
}

impl SpeciesText {
    /// One `Species` per model, or `None` where it names no model or names it both ways.
    fn variants(self) -> Option<Vec<Species>> {
        let models = match (self.model, self.models) {
            (Some(model), models) if models.is_empty() => vec![model],
            (None, models) if !models.is_empty() => models,
            _ => return None,
        };
        let variants = models.len() as u32;
        let species = models.into_iter().enumerate().map(|(variant, model)| Species {
            name: self.name.clone(),
            kind: self.kind,
            model,
            variant: variant as u32,
            variants,
            height_m: self.height_m,
            radius_per_height: self.radius_per_height,
            altitude_m: self.altitude_m,
            max_slope_deg: self.max_slope_deg,
            ground_blend: self.ground_blend,
            crown_shading: self.crown_shading,
        });
        Some(species.collect())
    }
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
    /// How many of the draw LODs (`draw_seeds.reach_m`: the mesh, then the billboard-cloud bands)
    /// its seeds are drawn in, nearest first, 1 to `SEED_LODS` (the default: all of them); past
    /// the last they fade out as every seed does past the last band. A texcell class uses all of
    /// them: its texcells take over where the last band ends.
    #[serde(default = "all_seed_lods")]
    pub seed_lods: u32,
}

fn all_seed_lods() -> u32 {
    layout::SEED_LODS
}

/// A manifest's class list compares equal to a table's classes when codes and names match.
#[derive(Debug, Clone, PartialEq)]
pub struct ClassTable {
    /// The classification scheme, e.g. "nc" or "nlcd", as a dataset's land-cover layer names it.
    pub scheme: String,
    /// The code that means "no data" in the source rasters of this scheme.
    pub nodata_code: u8,
    /// The scheme's classes (`[[class]]`), codes unique; codes absent mean "no class", no seeds.
    pub classes: Vec<Class>,
    /// What can grow (`[[species]]`, each variant its own entry after the first, at most
    /// `MAX_SPECIES` in all); pass 3 indexes them in this order.
    pub species: Vec<Species>,
}

/// A `ClassTable` as its TOML writes it.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ClassTableText {
    scheme: String,
    nodata_code: u8,
    #[serde(rename = "class")]
    classes: Vec<Class>,
    #[serde(default)]
    species: Vec<SpeciesText>,
}

impl ClassTable {
    /// The built-in table growing `scheme`'s classes with generated trees (`tree::ModelName`
    /// models, no model files needed), if there is one: `nc-generated` for `nc`.
    pub fn generated_for(scheme: &str) -> Option<&'static str> {
        BUILTIN.iter().map(|(name, _)| *name).find(|name| name.strip_suffix(GENERATED_SUFFIX) == Some(scheme))
    }

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
        let text: ClassTableText = toml::from_str(text)
            .map_err(|e| ClassTableError::Parse { origin: origin.to_owned(), message: e.to_string() })?;
        let mut species = Vec::with_capacity(text.species.len());
        for s in text.species {
            let name = s.name.clone();
            species.extend(s.variants().ok_or(ClassTableError::Models { origin: origin.to_owned(), name })?);
        }
        let table =
            ClassTable { scheme: text.scheme, nodata_code: text.nodata_code, classes: text.classes, species };
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

    /// Position of the species named `name` in `species` (its first variant): its index in the
    /// GPU's species table.
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
            if species.variant == 0 && self.species[..i].iter().any(|s| s.name == species.name) {
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
            let lods_rule = if class.texcells {
                (
                    class.seed_lods == layout::SEED_LODS,
                    "every draw LOD (the default) in a class with texcells: they take over where the last band ends",
                )
            } else {
                (
                    (1..=layout::SEED_LODS).contains(&class.seed_lods),
                    "from 1 (the mesh only) to the number of draw_seeds.reach_m bands",
                )
            };
            if !lods_rule.0 {
                return Err(ClassTableError::OutOfRange {
                    origin,
                    place: format!("class {} ({})", class.code, class.name),
                    key: "seed_lods",
                    value: class.seed_lods.to_string(),
                    rule: lods_rule.1,
                });
            }
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
    let checks: [(bool, &'static str, String, &'static str); 6] = [
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
        ((0.0..=1.0).contains(&s.ground_blend), "ground_blend", s.ground_blend.to_string(), "0 to 1"),
        ((0.0..=1.0).contains(&s.crown_shading), "crown_shading", s.crown_shading.to_string(), "0 to 1"),
    ];
    match checks.into_iter().find(|(ok, ..)| !ok) {
        Some((_, key, value, rule)) => Err((key, value, rule)),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests;
