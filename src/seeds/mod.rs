//! How it works: the seeded world, defined once (paper § 4.4). The ground is tiled by the TLM's
//! ring-0 cells; each cell shows one of P generic blue-noise patterns (`patterns`), picked by the
//! hashed colours of its four lattice corners, so a place always shows the same seeds, neighbours
//! differ, and any two neighbours' seeds agree across their border. A
//! seed is identified by (cell address, rank in the pattern); everything random about it (its
//! size, orientation, colour, where its ground colour is sampled) derives from one hash of that
//! identity and the world's seed number.
//!
//! Which seeds grow is decided by the land-cover class under them: a class's species table gives
//! cumulative densities, scaled by the cell's area into rank limits, and a seed of rank r becomes
//! the first species whose limit exceeds r. Thinning by rank keeps every density blue noise and
//! makes a class's seed count in a cell exact. `SeedTables` turns a class table and a land-cover
//! coding into those limits, as the GPU pass, its CPU twin and the exact oracle all read them:
//! they disagree only on visibility, never on what exists.

pub mod patterns;
pub mod spacing;
pub mod wind;

use thiserror::Error;

use crate::classes::{ClassTable, MAX_SPECIES, MAX_SPECIES_PER_CLASS, SpeciesKind};
use crate::dataset::lcc::LccCoding;
use crate::gpu::gpu_types::{SeedClass, SeedSpecies};
use crate::gpu::layout::{KIND_BUSH, KIND_ROCK, KIND_TREE, SEED_SALT, SEED_VARIANT_SALT, SEED_WORKGROUP};

/// Cells one dispatch checks at most (a dispatch dimension's limit).
pub const MAX_SEED_CELLS: u32 = 65535;
/// Entries of pass 3's block table at most (one per workgroup: 8 MiB, 64 M seeds checked per
/// frame); a frame checks no more cells than fill it (`max_cells`).
pub const MAX_SEED_BLOCKS: u32 = 1 << 20;

/// Why `SeedTables::new` refuses a class table for this dataset and these settings.
#[derive(Debug, Error)]
pub enum SeedError {
    /// A class's total density (after `seeds.density_scale`) needs more seeds per ring-0 cell than
    /// a pattern holds.
    #[error(
        "class {code} ({name}) asks for {density_per_km2} seeds per km²; the patterns hold {max_per_km2:.0} \
         (seeds.seeds_per_pattern / tlm.cell_m²): raise seeds.seeds_per_pattern or lower the density"
    )]
    TooDense {
        /// The class's land-cover code.
        code: u8,
        /// The class's name.
        name: String,
        /// Seeds per km² it asks for, summed over its rules and scaled.
        density_per_km2: f64,
        /// Seeds per km² the patterns hold: `seeds.seeds_per_pattern / tlm.cell_m²`.
        max_per_km2: f64,
    },
    /// The table has more species than the GPU's species table holds (`MAX_SPECIES`); parsed
    /// tables are checked already, so only a table built in code gets here.
    #[error("class table {scheme}: more than {MAX_SPECIES} species")]
    TooManySpecies {
        /// The table's `ClassTable::scheme`.
        scheme: String,
    },
}

/// Workgroups (block-table entries) pass 3 runs per cell when it checks `active_ranks` ranks.
pub fn workgroups_per_cell(active_ranks: u32) -> u32 {
    active_ranks.div_ceil(SEED_WORKGROUP)
}

/// Cells one frame can check at `active_ranks` ranks each: the dispatch limit, and the block table.
pub fn max_cells(active_ranks: u32) -> u32 {
    MAX_SEED_CELLS.min(MAX_SEED_BLOCKS / workgroups_per_cell(active_ranks).max(1))
}

/// Entries the block table needs for patterns of `seeds_per_pattern` seeds.
pub fn block_capacity(seeds_per_pattern: u32) -> u32 {
    (MAX_SEED_CELLS * workgroups_per_cell(seeds_per_pattern)).clamp(1, MAX_SEED_BLOCKS)
}

/// PCG (O'Neill), as a hash: the shaders' `pcg`.
pub fn pcg(v: u32) -> u32 {
    let state = v.wrapping_mul(747796405).wrapping_add(2891336453);
    let word = ((state >> ((state >> 28) + 4)) ^ state).wrapping_mul(277803737);
    (word >> 22) ^ word
}

/// Which of its species' `variants` models a seed of hash `hash` is drawn with: the shader's
/// `seed_variant`. Independent of the seed's height, turn and colour (its own salt).
pub fn seed_variant(hash: u32, variants: u32) -> u32 {
    pcg(hash ^ SEED_VARIANT_SALT) % variants.max(1)
}

