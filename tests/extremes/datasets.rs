//! The dataset's own extremes: cameras outside every corner and edge looking in (beyond the one
//! corner `tests/render.rs` checks), datasets of one sample, of one cell and of exactly one height
//! tile, and class tables that grow nothing (no species at all; species, but none for any class).

use glam::DVec3;
use terramp::camera::Camera;
use terramp::synth::SynthParams;

use terramp_testkit::audit::{Dem, Tolerance, audit, camera_at};
use terramp_testkit::small_settings;

#[test]
fn cameras_outside_every_corner_and_edge_look_in() {
    let dataset = terramp_testkit::synth_dataset(256, 7);
    // Sixteen views: a smaller frame keeps them quick.
    let mut r = terramp_testkit::renderer(&dataset, small_settings(192, 108));
    let dem = Dem::load(&r.dataset);
    let span = dem.span_m();
    let centre = [0.5 * span[0], 0.5 * span[1]];
    let o = r.dataset.manifest.origin_m;
    for (dx, dy) in [(-1, -1), (0, -1), (1, -1), (1, 0), (1, 1), (0, 1), (-1, 1), (-1, 0)] {
        // Where the dataset's edge or corner is, and a unit step away from it.
        let edge = [centre[0] + 0.5 * span[0] * f64::from(dx), centre[1] + 0.5 * span[1] * f64::from(dy)];
        let out = DVec3::new(f64::from(dx), f64::from(dy), 0.0).normalize();
        let yaw_in = (-out.x).atan2(-out.y).to_degrees();
        let edge_m = dem.mesh_height_m(edge[0], edge[1]);
        // Low: 2 m above the edge's height, 50 m out, level; high: 400 m out, 300 m above the
        // highest ground, looking down at the dataset.
        for (away_m, z_m, pitch) in [(50.0, edge_m + 2.0, 0.0), (400.0, dem.max_m + 300.0, -25.0)] {
            let camera = Camera {
                position_m: DVec3::new(o[0] + edge[0] + out.x * away_m, o[1] + edge[1] + out.y * away_m, z_m),
                yaw_deg: yaw_in,
                pitch_deg: pitch,
                roll_deg: 0.0,
                fov_deg: 60.0,
                near_m: 0.1,
            };
            let what = format!("({dx}, {dy}) {away_m} m out, {z_m:.0} m high");
            let (report, _) = r.render_resolved(&camera).unwrap();
            assert_eq!(report.camera_lifted_m, 0.0, "{what}: outside the dataset there is no ground");
            let a = audit(&r, &camera, &dem, Tolerance::flat(0.05, 20.0), 3);
            println!("{what}: {a:?}");
            a.assert_sound(&what);
            assert!(a.expect_ground > 20 && a.expect_sky > 20, "{what}: {a:?}");
        }
    }
}

#[test]
fn datasets_of_one_sample_one_cell_and_one_tile_render() {
    for size in [1, 2, 257] {
        let dataset =
            terramp_testkit::synth_dataset_with(&SynthParams { size, seed: 7, ..Default::default() });
        let mut r = terramp_testkit::renderer(&dataset, small_settings(160, 90));
        assert_eq!(r.dataset.height.pyramid.tiles_at(0), [1, 1], "size {size}");
        let dem = Dem::load(&r.dataset);
        let span = dem.span_m();
        let views = [
            ("straight down", camera_at(&r, &dem, [0.5 * span[0], 0.5 * span[1]], 0.8 * span[0], 0.0, -90.0)),
            (
                "from a corner",
                camera_at(&r, &dem, [0.1 * span[0], 0.1 * span[1]], 0.3 * span[0], 45.0, -30.0),
            ),
        ];
        for (what, camera) in views {
            let what = format!("size {size}, {what}");
            let (report, _) = r.render_resolved(&camera).unwrap();
            assert!(report.nodes_drawn > 0 && report.nodes_dropped == 0, "{what}: {report:?}");
            let a = audit(&r, &camera, &dem, Tolerance::flat(0.05, 0.1 * span[0]), 4);
            println!("{what}: {a:?}");
            a.assert_sound(&what);
            assert!(a.expect_ground > 10, "{what}: {a:?}");
        }
    }
}

/// Renders the synthetic dataset with the class table `text` and checks that nothing grows.
fn grows_nothing(name: &str, text: &str) {
    let path = std::env::temp_dir().join(format!("terramp-extremes-{name}-{}.toml", std::process::id()));
    std::fs::write(&path, text).unwrap();
    let dataset = terramp_testkit::synth_dataset(256, 7);
    let mut settings = small_settings(320, 180);
    settings.seeds.class_table = path.to_str().unwrap().to_owned();
    let mut r = terramp_testkit::renderer(&dataset, settings);
    let dem = Dem::load(&r.dataset);
    let span = dem.span_m();
    let camera = camera_at(&r, &dem, [0.4 * span[0], 0.4 * span[1]], 30.0, 60.0, -15.0);
    let (report, _) = r.render_resolved(&camera).unwrap();
    let a = audit(&r, &camera, &dem, Tolerance::flat(0.05, 20.0), 4);
    println!("{name}: {report:?}\n{a:?}");
    a.assert_sound(name);
    assert!(report.seed_cells > 0, "{name}: no cell to grow seeds in: {report:?}");
    let counters = a.counters.unwrap();
    assert_eq!((a.seeds, counters.selected, counters.overflow), (0, 0, 0), "{name}: {counters:?}");
    assert_eq!(r.read_compacted().unwrap().unwrap().drawn(), 0, "{name}");
    assert_eq!(r.seed_twin().unwrap().unwrap().1, counters, "{name}");
    let _ = std::fs::remove_file(&path);
}

#[test]
fn class_tables_that_grow_nothing_give_zero_seeds() {
    grows_nothing("no-species", "scheme = \"nc\"\nnodata_code = 255\nspecies = []\nclass = []\n");
    let classes: String =
        (1..=7).map(|code| format!("[[class]]\ncode = {code}\nname = \"c{code}\"\nseeds = []\n")).collect();
    let species = "[[species]]\nname = \"bush\"\nkind = \"bush\"\nmodel = \"Bush_1\"\nheight_m = [0.8, 1.6]\n\
        radius_per_height = 0.8\nmax_slope_deg = 60.0\n";
    grows_nothing("no-seeds", &format!("scheme = \"nc\"\nnodata_code = 255\n{species}{classes}"));
}
