//! The packed words, the constants' names and the page and pattern codings, round-tripped.

use super::*;

#[test]
fn words_round_trip_and_mask_each_field() {
    let s = SpeciesLod { species: 9, lod: 3, last: 1, lcc_level: 2, height_level: 11 };
    assert_eq!(s.pack(), 9 | 3 << 8 | 1 << 11 | 2 << 12 | 11 << 16);
    assert_eq!(SpeciesLod::unpack(s.pack()), s);
    let wide = LevelRange { min: 0x1ff, max: 1 };
    assert_eq!(LevelRange::unpack(wide.pack()), LevelRange { min: 0xff, max: 1 });
    assert_eq!(TileSpan { first: 3, last: 70_000 }.pack() >> 16, 70_000 & 0xffff);
    assert_eq!(SeedJitter::unpack(0xabcd_1234), SeedJitter { angle: 0x1234, colour: 0xabcd });
}

#[test]
fn every_constant_is_declared_once() {
    let names: Vec<_> = wgsl_constants().into_iter().map(|(name, ..)| name).collect();
    let mut unique = names.clone();
    unique.sort_unstable();
    unique.dedup();
    assert_eq!(names.len(), unique.len(), "{names:?}");
    assert!(names.contains(&"RADIAL_INACTIVE") && names.contains(&"COUNT_OCCLUSION"));
}

#[test]
fn page_entries_and_patterns_round_trip() {
    assert_eq!(page_slot(PAGE_EMPTY), None);
    assert_eq!(page_slot(page_entry(7)), Some(7));
    assert_eq!(tlm_pattern(TLM_CULLED), None);
    assert_eq!(tlm_pattern(tlm_visibility(5)), Some(5));
    assert_eq!(seed_group(MAX_SPECIES - 1, SEED_LODS - 1), SEED_GROUPS - 1);
}
