//! How it works: a generated tree is named like a model file's stem, so that class tables, the
//! impostor folders and the baker treat it as any model: `tree-<species>-s<seed>-h<health %>`
//! (`tree-spruce-s7-h80` is a spruce grown from seed 7 at health 0.8). A name either parses whole
//! into a known species, a seed and a health of 0 to 100 %, or is not a generated tree's.

use std::fmt;

use super::{NAMES, Tree, TreeError, generate};

/// A generated tree's model name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ModelName {
    /// One of [`NAMES`].
    pub species: &'static str,
    /// The seed it is grown from.
    pub seed: u64,
    /// Its health in percent, 0 to 100.
    pub health_percent: u8,
}

impl ModelName {
    /// The generated tree `stem` names, or `None` when it names none.
    pub fn parse(stem: &str) -> Option<Self> {
        let rest = stem.strip_prefix("tree-")?;
        let (species, rest) = rest.split_once("-s")?;
        let (seed, health) = rest.split_once("-h")?;
        let species = NAMES.iter().copied().find(|n| *n == species)?;
        let digits = |s: &str| !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit());
        if !digits(seed) || !digits(health) {
            return None;
        }
        let health_percent = health.parse::<u8>().ok().filter(|h| *h <= 100)?;
        Some(Self { species, seed: seed.parse().ok()?, health_percent })
    }

    /// Grows the tree.
    pub fn generate(&self) -> Result<Tree, TreeError> {
        generate(self.species, self.seed, f32::from(self.health_percent) / 100.0)
    }
}

impl fmt::Display for ModelName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "tree-{}-s{}-h{}", self.species, self.seed, self.health_percent)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_anything_else_is_no_tree() {
        let name = ModelName { species: "spruce", seed: 7, health_percent: 80 };
        assert_eq!(name.to_string(), "tree-spruce-s7-h80");
        assert_eq!(ModelName::parse("tree-spruce-s7-h80"), Some(name));
        for other in [
            "Pine_1",
            "tree-baobab-s1-h100",
            "tree-spruce-s7-h101",
            "tree-spruce-s-h80",
            "tree-spruce-s7-h",
            "tree-spruce-s+7-h80",
            "tree-spruce-s7-h80-extra",
            "tree-spruce-7-80",
        ] {
            assert_eq!(ModelName::parse(other), None, "{other}");
        }
    }
}
