//! Seed selection (pass 3) on real data: `nc/` (DEM, Landsat, land use) and `zion/` (DEM and
//! NLCD) are built into a temporary folder. The GPU pass equals its CPU twin from several
//! cameras, with every seed on the f64 drawn ground (the finest mesh's triangles); against the
//! exact oracle, the `accurate` preset keeps at least 99 % of the visible seeds with at least 95 %
//! precision; and on `nc/` the species follow the map: no trees on water or developed land, and
//! each class's seed count matches its table density over the ground it covers.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

/// Most a ground colour's channel may differ, GPU against twin, in steps of 255: the driver's sRGB
/// table against the twin's formula may round one step apart.
const MAX_COLOUR_ERROR: u32 = 1;
/// Most a seed's base may lie off the f64 drawn ground, millimetres: f32 heights of up to 2,700 m
/// and camera-relative positions give 0.05–0.30 mm (docs/seeds.md); a centimetre is far above that
/// rounding and far below the metres by which the bilinear patch missed the triangles.
const MAX_BASE_MM: f64 = 10.0;
/// Least recall of the accurate preset against the exact oracle: it marches the DEM where a summit
/// is within a pixel of a silhouette and lost no visible seed on these views (docs/seeds.md); the
/// percent is for summits within f32 rounding of a ridge.
const MIN_RECALL: f64 = 0.99;
/// Least precision: the preset keeps summits hidden by less than its occlusion tolerance (2 m +
/// 8 m per km), 0.01–1.8 % of what it keeps on these views (docs/seeds.md).
const MIN_PRECISION: f64 = 0.95;

use std::collections::HashSet;

use glam::DVec3;
use terramp::camera::Camera;
use terramp::classes::{ClassTable, SpeciesKind};
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::gpu::gpu_types::SeedRecord;
use terramp::gpu::layout::SpeciesLod;
use terramp::passes::seed_select::frame::SeedCellRef;
use terramp::reference::accuracy::{HeightError, SeedAgreement, SeedId, record_id};
use terramp::reference::oracle::{OracleInputs, visible_seeds};
use terramp::reference::seed_select::{SeedComparison, class_offset};
use terramp::seeds::cell_pattern;
use terramp_testkit::camera::posed;

use support::{build_nc, build_nc_ndvi, build_zion};
use terramp_testkit::{TempDir, shared_data};

