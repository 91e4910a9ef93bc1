//! Grazing views: the view direction at 89.9° from the ground's normal (exactly, over the flat
//! water of a synthetic lake; against the horizontal elsewhere) and exactly horizontal. Nothing
//! in any buffer may become non-finite (depth, colour, Tile Load Map, seed records), the ground
//! may have no hole where rays through the DEM meet it, and no seed may stand above the mesh
//! (a gap under it) or off its ground.

use terramp::synth::SynthParams;

use terramp_testkit::audit::{Dem, Tolerance, audit, camera_at};
use terramp_testkit::small_settings;

/// The longest run of flat water samples along x (start sample, length in samples).
fn longest_lake_run(dem: &Dem, water_m: f64) -> ([u32; 2], u32) {
    let mut best = ([0, 0], 0);
    for j in 0..dem.size[1] {
        let mut run = 0;
        for i in 0..dem.size[0] {
            run = if dem.sample_m(i, j) == water_m { run + 1 } else { 0 };
            if run > best.1 {
                best = ([i + 1 - run, j], run);
            }
        }
    }
    best
}

#[test]
fn grazing_and_horizontal_views_keep_every_buffer_finite_and_the_ground_whole() {
    let params = SynthParams { size: 256, seed: 7, ..Default::default() };
    let dataset = terramp_testkit::synth_dataset_with(&params);
    let mut r = terramp_testkit::renderer(&dataset, small_settings(320, 180));
    let dem = Dem::load(&r.dataset);
    let span = dem.span_m();
    let ([i, j], run) = longest_lake_run(&dem, params.water_level_m);
    let run_m = f64::from(run) * dem.spacing_m;
    println!("lake run of {run_m} m from sample ({i}, {j})");
    assert!(run_m >= 200.0, "no lake to graze (longest flat run {run_m} m)");
    // Low enough that the ray at 0.1° meets the water half-way along the run.
    let lake = [f64::from(i) * dem.spacing_m + 1.0, f64::from(j) * dem.spacing_m];
    let above_lake_m = 0.5 * run_m * 0.1f64.to_radians().tan();
    let views = [
        ("89.9° on the lake", camera_at(&r, &dem, lake, above_lake_m, 90.0, -0.1)),
        ("horizontal on the lake", camera_at(&r, &dem, lake, above_lake_m, 90.0, 0.0)),
        ("0.1° down, 2 m up", camera_at(&r, &dem, [0.4 * span[0], 0.3 * span[1]], 2.0, 20.0, -0.1)),
        ("0.1° down, 2 m up, west", camera_at(&r, &dem, [0.7 * span[0], 0.6 * span[1]], 2.0, 265.0, -0.1)),
        ("horizontal, 2 m up", camera_at(&r, &dem, [0.5 * span[0], 0.5 * span[1]], 2.0, 135.0, 0.0)),
        ("horizontal, 30 m up", camera_at(&r, &dem, [0.2 * span[0], 0.8 * span[1]], 30.0, 160.0, 0.0)),
    ];
    for (what, camera) in views {
        r.render_resolved(&camera).unwrap();
        let a = audit(&r, &camera, &dem, Tolerance::flat(0.05, 20.0), 4);
        println!("{what}: {a:?}");
        a.assert_sound(what);
        assert!(a.expect_ground > 50 && a.expect_sky > 50, "{what}: {a:?}");
        assert!(a.tlm_visible > 0, "{what}: the TLM sees nothing ({a:?})");
        // The seed's base is sunk `sink_fraction` of its height into the drawn ground: never above it.
        assert!(
            a.worst_seed_gap_m <= 0.0,
            "{what}: a seed's base is {} m above the mesh",
            a.worst_seed_gap_m
        );
    }
}
