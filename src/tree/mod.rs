//! How it works: the Virtual Forest's tree generator (Wesslén & Seipel, after Weber & Penn 1995).
//! A species (`species.rs`: spruce, pine, birch, broadleaf, bush) is a trunk and up to three
//! levels of branches with their lengths, curvature, angles and counts, and leaves on the last
//! level; `grow.rs` runs Weber & Penn's recursion from a seed, each part drawing its randomness
//! from its own hashed key, and the paper's **health** decides which parts are kept (moderate
//! losses omit leaves at random, larger ones remove branches too), so that a sicker tree is a
//! subset of a healthier one. `mesh.rs` turns the result into bark tubes sorted by level and leaf
//! quads sorted by rank (selectable by index range), `textures.rs` paints the bark and leaf
//! textures, and `glb.rs` writes glTF 2.0 binary: metres, +Y up, base at y = 0, so a generated
//! tree goes through the same baker as any model. The same (species, seed, health) gives the
//! same bytes.

mod glb;
mod grow;
mod mesh;
mod name;
mod species;
mod textures;

use thiserror::Error;

use crate::impostor::Detail;

pub use glb::{Alpha, Material};
pub use grow::{branch_keep, leaf_keep};
pub use mesh::{Part, TreeMesh};
pub use name::ModelName;
pub use species::{LeafKind, Leaves, Level, NAMES, Shape, Species, species};
pub use textures::LEAF_TEXELS;

/// Why a tree could not be generated.
#[derive(Debug, Error)]
pub enum TreeError {
    /// The species name is not one the generator knows.
    #[error("unknown tree species `{0}`: the generator knows {known}", known = NAMES.join(", "))]
    UnknownSpecies(String),
    /// Health must lie in [0, 1].
    #[error("tree health {0} is outside [0, 1] (1 healthy, 0 dead)")]
    Health(f32),
    /// A procedural texture could not be encoded as PNG.
    #[error("encoding a tree texture: {0}")]
    Texture(#[source] image::ImageError),
}

/// A generated tree: its meshes and its two textures.
#[derive(Debug, Clone)]
pub struct Tree {
    /// Species, seed and health it was grown from.
    pub species: &'static str,
    /// The seed.
    pub seed: u64,
    /// The health, in [0, 1].
    pub health: f32,
    /// Bark tubes and leaf quads.
    pub mesh: TreeMesh,
    /// The bark texture, PNG.
    pub bark_png: Vec<u8>,
    /// The leaf texture, PNG.
    pub leaf_png: Vec<u8>,
}

/// Alpha cutoff of the leaf cards.
pub const LEAF_ALPHA_CUTOFF: f32 = 0.5;

/// Grows the built-in species `name` from `seed` at `health` (1 healthy .. 0 dead).
pub fn generate(name: &str, seed: u64, health: f32) -> Result<Tree, TreeError> {
    let species = species(name).ok_or_else(|| TreeError::UnknownSpecies(name.to_string()))?;
    generate_species(&species, seed, health)
}

/// Grows `species` from `seed` at `health`.
pub fn generate_species(species: &Species, seed: u64, health: f32) -> Result<Tree, TreeError> {
    if !(0.0..=1.0).contains(&health) {
        return Err(TreeError::Health(health));
    }
    let grown = grow::grow(species, seed, health);
    let mesh = mesh::build(grown, species.levels.len());
    Ok(Tree {
        species: species.name,
        seed,
        health,
        mesh,
        bark_png: textures::bark_png(species).map_err(TreeError::Texture)?,
        leaf_png: textures::leaf_png(&species.leaves, health).map_err(TreeError::Texture)?,
    })
}

impl Tree {
    /// Radius of the bounding sphere centred at half the tree's height, per metre of height: the
    /// class tables' `radius_per_height`, for culling.
    pub fn radius_per_height(&self) -> f32 {
        let parts = [&self.mesh.bark, &self.mesh.leaves];
        let top_m = parts.iter().flat_map(|p| &p.positions).map(|p| p[1]).fold(1e-3, f32::max);
        let centre = glam::Vec3::new(0.0, 0.5 * top_m, 0.0);
        let radius_m =
            parts.iter().flat_map(|p| &p.positions).map(|&p| centre.distance(p.into())).fold(0.0, f32::max);
        radius_m / top_m
    }

    /// The tree as a glTF 2.0 binary (`.glb`): unless it has none, a leaf primitive (alpha-masked,
    /// two-sided) first, then one bark primitive per branching level, trunk first, each material
    /// with its continuous LOD (`impostor::Detail`): the baker keeps materials in this order, so
    /// the mesh's index buffer runs from the first leaves to thin out to the finest twigs.
    pub fn to_glb(&self) -> Vec<u8> {
        let name = format!("{} {} h{:.2}", self.species, self.seed, self.health);
        let leaves = Material {
            name: "leaves".into(),
            png: &self.leaf_png,
            alpha: Alpha::Mask(LEAF_ALPHA_CUTOFF),
            double_sided: true,
            detail: Some(Detail::Leaves { size_m: self.mesh.leaf_size_m }),
        };
        let levels = self.mesh.bark_by_level();
        let mut primitives = vec![(&self.mesh.leaves, leaves)];
        for (level, (part, &diameter_m)) in levels.iter().zip(&self.mesh.level_diameters_m).enumerate() {
            let bark = Material {
                name: format!("bark {level}"),
                png: &self.bark_png,
                alpha: Alpha::Opaque,
                double_sided: false,
                detail: Some(Detail::Stems { diameter_m }),
            };
            primitives.push((part, bark));
        }
        glb::write(&name, &primitives)
    }
}

#[cfg(test)]
mod tests;
