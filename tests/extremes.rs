//! The extremes of DESIGN.md ("Extremes the numbers must survive"), each a test on the software
//! adapter over small synthetic datasets; every frame is audited (`terramp_testkit::audit`): depth, colour,
//! Tile Load Map and seed records read back and checked for non-finite or out-of-range values,
//! holes and stray ground judged against rays cast through the f64 DEM.
//!
//! - `coordinates`: UTM-like and 10⁷ m offsets render the same image and the same seeds; seeds in
//!   a planet-size dataset, 10⁷ m from its origin, stand where the patterns put them.
//! - `depth`: reversed-Z keeps depths distinct from 0.1 m to 500 km (f32 arithmetic, and two
//!   surfaces close together rasterised far away); cameras 2 m and 100 km / 500 km up.
//! - `grazing`: views at 89.9° incidence and exactly horizontal.
//! - `datasets`: cameras outside every corner and edge looking in, datasets of one sample and one
//!   tile, zero seeds.
//! - `degenerate`: zero-area and oversized viewports, fields of view near 0° and 180°, non-finite
//!   and absurd cameras, a camera inside the terrain.
//!
//! Covered elsewhere and not repeated here: more seeds than the output holds
//! (`tests/seed_select.rs`, `overflow_is_flagged_counted_and_keeps_valid_records`), land-cover
//! codes outside the class table (`tests/seed_select.rs`, `classes_missing_from_the_table_grow_nothing`),
//! keys outside the draw groups (`tests/compact.rs`), no-adapter errors (`tests/render.rs`), and
//! real data: DEM voids and nodata (`rainier/`, `zion/`) and hand-made cliffs in
//! `data-tools/tests/extremes.rs`; the round Earth's: the antimeridian, a pole, 0.5 m above the
//! ground at 179.9999° E (`data-tools/tests/earth_extremes.rs`) and 40,000 km up
//! (`data-tools/tests/earth_orbit.rs`).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

#[path = "extremes/coordinates.rs"]
mod coordinates;
#[path = "extremes/datasets.rs"]
mod datasets;
#[path = "extremes/degenerate.rs"]
mod degenerate;
#[path = "extremes/depth.rs"]
mod depth;
#[path = "extremes/grazing.rs"]
mod grazing;