/// The seed-pattern hash of ring-0 cell (`x`, `y`) (global address, as two's-complement bits).
pub fn pattern_hash(x: u32, y: u32, seed: u32) -> u32 {
    pcg(x ^ pcg(y ^ pcg(seed)))
}

/// The colour, of `colours`, of lattice corner (`x`, `y`) of the ring-0 cell grid (the corner at
/// the south-west of cell (x, y)): the shader's `corner_colour`.
pub fn corner_colour(x: u32, y: u32, seed: u32, colours: u32) -> u32 {
    pattern_hash(x, y, seed) % colours.max(1)
}

/// The pattern ring-0 cell `address` shows: the one of its four corners' colours,
/// c₀₀ + C (c₁₀ + C (c₀₁ + C c₁₁)) of the C⁴ (`patterns::SeedPatterns`). The shader's
/// `cell_pattern`.
pub fn cell_pattern(address: [i32; 2], seed: u32, colours: u32) -> u32 {
    let (x, y, c) = (address[0] as u32, address[1] as u32, colours.max(1));
    let k = |dx: u32, dy: u32| corner_colour(x.wrapping_add(dx), y.wrapping_add(dy), seed, c);
    k(0, 0) + c * (k(1, 0) + c * (k(0, 1) + c * k(1, 1)))
}

/// The hash of seed `rank` of cell `address`: the shader's `seed_hash`.
pub fn seed_hash(address: [i32; 2], rank: u32, seed: u32) -> u32 {
    pcg(rank ^ pattern_hash(address[0] as u32, address[1] as u32, seed ^ SEED_SALT))
}

