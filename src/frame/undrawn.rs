//! How it works: pass 3 selects the seeds of every species of the class table, and pass 4 draws a
//! species only with its model's impostor from `draw_seeds.impostors`; without the folder, or
//! without a model in it, those seeds are selected, counted and never drawn, and a frame shows no
//! sign of them. `UndrawnSeeds` is that gap, found when a renderer is made (the same test
//! `load_impostors` makes: the model's manifest in the folder) or from a dataset and settings
//! alone, for a command to say before it spends its time; `Display` is the sentence it says.

use std::fmt;

use crate::classes::ClassTable;
use crate::config::Settings;
use crate::dataset::Dataset;
use crate::passes::draw_seeds::frame::has_impostor;

use super::RenderError;

/// Seeds that are selected but cannot be drawn: the class table's models that have no impostor.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UndrawnSeeds {
    /// The class table the species come from (`seeds.class_table`, else the land cover's scheme).
    pub class_table: String,
    /// The impostor folder, `draw_seeds.impostors` (empty: none).
    pub impostors: String,
    /// The table's models, each once.
    pub models: usize,
    /// Those with no impostor in the folder (every one without a folder), in the table's order.
    pub missing: Vec<String>,
}

impl UndrawnSeeds {
    /// What `settings` leave undrawn of the seeds grown from `table` (named `class_table`): `None`
    /// when every model has its impostor, or when no seed is selected (`seeds.density_scale` 0).
    pub fn find(class_table: &str, table: &ClassTable, settings: &Settings) -> Option<Self> {
        let dir = settings.draw_seeds.impostors.as_str();
        let mut models: Vec<&str> = Vec::new();
        for species in &table.species {
            if !models.contains(&species.model.as_str()) {
                models.push(&species.model);
            }
        }
        let missing: Vec<String> = models
            .iter()
            .filter(|m| dir.is_empty() || !has_impostor(std::path::Path::new(dir), m))
            .map(|m| m.to_string())
            .collect();
        (settings.seeds.density_scale > 0.0 && !missing.is_empty()).then(|| Self {
            class_table: class_table.to_owned(),
            impostors: dir.to_owned(),
            models: models.len(),
            missing,
        })
    }

    /// As `find`, for the seeds `dataset`'s land cover grows (`None` without land cover).
    pub fn of(dataset: &Dataset, settings: &Settings) -> Result<Option<Self>, RenderError> {
        let Some(landcover) = &dataset.manifest.landcover else { return Ok(None) };
        let name = super::seeds::class_table_name(settings, landcover);
        Ok(Self::find(name, &ClassTable::load(name)?, settings))
    }

    /// Whether no seed at all can be drawn.
    pub fn none_drawn(&self) -> bool {
        self.missing.len() == self.models
    }
}

impl fmt::Display for UndrawnSeeds {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let table = &self.class_table;
        let list = self.missing.join(", ");
        if self.impostors.is_empty() {
            write!(
                f,
                "seeds of the class table {table} are selected but none is drawn: draw_seeds.impostors names \
                 no impostor folder (bake the models {list} with terramp-data bake; config/demo.toml names \
                 the folder `terramp demo` bakes for the default dataset)"
            )
        } else if self.none_drawn() {
            write!(
                f,
                "seeds of the class table {table} are selected but none is drawn: {} holds no impostor of \
                 its models ({list})",
                self.impostors
            )
        } else {
            write!(
                f,
                "{} of the class table {table}'s {} models have no impostor in {} ({list}): their species' \
                 seeds are selected but not drawn",
                self.missing.len(),
                self.models,
                self.impostors
            )
        }
    }
}