/// Named camera poses: grid x, y, height above the ground, yaw, pitch.
type Poses<'a> = &'a [(&'a str, [f64; 5])];

fn renderer(dataset: Dataset, mut settings: Settings, width: u32, height: u32) -> Renderer {
    settings.render.width = width;
    settings.render.height = height;
    let gpu = terramp_testkit::gpu();
    Renderer::new(gpu, dataset, settings).unwrap()
}

/// Largest distance between a seed's base and the f64 drawn ground under it, metres.
fn worst_base_error_m(r: &Renderer, camera: &Camera, seeds: &[SeedRecord]) -> f64 {
    HeightError::of(&r.dataset, &r.exact_placing(camera), seeds).unwrap().max_m
}

fn gpu_equals_twin(dataset: Dataset, views: Poses) {
    let mut r = renderer(dataset, Settings::default(), 320, 180);
    for &(what, pose) in views {
        let camera = posed(&r, pose);
        r.render_resolved(&camera).unwrap();
        let (gpu, gpu_counters) = r.read_seeds().unwrap().unwrap();
        let (twin, twin_counters) = r.seed_twin().unwrap().unwrap();
        let diff = SeedComparison::of(&gpu, &twin);
        let base_mm = worst_base_error_m(&r, &camera, &gpu) * 1000.0;
        println!(
            "{what}: {} checked, {} selected, culled class {} rule {} distance {} frustum {} occlusion {}; \
             length error {:.1e} m, colour {}/255, base within {base_mm:.2} mm",
            twin_counters.checked,
            twin_counters.selected,
            twin_counters.class,
            twin_counters.rule,
            twin_counters.distance,
            twin_counters.frustum,
            twin_counters.occlusion,
            diff.max_length_error_m,
            diff.max_colour_error
        );
        assert!(!twin.is_empty(), "{what}: no seeds");
        assert_eq!(gpu_counters, twin_counters, "{what}");
        assert!(diff.only_gpu.is_empty() && diff.only_twin.is_empty(), "{what}: {diff:?}");
        assert!(diff.mismatched.is_empty(), "{what}: {:?}", diff.mismatched);
        assert!(diff.non_finite.is_empty(), "{what}: not finite: {:?}", diff.non_finite);
        assert_eq!(diff.max_length_error_m, 0.0, "{what}");
        assert!(diff.max_colour_error <= MAX_COLOUR_ERROR, "{what}");
        assert!(base_mm <= MAX_BASE_MM, "{what}: a seed's base is {base_mm} mm off the DEM");
    }
}

#[test]
fn nc_and_zion_gpu_equals_twin() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("seeds-twin");
    gpu_equals_twin(
        build_nc(&tmp.path().join("nc")),
        &[
            ("nc oblique", [6000.0, 5000.0, 120.0, 40.0, -12.0]),
            ("nc low", [9000.0, 8000.0, 4.0, 200.0, 0.0]),
            ("nc high", [3000.0, 3000.0, 900.0, 60.0, -35.0]),
        ],
    );
    // The imagery's vegetation index thins the seeds (`seeds.vegetation_*`).
    gpu_equals_twin(
        build_nc_ndvi(&tmp.path().join("nc_ndvi")),
        &[
            ("nc ndvi oblique", [6000.0, 5000.0, 120.0, 40.0, -12.0]),
            ("nc ndvi high", [3000.0, 3000.0, 900.0, 60.0, -35.0]),
        ],
    );
    gpu_equals_twin(
        build_zion(&tmp.path().join("zion")),
        &[
            ("zion canyon", [17000.0, 20000.0, 60.0, 0.0, -5.0]),
            ("zion high", [12000.0, 25000.0, 800.0, 120.0, -25.0]),
            ("zion rim", [25000.0, 15000.0, 10.0, 270.0, -2.0]),
        ],
    );
}

/// Recall and precision of the GPU's seeds against the oracle's visible set from `pose`.
fn recall_precision(r: &mut Renderer, what: &str, pose: [f64; 5]) -> (f64, f64, usize) {
    let camera = posed(r, pose);
    r.render_resolved(&camera).unwrap();
    let (gpu, _) = r.read_seeds().unwrap().unwrap();
    let (tables, patterns) = r.seed_world().unwrap();
    let viewport_px = [r.settings.render.width, r.settings.render.height];
    let inputs = OracleInputs {
        dataset: &r.dataset,
        settings: &r.settings,
        tables,
        patterns,
        camera: &camera,
        viewport_px,
    };
    let (truth_seeds, counts) = visible_seeds(&inputs).unwrap();
    let agreement = SeedAgreement::of(&gpu, &truth_seeds);
    let truth: HashSet<SeedId> = truth_seeds.iter().map(|s| (s.address, s.rank)).collect();
    let kept: HashSet<SeedId> = gpu.iter().map(record_id).collect();
    // Where the GPU's set differs, and why: TLM cells never activated, or seeds the GPU keeps
    // whose summit the exact DEM hides or whose sphere only the frustum margin keeps.
    let snapshot = r.seed_snapshot().unwrap().unwrap();
    let active: HashSet<[i64; 2]> =
        snapshot.frame.cells.iter().map(|c| [i64::from(c.address[0]), i64::from(c.address[1])]).collect();
    let missed = agreement.missed();
    let missed_cells = truth.difference(&kept).filter(|(a, _)| !active.contains(a)).count();
    let placing = r.exact_placing(&camera);
    let eye = placing.camera_grid_m();
    let extra_hidden = gpu
        .iter()
        .filter(|g| !truth.contains(&record_id(g)))
        .filter(|g| {
            let rel = DVec3::from(g.position_rel_m.map(f64::from)) + DVec3::Z * f64::from(g.height_m);
            !terramp::reference::oracle::segment_clears_dem(&r.dataset, eye, placing.grid_m(rel)).unwrap()
        })
        .count();
    println!(
        "{what}: {missed} missed ({missed_cells} in cells the TLM left out); {} extra ({extra_hidden} hidden by the DEM)",
        agreement.extra()
    );
    let (recall, precision) = (agreement.recall(), agreement.precision());
    println!(
        "{what}: oracle {} visible of {} candidates ({counts:?}); GPU {} kept; recall {:.2} %, precision {:.2} %",
        agreement.visible,
        counts.candidates,
        agreement.kept,
        100.0 * recall,
        100.0 * precision
    );
    (recall, precision, agreement.visible as usize)
}

#[test]
fn accurate_preset_against_the_exact_oracle() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("seeds-oracle");
    let accurate = Settings::preset("accurate").unwrap();
    let views: [(Dataset, Poses); 2] = [
        (
            build_nc(&tmp.path().join("nc")),
            &[
                ("nc oblique", [6000.0, 5000.0, 120.0, 40.0, -12.0]),
                ("nc low", [9000.0, 8000.0, 4.0, 200.0, 0.0]),
            ],
        ),
        (
            build_zion(&tmp.path().join("zion")),
            &[
                ("zion canyon", [17000.0, 20000.0, 60.0, 0.0, -5.0]),
                ("zion rim", [25000.0, 15000.0, 10.0, 270.0, -2.0]),
            ],
        ),
    ];
    for (dataset, poses) in views {
        let mut r = renderer(dataset, accurate.clone(), 640, 360);
        for &(what, pose) in poses {
            let (recall, precision, visible) = recall_precision(&mut r, what, pose);
            assert!(visible > 100, "{what}: only {visible} visible seeds; pick a better view");
            assert!(recall >= MIN_RECALL, "{what}: recall {recall}");
            assert!(precision >= MIN_PRECISION, "{what}: precision {precision}");
        }
    }
}

