//! The Tile Load Map on real data: `nc/` and `rainier/` are built into a temporary folder, rendered
//! from several cameras on the software adapter, and the GPU pass must equal its CPU twin in every
//! field of every cell (and keep some cells, and cull the sky).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::passes::tile_load_map::frame::height_tile_ranges;
use terramp_testkit::camera::posed;
use terramp_testkit::tlm::{assert_gpu_equals_twin, run, visible};
use terramp_testkit::{TempDir, shared_data};

use support::build;

fn check(dataset: Dataset, cameras: &[(&str, [f64; 5])]) {
    let mut settings = Settings::default();
    settings.render.width = 160;
    settings.render.height = 96;
    let gpu = terramp_testkit::gpu();
    let mut r = Renderer::new(gpu, dataset, settings).unwrap();
    let ranges = height_tile_ranges(&r.dataset);
    for &(what, pose) in cameras {
        // Positions are grid metres; heights above the ground there (clamped into the dataset).
        let camera = posed(&r, pose);
        let run = run(&mut r, &camera, &ranges);
        assert_gpu_equals_twin(&run, what);
        let visible = visible(&run.gpu);
        println!("{what}: {} rings, {visible} of {} cells visible", run.layout.rings, run.gpu.len());
        if what.contains("sky") {
            assert_eq!(visible, 0, "{what}");
        } else {
            assert!(visible > 0, "{what}: nothing visible");
        }
    }
}

#[test]
fn nc_and_rainier_gpu_equals_twin() {
    let Some(data) = shared_data() else { return };
    let tmp = TempDir::new("tlm");
    let nc = data.join("nc");
    let arg = |f: &str| nc.join(f).to_str().unwrap().to_owned();
    let (nc, _) = build(
        &tmp.path().join("nc"),
        &["--dem", &arg("elev_ned_30m.tif"), "--imagery", &arg("landsat_multiband.tif"), "--bands", "3,2,1"],
    );
    check(
        nc,
        &[
            ("nc high oblique", [7000.0, 6000.0, 2500.0, 40.0, -30.0]),
            ("nc low grazing", [3000.0, 2000.0, 2.0, 70.0, -1.0]),
            ("nc outside looking in", [-3000.0, -2000.0, 800.0, 45.0, -10.0]),
            ("nc sky", [7000.0, 6000.0, 300.0, 0.0, 45.0]),
        ],
    );
    let dem = data.join("rainier/mt_rainier_90m.tif");
    let (rainier, _) = build(&tmp.path().join("rainier"), &["--dem", dem.to_str().unwrap()]);
    let [w, h] = rainier.manifest.extent_m();
    // The summit sits near the middle of the tile; look at it from the south-west, low.
    check(
        rainier,
        &[
            ("rainier high oblique", [0.5 * w, 0.5 * h, 6000.0, 0.0, -35.0]),
            ("rainier at the mountain", [0.5 * w - 15000.0, 0.5 * h - 15000.0, 10.0, 45.0, 3.0]),
            ("rainier outside looking in", [-20000.0, 0.5 * h, 3000.0, 90.0, -5.0]),
            ("rainier sky", [0.5 * w, 0.5 * h, 5000.0, 200.0, 30.0]),
        ],
    );
}