/// A hash as a number in [0, 1), exactly representable in f32.
pub fn unit(hash: u32) -> f32 {
    (hash >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// The seed's height from its species and hash: the shader's `seed_height`.
pub fn seed_height_m(species: &SeedSpecies, hash: u32) -> f32 {
    species.height_m[0] + (species.height_m[1] - species.height_m[0]) * unit(hash)
}

/// Which species (index into the species table) seed `rank` of a cell of `class` becomes, if any.
pub fn species_of_rank(class: &SeedClass, rank: u32) -> Option<u32> {
    let r = rank as f32;
    (0..MAX_SPECIES_PER_CLASS).find(|&k| r < class.rank_limit[k]).map(|k| class.species[k])
}

/// The per-dataset tables of pass 3: species, and per land-cover palette index its seeds.
#[derive(Debug, Clone, PartialEq)]
pub struct SeedTables {
    /// The class table's species in its order (a rule's species index points here): height and
    /// altitude ranges in metres, steepest slope, crown radius, kind.
    pub species: Vec<SeedSpecies>,
    /// Indexed by palette index (0: bare ground, no seeds).
    pub classes: Vec<SeedClass>,
}

impl SeedTables {
    /// The tables for a dataset coded with `coding`, its classes grown per `table` with every
    /// density scaled by `density_scale` (`seeds.density_scale`: rank thinning keeps exactly that
    /// fraction, still blue noise), on patterns of `seeds_per_pattern` seeds over cells of `cell_m`.
    pub fn new(
        table: &ClassTable,
        coding: &LccCoding,
        cell_m: f64,
        seeds_per_pattern: u32,
        density_scale: f64,
    ) -> Result<Self, SeedError> {
        if table.species.len() > MAX_SPECIES {
            return Err(SeedError::TooManySpecies { scheme: table.scheme.clone() });
        }
        let species = table
            .species
            .iter()
            .map(|s| {
                let tan = s.max_slope_deg.to_radians().tan();
                SeedSpecies {
                    height_m: s.height_m,
                    altitude_m: s.altitude_m,
                    max_slope_tan_sq: if s.max_slope_deg >= 90.0 { f32::INFINITY } else { tan * tan },
                    radius_per_height: s.radius_per_height,
                    kind: match s.kind {
                        SpeciesKind::Tree => KIND_TREE,
                        SpeciesKind::Bush => KIND_BUSH,
                        SpeciesKind::Rock => KIND_ROCK,
                    },
                    wind_bend: wind::bend_of(s.kind),
                    variants: s.variants,
                    _pad: 0,
                }
            })
            .collect();
        let cell_km2 = (cell_m / 1000.0).powi(2);
        let max_per_km2 = f64::from(seeds_per_pattern) / cell_km2;
        let mut classes = vec![SeedClass::default(); coding.palette.len() + 1];
        for (index, entry) in classes.iter_mut().enumerate().skip(1) {
            let Some(class) = coding.code_of(index as u32).and_then(|code| table.class(code)) else {
                continue;
            };
            entry.lods = class.seed_lods;
            let mut cumulative_per_km2 = 0.0f64;
            for (k, rule) in class.seeds.iter().enumerate().take(MAX_SPECIES_PER_CLASS) {
                cumulative_per_km2 += f64::from(rule.per_km2) * density_scale;
                entry.rank_limit[k] = (cumulative_per_km2 * cell_km2) as f32;
                entry.species[k] = table.species_index(&rule.species).unwrap_or_default() as u32;
            }
            if cumulative_per_km2 > max_per_km2 {
                return Err(SeedError::TooDense {
                    code: class.code,
                    name: class.name.clone(),
                    density_per_km2: cumulative_per_km2,
                    max_per_km2,
                });
            }
        }
        Ok(Self { species, classes })
    }

    /// Ranks below which some class grows a seed: the rest of every pattern is culled by class
    /// whatever the map says, so pass 3 need not check it.
    pub fn active_ranks(&self) -> u32 {
        let limit = self.classes.iter().flat_map(|c| c.rank_limit).fold(0.0f32, f32::max);
        limit.ceil() as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_is_in_range_and_exact() {
        assert_eq!(unit(0), 0.0);
        assert!(unit(u32::MAX) < 1.0);
        assert_eq!(unit(1 << 8), 1.0 / 16_777_216.0);
    }

    #[test]
    fn seed_hash_depends_on_every_input() {
        let h = seed_hash([3, -4], 17, 1);
        assert_eq!(h, seed_hash([3, -4], 17, 1));
        assert_ne!(h, seed_hash([4, -4], 17, 1));
        assert_ne!(h, seed_hash([3, -3], 17, 1));
        assert_ne!(h, seed_hash([3, -4], 18, 1));
        assert_ne!(h, seed_hash([3, -4], 17, 2));
    }

    #[test]
    fn every_frame_fits_the_block_table() {
        for spp in [64, 100, 1280, 2048, 4096, 65536] {
            let capacity = block_capacity(spp);
            assert!(capacity <= MAX_SEED_BLOCKS, "{spp}");
            for ranks in (0..=spp).step_by(7).chain([spp]) {
                assert!(max_cells(ranks) * workgroups_per_cell(ranks) <= capacity, "{spp} {ranks}");
            }
        }
        assert_eq!(max_cells(2048), 32768);
    }

    #[test]
    fn variants_share_a_species_evenly_whatever_the_height() {
        let seeds = 40_000u32;
        for variants in [1, 2, 3, 4] {
            // Seeds counted per variant, among all and among the short half (`unit(hash) < 0.5`).
            let (mut all, mut short) = (vec![0u32; variants as usize], vec![0u32; variants as usize]);
            for rank in 0..seeds {
                let hash = seed_hash([rank as i32 % 97, rank as i32 / 97], rank, 7);
                let v = seed_variant(hash, variants) as usize;
                all[v] += 1;
                short[v] += u32::from(unit(hash) < 0.5);
            }
            let share = 1.0 / f64::from(variants);
            let total_short: u32 = short.iter().sum();
            // Four standard deviations of a fair draw's share: 0.0025 over 40,000 seeds at a half,
            // 0.0035 over the short 20,000; a variant tied to the height would be off by far more.
            assert!(total_short > seeds / 3, "{total_short} short seeds");
            for (a, s) in all.iter().zip(&short) {
                assert!((f64::from(*a) / f64::from(seeds) - share).abs() < 0.01, "{variants}: {all:?}");
                assert!(
                    (f64::from(*s) / f64::from(total_short) - share).abs() < 0.015,
                    "{variants}: {short:?}"
                );
            }
        }
        assert_eq!(seed_variant(12345, 0), 0);
    }

    #[test]
    fn rank_thinning_picks_species_by_cumulative_density() {
        let class =
            SeedClass { rank_limit: [10.0, 15.5, 0.0, 0.0], species: [4, 7, 0, 0], ..SeedClass::default() };
        assert_eq!(species_of_rank(&class, 0), Some(4));
        assert_eq!(species_of_rank(&class, 9), Some(4));
        assert_eq!(species_of_rank(&class, 10), Some(7));
        assert_eq!(species_of_rank(&class, 15), Some(7));
        assert_eq!(species_of_rank(&class, 16), None);
        assert_eq!(species_of_rank(&SeedClass::default(), 0), None);
    }
}