#[test]
fn nc_species_follow_the_land_cover() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("seeds-classes");
    let dataset = build_nc(&tmp.path().join("nc"));
    let mut settings = Settings::default();
    // Every seed of the block counts: no size-scaled distance cut, nothing hidden from above.
    settings.tlm.radial_bands_m = [30000.0, 40000.0, 50000.0];
    settings.draw_seeds.reach_m = [120.0, 30000.0, 40000.0, 50000.0];
    settings.seeds.reference_height_m = 0.01;
    settings.seeds.capacity = 1 << 21;
    let tiles = |p: Option<&terramp::dataset::LayerPack>| p.map_or(16, |l| l.pyramid.tile_count() as u32);
    settings.cache.height_slots = tiles(Some(&dataset.height)).max(16);
    settings.cache.imagery_slots = tiles(dataset.imagery.as_ref()).max(16);
    settings.cache.landcover_slots = tiles(dataset.landcover.as_ref()).max(16);
    let mut r = renderer(dataset, settings, 320, 320);
    r.pin_everything().unwrap();
    let [w, h] = r.dataset.manifest.extent_m();
    // Straight down from high above the middle: a 16 × 16 block of cells (4 km) in full view.
    let camera = posed(&r, [0.5 * w, 0.5 * h, 12000.0, 0.0, -89.9]);
    r.render_resolved(&camera).unwrap();
    let cell_m = r.settings.tlm.cell_m;
    let first = [0.5 * w, 0.5 * h].map(|v| (v / cell_m).floor() as i64 - 8);
    let (seed, colours) = (r.settings.tlm.seed, r.settings.tlm.corner_colours());
    let cells: Vec<SeedCellRef> = (0..256)
        .map(|k| {
            let address = [first[0] + k % 16, first[1] + k / 16];
            SeedCellRef {
                address,
                pattern: cell_pattern([address[0] as i32, address[1] as i32], seed, colours),
                radial_lod: 1,
            }
        })
        .collect();
    r.run_seed_select(&camera, &cells).unwrap();
    let (records, counters) = r.read_seeds().unwrap().unwrap();
    assert_eq!((counters.frustum, counters.occlusion, counters.overflow), (0, 0, 0), "{counters:?}");

    let table = ClassTable::load("nc").unwrap();
    let meta = r.dataset.manifest.landcover.clone().unwrap();
    let texel_m = 2.0 * meta.layer.texel_m;
    let half = 0.5 * r.dataset.manifest.height.spacing_m;
    let placing = r.exact_placing(&camera);
    let code_at = |x: f64, y: f64| {
        let q = [((x + half) / texel_m).floor() as u32, ((y + half) / texel_m).floor() as u32];
        meta.coding.code_of(r.dataset.landcover_index(1, q).unwrap()).unwrap_or(meta.nodata_code)
    };
    let mut seeds_per_code = std::collections::BTreeMap::<u8, u64>::new();
    for s in &records {
        // Its class is read where its hash moves it, up to half a texel (`class_offset`).
        let offset = class_offset(s.address, s.rank, r.settings.tlm.seed).map(|v| f64::from(v) * texel_m);
        let grid = placing.grid_m(DVec3::from(s.position_rel_m.map(f64::from)));
        let code = code_at(grid.x + offset[0], grid.y + offset[1]);
        let species = &table.species[SpeciesLod::unpack(s.species_lod).species as usize];
        assert!(
            !(species.kind == SpeciesKind::Tree && (code == 1 || code == 6)),
            "a {} stands on class {code}",
            species.name
        );
        *seeds_per_code.entry(code).or_default() += 1;
    }
    // The block's area per class, from the level-1 texels whose centres lie in it.
    let (lo, hi) = (first.map(|v| v as f64 * cell_m), first.map(|v| (v + 16) as f64 * cell_m));
    let mut area_km2 = std::collections::BTreeMap::<u8, f64>::new();
    let texels =
        |a: usize| ((lo[a] + half) / texel_m).floor() as u32..((hi[a] + half) / texel_m).ceil() as u32;
    for qy in texels(1) {
        for qx in texels(0) {
            let centre = [(f64::from(qx) + 0.5) * texel_m - half, (f64::from(qy) + 0.5) * texel_m - half];
            if (0..2).all(|a| centre[a] >= lo[a] && centre[a] < hi[a]) {
                *area_km2.entry(code_at(centre[0], centre[1])).or_default() += texel_m * texel_m * 1e-6;
            }
        }
    }
    let mut compared = 0;
    for (&code, &km2) in &area_km2 {
        let expected = km2 * f64::from(table.density_per_km2(code));
        let found = seeds_per_code.get(&code).copied().unwrap_or(0) as f64;
        println!("class {code}: {km2:.3} km², {found} seeds, {expected:.0} expected");
        if expected < 50.0 {
            continue;
        }
        // Rank thinning makes each cell's count exact where a class covers it; what remains is the
        // blue-noise sampling of class boundaries (and slope rules, rare on this piedmont).
        let tolerance = 4.0 * expected.sqrt() + 0.03 * expected;
        assert!((found - expected).abs() <= tolerance, "class {code}: {found} seeds, {expected:.0} expected");
        compared += 1;
    }
    assert!(compared >= 3, "only {compared} classes were dense enough to compare");
    assert_eq!(seeds_per_code.get(&6).copied().unwrap_or(0), 0, "seeds on water");
}

