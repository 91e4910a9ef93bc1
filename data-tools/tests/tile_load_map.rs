//! The Tile Load Map on real data: `nc/` and `rainier/` are built into a temporary folder, rendered
//! from several cameras on the software adapter, and the GPU pass must equal its CPU twin in every
//! field of every cell (and keep some cells, and cull the sky).

mod support;

use glam::DVec3;
use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::gpu::gpu_types::TlmCell;
use terramp::gpu::{AdapterChoice, Gpu};
use terramp::passes::depth_pyramid::gpu::DepthPyramid;
use terramp::passes::terrain::select::Lods;
use terramp::passes::tile_load_map::frame::{TlmImagery, TlmInputs, height_tile_ranges};
use terramp::passes::tile_load_map::gpu::TileLoadMapPass;
use terramp::passes::tile_load_map::layout::TlmLayout;
use terramp::reference::tile_load_map::tile_load_map;

use support::{TempDir, build, shared_data};

/// Renders `camera`, runs the depth pyramid and the TLM on its depth and the twin on the same
/// inputs; returns (GPU cells, twin cells, rings).
fn gpu_and_twin(r: &mut Renderer, camera: &Camera) -> (Vec<TlmCell>, Vec<TlmCell>, u32) {
    r.render(camera).unwrap();
    let s = r.settings.clone();
    let (w, h) = (s.render.width, s.render.height);
    let device = &r.gpu.device;
    let hiz = DepthPyramid::new(device, w, h);
    let pass = TileLoadMapPass::new(device, &s);
    let ranges = height_tile_ranges(&r.dataset);
    let bindings = pass.bind_group(device, &ranges, &hiz);
    let m = &r.dataset.manifest;
    let camera_grid_m = camera.position_m - DVec3::new(m.origin_m[0], m.origin_m[1], 0.0);
    let lods = Lods::for_view(&r.dataset, &s.terrain, camera, h);
    let rect = TlmLayout::dataset_rect_m(&lods.pyramid, lods.spacing_m);
    let layout = TlmLayout::new(&s.tlm, rect, [camera_grid_m.x, camera_grid_m.y]);
    let imagery = TlmImagery::of(&r.dataset, &s.imagery);
    let inputs = TlmInputs {
        settings: &s.tlm,
        layout: &layout,
        camera,
        camera_grid_m,
        viewport_px: [w, h],
        lods: &lods,
        imagery,
        hiz_mips: hiz.mips(),
    };
    let frame = pass.prepare(&r.gpu.queue, &inputs).unwrap();
    let mut encoder = device.create_command_encoder(&Default::default());
    hiz.encode(&mut encoder, &r.depth_texture().create_view(&Default::default()));
    pass.encode(&mut encoder, &bindings, &frame);
    r.gpu.queue.submit([encoder.finish()]);
    let gpu = pass.read_back(&r.gpu, &frame).unwrap();
    let twin = tile_load_map(&frame.uniforms, &frame.spans, &ranges, &hiz.read_back(&r.gpu).unwrap());
    (gpu, twin, layout.rings)
}

fn check(dataset: Dataset, cameras: &[(&str, [f64; 5])]) {
    let mut settings = Settings::default();
    settings.render.width = 160;
    settings.render.height = 96;
    let gpu = Gpu::new(AdapterChoice::Auto).expect("a GPU adapter (install mesa-vulkan-drivers)");
    let mut r = Renderer::new(gpu, dataset, settings).unwrap();
    for &(what, pose) in cameras {
        // Positions are grid metres; heights above the ground there (clamped into the dataset).
        let camera = support::camera_over(&r, pose);
        let (gpu, twin, rings) = gpu_and_twin(&mut r, &camera);
        let differ: Vec<usize> = (0..gpu.len()).filter(|&i| gpu[i] != twin[i]).collect();
        let shown: Vec<_> = differ.iter().take(5).map(|&i| (i, gpu[i], twin[i])).collect();
        assert!(differ.is_empty(), "{what}: {} cells differ (index, GPU, twin): {shown:?}", differ.len());
        let visible = gpu.iter().filter(|c| c.visibility != 0).count();
        println!("{what}: {rings} rings, {visible} of {} cells visible", gpu.len());
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
