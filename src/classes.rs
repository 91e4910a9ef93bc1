//! How it works: a land-cover class table names the codes of one classification scheme
//! (`config/classes/*.toml`). The built-in tables are compiled in, so `--classes nlcd` works from
//! anywhere; a path to a TOML file of the same shape works too. Codes outside the table are not an
//! error: they mean "no class" (no seeds), and the builder counts them.

use std::path::Path;

use serde::Deserialize;
use thiserror::Error;

use crate::dataset::ClassName;

const BUILTIN: &[(&str, &str)] = &[
    ("nc", include_str!("../config/classes/nc.toml")),
    ("nlcd", include_str!("../config/classes/nlcd.toml")),
];

#[derive(Debug, Error)]
pub enum ClassTableError {
    #[error("class table `{0}` is neither a built-in table ({builtins}) nor a readable file: {1}", builtins = builtin_names())]
    NotFound(String, std::io::Error),
    #[error("class table {origin}: {message}")]
    Parse { origin: String, message: String },
    #[error("class table {origin}: code {code} is listed twice")]
    Duplicate { origin: String, code: u8 },
}

fn builtin_names() -> String {
    BUILTIN.iter().map(|(name, _)| *name).collect::<Vec<_>>().join(", ")
}

#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClassTable {
    pub scheme: String,
    /// The code that means "no data" in the source rasters of this scheme.
    pub nodata_code: u8,
    #[serde(rename = "class")]
    pub classes: Vec<ClassName>,
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

    pub fn parse(text: &str, origin: &str) -> Result<Self, ClassTableError> {
        let table: ClassTable = toml::from_str(text)
            .map_err(|e| ClassTableError::Parse { origin: origin.to_owned(), message: e.to_string() })?;
        let mut codes: Vec<u8> = table.classes.iter().map(|c| c.code).collect();
        codes.sort_unstable();
        if let Some(pair) = codes.windows(2).find(|pair| pair[0] == pair[1]) {
            return Err(ClassTableError::Duplicate { origin: origin.to_owned(), code: pair[0] });
        }
        Ok(table)
    }

    /// The table's codes and names, as a dataset's manifest records them.
    pub fn names(&self) -> Vec<ClassName> {
        self.classes.clone()
    }

    pub fn contains(&self, code: u8) -> bool {
        self.classes.iter().any(|c| c.code == code)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_parse() {
        let nc = ClassTable::load("nc").unwrap();
        assert_eq!(nc.classes.len(), 7);
        assert!(nc.contains(6) && !nc.contains(8));
        let nlcd = ClassTable::load("nlcd").unwrap();
        assert!(nlcd.contains(41) && nlcd.contains(95) && !nlcd.contains(255));
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
}