/// Recall and precision of every preset against the oracle, for the closing figures
/// (`scripts/measure_seeds.sh` runs it): `cargo test -p terramp-data-tools --test seeds -- --ignored`.
#[test]
#[ignore = "measurement: prints recall and precision per preset"]
fn recall_and_precision_per_preset() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("seeds-presets");
    let datasets = [
        (
            "nc",
            tmp.path().join("nc"),
            [6000.0, 5000.0, 120.0, 40.0, -12.0],
            [9000.0, 8000.0, 4.0, 200.0, 0.0],
        ),
        (
            "zion",
            tmp.path().join("zion"),
            [17000.0, 20000.0, 60.0, 0.0, -5.0],
            [25000.0, 15000.0, 10.0, 270.0, -2.0],
        ),
    ];
    for (name, dir, oblique, low) in &datasets {
        for preset in ["fast", "balanced", "accurate"] {
            let dataset = if *name == "nc" { build_nc(dir) } else { build_zion(dir) };
            let mut r = renderer(dataset, Settings::preset(preset).unwrap(), 1280, 720);
            for (view, pose) in [("oblique", oblique), ("low", low)] {
                let (recall, precision, visible) = recall_precision(&mut r, &format!("{name} {view}"), *pose);
                println!(
                    "| {name} | {view} | {preset} | {visible} | {:.2} % | {:.2} % |",
                    100.0 * recall,
                    100.0 * precision
                );
            }
            drop(r);
            let _ = std::fs::remove_dir_all(dir);
        }
    }
}
