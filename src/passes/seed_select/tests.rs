//! Pass 3's inputs against an independent derivation: the twin reads the very uniforms, cells and
//! tables the GPU gets, so a mistake in building them would pass GPU == twin unseen. Here they are
//! derived again, the obvious way in f64, from the settings, the dataset's manifest and a
//! hand-made class table, and compared.

use glam::DVec3;

use super::frame::{SeedCellRef, SeedFrame, SeedInputs};
use crate::camera::Camera;
use crate::classes::ClassTable;
use crate::config::Settings;
use crate::dataset::lcc::LccCoding;
use crate::dataset::{Dataset, Pyramid};
use crate::earth::placing::EarthPlacing;
use crate::seeds::SeedTables;
use crate::synth::{SynthParams, synthesize};

/// A small synthetic dataset far from the CRS origin (large coordinates are where rounding bites),
/// in a folder of its own for test `test` (tests run in parallel).
fn dataset(test: &str) -> Dataset {
    let dir = std::env::temp_dir().join(format!("terramp-seed-inputs-{test}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let params =
        SynthParams { size: 300, seed: 3, origin_m: [512_345.5, 4_012_345.25], ..Default::default() };
    synthesize(&dir, &params, false).unwrap();
    Dataset::open(&dir).unwrap()
}

/// `value` as an integer part and a remainder, checked to rebuild it: the remainder in [0, 1) and
/// integer + remainder within f32's rounding of the remainder.
fn assert_split(what: &str, value_f64: f64, whole: i32, frac: f32) {
    assert!((0.0..1.0).contains(&frac), "{what}: remainder {frac}");
    let rebuilt = f64::from(whole) + f64::from(frac);
    assert!((rebuilt - value_f64).abs() <= 1e-6, "{what}: {whole} + {frac} is not {value_f64}");
}

/// The first page-table entry of each level, counted tile by tile (not by `Pyramid::tile_index`).
fn first_entries(pyramid: &Pyramid) -> Vec<u32> {
    (0..pyramid.levels)
        .map(|level| (0..level).map(|l| pyramid.tiles_at(l)[0] * pyramid.tiles_at(l)[1]).sum())
        .collect()
}

/// Pass 3's frame of `cells` for a camera at `camera_grid_m` (grid space), looking 30° east of
/// north and 10° down, over a 640 × 360 view.
fn seed_frame(
    settings: &Settings,
    dataset: &Dataset,
    camera_grid_m: DVec3,
    cells: &[SeedCellRef],
    active_ranks: u32,
) -> SeedFrame {
    let origin_m = dataset.manifest.origin_m;
    let camera = Camera {
        position_m: DVec3::new(origin_m[0], origin_m[1], 0.0) + camera_grid_m,
        yaw_deg: 30.0,
        pitch_deg: -10.0,
        roll_deg: 0.0,
        fov_deg: 60.0,
        near_m: 0.1,
    };
    let exact = EarthPlacing::new(None, origin_m, false).exact(camera_grid_m);
    let mut placing = EarthPlacing::new(None, origin_m, false);
    let mut placed = placing.view(&exact);
    let cell_m = settings.tlm.cell_m;
    let corner =
        |c: &SeedCellRef| DVec3::new(c.address[0] as f64 * cell_m, c.address[1] as f64 * cell_m, 0.0);
    let cells: Vec<_> = cells.iter().map(|c| (*c, placed.node(corner(c)))).collect();
    let inputs = SeedInputs {
        settings,
        dataset,
        camera: &camera,
        camera_grid_m,
        viewport_px: [640, 360],
        cells: &cells,
        active_ranks,
        nadir: exact.nadir_node(),
    };
    SeedFrame::new(&inputs).unwrap()
}

#[test]
fn uniforms_and_cells_equal_an_independent_derivation() {
    let dataset = dataset("uniforms");
    let m = &dataset.manifest;
    let settings = Settings::default();
    let camera_grid_m = DVec3::new(1234.5, 987.25, 600.0);
    let cells = [
        SeedCellRef { address: [0, 0], pattern: 3, radial_lod: 0 },
        SeedCellRef { address: [4, 3], pattern: 15, radial_lod: 2 },
        SeedCellRef { address: [-1, 7], pattern: 0, radial_lod: 3 },
    ];
    let frame = seed_frame(&settings, &dataset, camera_grid_m, &cells, 1000);
    let u = &frame.uniforms;
    let spacing_m = m.height.spacing_m;
    let cell_m = settings.tlm.cell_m;
    let lcc_texel_m = 2.0 * m.landcover.as_ref().unwrap().layer.texel_m;
    let imagery_texel_m = m.imagery.as_ref().unwrap().texel_m;

    let close = |what: &str, got: f32, want: f64| {
        assert!((f64::from(got) - want).abs() <= want.abs() * 1e-6, "{what}: {got} against {want}");
    };
    close("cell_in_samples", u.cell_in_samples, cell_m / spacing_m);
    close("cell_in_lcc_texels", u.cell_in_lcc_texels, cell_m / lcc_texel_m);
    close("cell_in_imagery_texels", u.cell_in_imagery_texels, cell_m / imagery_texel_m);
    close("inv_spacing_m", u.inv_spacing_m, 1.0 / spacing_m);
    close("camera_z_m", u.camera_z_m, camera_grid_m.z);
    close("cell_m", u.cell_m, cell_m);
    close(
        "ground_radius_texels",
        u.ground_radius_texels,
        settings.seeds.ground_colour_radius_m / imagery_texel_m,
    );
    close(
        "occlusion_tolerance_per_m",
        u.occlusion_tolerance_per_m,
        settings.seeds.occlusion_tolerance_per_km / 1000.0,
    );
    for (k, reach) in settings.draw_seeds.reach_m.iter().enumerate() {
        close("draw_reach_m", u.draw_reach_m[k], *reach);
    }
    assert_eq!((u.capacity, u.seeds_per_pattern, u.seed), (262_144, 2048, settings.tlm.seed));
    assert_eq!((u.active_ranks, u.screen_px, u.height_size), (1000, [640, 360], [300, 300]));
    assert_split("camera x", camera_grid_m.x / spacing_m, u.camera_sample[0], u.camera_sample_frac[0]);
    assert_split("camera y", camera_grid_m.y / spacing_m, u.camera_sample[1], u.camera_sample_frac[1]);
    // Page tables: each level's first entry, and its tiles along x and y.
    for (pyramid, table) in [
        (&dataset.height.pyramid, &u.height_levels[..]),
        (&dataset.imagery.as_ref().unwrap().pyramid, &u.imagery_levels[..]),
        (&dataset.landcover.as_ref().unwrap().pyramid, &u.lcc_levels[..]),
    ] {
        for (level, first) in first_entries(pyramid).into_iter().enumerate() {
            let [nx, ny] = pyramid.tiles_at(level as u32);
            assert_eq!(table[level], [first, nx, ny, 0], "level {level}");
        }
    }

    assert_eq!((frame.cells.len(), frame.cells_dropped), (3, 0));
    // Near to far: the centres of [4, 3], [0, 0] and [-1, 7] are 123 m, 1.40 km and 1.65 km away.
    for (c, reference) in frame.cells.iter().zip([&cells[1], &cells[0], &cells[2]]) {
        let corner = reference.address.map(|g| g as f64 * cell_m);
        let what = format!("cell {:?}", reference.address);
        for a in 0..2 {
            close(&format!("{what} rel_m"), c.rel_m[a], corner[a] - [camera_grid_m.x, camera_grid_m.y][a]);
            assert_split(
                &format!("{what} height"),
                corner[a] / spacing_m,
                c.height_sample[a],
                c.height_frac[a],
            );
            // Cell layers start half a height spacing south-west of grid space's origin.
            let lcc = (corner[a] + 0.5 * spacing_m) / lcc_texel_m;
            assert_split(&format!("{what} land cover"), lcc, c.lcc_texel[a], c.lcc_frac[a]);
            let imagery = (corner[a] + 0.5 * spacing_m) / imagery_texel_m;
            assert_split(&format!("{what} imagery"), imagery, c.imagery_texel[a], c.imagery_frac[a]);
        }
        assert_eq!(c.address, reference.address.map(|g| g as i32));
        assert_eq!((c.pattern, c.lcc_level), (reference.pattern, reference.radial_lod.min(2)), "{what}");
    }
}

#[test]
fn cells_are_checked_near_to_far_and_the_farthest_are_dropped() {
    let dataset = dataset("near-to-far");
    let settings = Settings::default();
    let cell_m = settings.tlm.cell_m;
    let camera_grid_m = DVec3::new(10.0 * cell_m, 0.0, 600.0);
    let ranks = settings.seeds.seeds_per_pattern;
    let kept = crate::seeds::max_cells(ranks) as i64;
    // A row of cells west and east of the camera's, in an order unlike the distance's, and cells
    // at equal distances (x = 9 and 10: their centres lie 0.5 cell either side of the camera).
    let cells: Vec<SeedCellRef> = (0..kept + 5)
        .map(|i| (i * 7919) % (kept + 5) - 4)
        .map(|x| SeedCellRef { address: [x, 0], pattern: x.rem_euclid(16) as u32, radial_lod: 0 })
        .collect();
    let frame = seed_frame(&settings, &dataset, camera_grid_m, &cells, ranks);
    assert_eq!((frame.cells.len() as i64, frame.cells_dropped), (kept, 5));
    let distance = |c: &crate::gpu::gpu_types::SeedCell| (f64::from(c.address[0]) + 0.5 - 10.0).abs();
    for pair in frame.cells.windows(2) {
        let (a, b) = (distance(&pair[0]), distance(&pair[1]));
        assert!(a < b || (a == b && pair[0].address < pair[1].address), "{:?} before {:?}", pair[0], pair[1]);
    }
    assert_eq!(frame.cells[..2].iter().map(|c| c.address[0]).collect::<Vec<_>>(), [9, 10]);
    // The dropped five are the farthest: the row's east end.
    let farthest_kept = frame.cells.iter().map(|c| c.address[0]).max().unwrap();
    assert_eq!(i64::from(farthest_kept), kept - 5, "{:?}", frame.cells.last());
}

const TABLE: &str = r#"
scheme = "hand"
nodata_code = 255

[[species]]
name = "pine"
kind = "tree"
model = "Pine_1"
height_m = [9.0, 21.0]
radius_per_height = 0.5
max_slope_deg = 45.0

[[species]]
name = "bush"
kind = "bush"
model = "Bush_1"
height_m = [1.0, 2.0]
radius_per_height = 0.8
altitude_m = [100.0, 400.0]
max_slope_deg = 50.0

[[class]]
code = 5
name = "forest"
seeds = [{ species = "pine", per_km2 = 10000 }, { species = "bush", per_km2 = 2500 }]

[[class]]
code = 7
name = "scrub"
seeds = [{ species = "bush", per_km2 = 4000 }]
"#;

#[test]
fn species_tables_equal_densities_times_cell_area() {
    let table = ClassTable::parse(TABLE, "hand-made").unwrap();
    // Codes 3 (no class in the table), 5 and 7; palette indices 1, 2 and 3.
    let coding = LccCoding::for_codes([7, 3, 5]).unwrap();
    let tables = SeedTables::new(&table, &coding, 200.0, 2048, 0.5).unwrap();
    // 200 m cells are 0.04 km²; density_scale halves every density.
    let (forest, scrub) = (&tables.classes[2], &tables.classes[3]);
    assert_eq!(tables.classes.len(), 4);
    assert_eq!(tables.classes[1].rank_limit, [0.0; 4], "code 3 grows nothing");
    assert_eq!(forest.rank_limit, [0.5 * 10_000.0 * 0.04, 0.5 * 12_500.0 * 0.04, 0.0, 0.0]);
    assert_eq!(&forest.species[..2], &[0, 1]);
    assert_eq!((scrub.rank_limit[0], scrub.species[0]), (0.5 * 4000.0 * 0.04, 1));
    assert_eq!(tables.active_ranks(), 250);
    let [pine, bush] = [&tables.species[0], &tables.species[1]];
    assert_eq!((pine.height_m, pine.radius_per_height), ([9.0, 21.0], 0.5));
    assert!((f64::from(pine.max_slope_tan_sq) - 1.0).abs() < 1e-6, "tan² 45° is 1");
    assert_eq!(bush.altitude_m, [100.0, 400.0]);
    assert_eq!((pine.kind, bush.kind), (crate::gpu::layout::KIND_TREE, crate::gpu::layout::KIND_BUSH));
}
