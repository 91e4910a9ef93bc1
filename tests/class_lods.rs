//! A class's own last draw LOD (`[[class]] seed_lods` in a class table): pass 3 culls its seeds
//! beyond it by distance and marks the last one so that they fade out there, exactly as its twin
//! and the exact oracle do, and leaves every other class's seeds as they were.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::collections::HashMap;

use terramp::frame::Renderer;
use terramp::gpu::gpu_types::SeedRecord;
use terramp::gpu::layout::{SEED_LODS, SpeciesLod};
use terramp::reference::oracle::visible_seeds;
use terramp::reference::seed_select::SeedComparison;
use terramp_testkit::camera::over_fraction;

/// The species of nc's table that grows in shrubland only: the test's shrubland grows it alone.
const SHRUBLAND_ONLY: &str = "virginia pine";
/// The draw LODs the shrubland keeps: the mesh and the first billboard-cloud band.
const SHRUBLAND_LODS: u32 = 2;

type Identity = ([i32; 2], u32);

fn by_identity(records: &[SeedRecord]) -> HashMap<Identity, SpeciesLod> {
    records.iter().map(|r| ((r.address, r.rank), SpeciesLod::unpack(r.species_lod))).collect()
}

#[test]
fn a_class_draws_its_seeds_to_its_own_last_lod() {
    // nc's table with a shrubland of pines alone (no other class grows them), twice: drawn to
    // every LOD, and to its first SHRUBLAND_LODS.
    let nc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/config/classes/nc.toml")).unwrap();
    let start = nc.find("name = \"shrubland\"\n").unwrap();
    let end = start + nc[start..].find("\n]\n").unwrap() + 3;
    let shrubland = |lods: u32| {
        let class = format!(
            "name = \"shrubland\"\nseed_lods = {lods}\nseeds = [{{ species = \"{SHRUBLAND_ONLY}\", per_km2 = 3000.0 }}]\n"
        );
        format!("{}{class}{}", &nc[..start], &nc[end..])
    };
    let paths = [SEED_LODS, SHRUBLAND_LODS].map(|lods| {
        let path =
            std::env::temp_dir().join(format!("terramp-class-lods-{lods}-{}.toml", std::process::id()));
        std::fs::write(&path, shrubland(lods)).unwrap();
        path
    });
    assert_eq!(nc.matches(SHRUBLAND_ONLY).count(), 2, "nc's {SHRUBLAND_ONLY} grows elsewhere than shrubland");

    let dataset = terramp_testkit::synth_dataset(1024, 7);
    let render = |class_table: &str| {
        let mut settings = terramp_testkit::small_settings(320, 180);
        settings.seeds.class_table = class_table.to_owned();
        let mut r = terramp_testkit::renderer(&dataset, settings);
        // High and looking far, so the shrubland's pines reach every band.
        let camera = over_fraction(&r, [0.6, 0.5], 300.0, 200.0, -12.0);
        r.render_resolved(&camera).unwrap();
        (r, camera)
    };
    let (all, camera) = render(paths[0].to_str().unwrap());
    let (near, _) = render(paths[1].to_str().unwrap());
    for path in paths {
        let _ = std::fs::remove_file(path);
    }
    let pine = all.class_table().unwrap().species_index(SHRUBLAND_ONLY).unwrap() as u32;
    let is_pine = |s: &SpeciesLod| {
        let species = &all.class_table().unwrap().species[s.species as usize];
        species.name == SHRUBLAND_ONLY
    };

    let (all_seeds, all_counters) = all.read_seeds().unwrap().unwrap();
    let (near_seeds, near_counters) = near.read_seeds().unwrap().unwrap();
    let mut far_pines = 0;
    let mut lods = [0usize; SEED_LODS as usize];
    for s in all_seeds.iter().map(|r| SpeciesLod::unpack(r.species_lod)).filter(is_pine) {
        lods[s.lod as usize] += 1;
        far_pines += usize::from(s.lod >= SHRUBLAND_LODS);
        assert_eq!(
            s.last,
            u32::from(s.lod + 1 == SEED_LODS),
            "every class draws every LOD by default: {s:?}"
        );
    }
    println!("{SHRUBLAND_ONLY} (species {pine}) per LOD with every LOD drawn: {lods:?}");
    println!(
        "selected: {} with every LOD, {} with shrubland to LOD {SHRUBLAND_LODS}",
        all_counters.selected, near_counters.selected
    );
    assert!(far_pines >= 20 && lods[0] + lods[1] >= 20, "too few pines to judge: {lods:?}");

    // The GPU equals its twin with the class's rule.
    let (twin, twin_counters) = near.seed_twin().unwrap().unwrap();
    assert_eq!(near_counters, twin_counters);
    let diff = SeedComparison::of(&near_seeds, &twin);
    assert!(diff.only_gpu.is_empty() && diff.only_twin.is_empty() && diff.mismatched.is_empty(), "{diff:?}");

    // The shrubland's pines stop at its last LOD, and are marked there; nothing else changes.
    let near_by_id = by_identity(&near_seeds);
    for (id, before) in by_identity(&all_seeds) {
        let after = near_by_id.get(&id);
        if !is_pine(&before) {
            assert_eq!(after, Some(&before), "seed {id:?} of another class changed");
        } else if before.lod >= SHRUBLAND_LODS {
            assert_eq!(after, None, "seed {id:?} drawn beyond its class's last LOD");
        } else {
            let last = u32::from(before.lod + 1 == SHRUBLAND_LODS);
            assert_eq!(after, Some(&SpeciesLod { last, ..before }), "seed {id:?}");
        }
    }
    assert_eq!(near_seeds.len() + far_pines, all_seeds.len());
    assert_eq!(near_counters.selected as usize + far_pines, all_counters.selected as usize);

    // The exact oracle (and so the ground truth's recall) follows the same rule.
    let oracle_far = |r: &Renderer| {
        let seeds = visible_seeds(&r.oracle_inputs(&camera).unwrap()).unwrap().0;
        let pines = seeds.iter().filter(|s| s.species == pine);
        (pines.clone().filter(|s| s.lod >= SHRUBLAND_LODS).count(), pines.count())
    };
    let (all_far, all_pines) = oracle_far(&all);
    let (near_far, near_pines) = oracle_far(&near);
    println!(
        "oracle's pines: {all_pines} ({all_far} beyond LOD {SHRUBLAND_LODS}) against {near_pines} ({near_far})"
    );
    assert!(all_far > 0, "the oracle sees no far pine to cut");
    assert_eq!((near_far, near_pines), (0, all_pines - all_far));
}
