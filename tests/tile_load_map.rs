//! Pass 1, the Tile Load Map, on the software adapter: the ring layout covers the dataset and
//! nests exactly, the depth pyramid equals a CPU min-reduction, the readback ring never waits and
//! keeps frames in order, and the GPU pass equals its CPU twin bit for bit for many cameras, never
//! culls a cell whose ground is on screen, and picks the levels an f64 computation picks.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::DVec3;
use terramp::config::{Settings, TlmSettings};
use terramp::frame::Renderer;
use terramp::gpu::counter::Counting;
use terramp::gpu::layout::TLM_CULLED;
use terramp::gpu::readback_ring::ReadbackRing;
use terramp::passes::depth_pyramid::frame::HizMips;
use terramp::passes::depth_pyramid::gpu::DepthPyramid;
use terramp::passes::tile_load_map::frame::height_tile_ranges;
use terramp::passes::tile_load_map::layout::TlmLayout;
use terramp::reference::depth_pyramid::depth_pyramid;
use terramp::reference::tile_load_map::tile_load_map;
use terramp::seeds::cell_pattern;
use terramp::seeds::patterns::corner_colours_of;
use terramp_testkit::camera::{at_grid as camera_at, over};
use terramp_testkit::tlm::{
    assert_gpu_equals_twin, assert_levels_match_f64, assert_no_false_culls, cell_height_range, run, run_with,
    visible,
};
use terramp_testkit::{gpu, renderer, small_settings, synth_dataset};

/// Small rings, so a few-km synthetic dataset needs several of them.
fn tlm_settings(cell_m: f64, cells: u32) -> TlmSettings {
    TlmSettings { cell_m, cells, ..Settings::default().tlm }
}

/// Grid position of the highest sample of a coarse level, with its height.
fn peak(r: &Renderer) -> DVec3 {
    let pyramid = r.dataset.height.pyramid;
    let level = pyramid.levels.saturating_sub(1).min(2);
    let [nx, ny] = pyramid.size_at(level);
    let spacing = r.dataset.manifest.height.spacing_m * f64::from(1u32 << level);
    let mut best = DVec3::new(0.0, 0.0, f64::MIN);
    for y in 0..ny {
        for x in 0..nx {
            let z = r.dataset.height_sample(level, x, y).unwrap();
            if z > best.z {
                best = DVec3::new(f64::from(x) * spacing, f64::from(y) * spacing, z);
            }
        }
    }
    best
}

#[test]
fn gpu_equals_twin_and_never_culls_what_is_on_screen() {
    let dataset = synth_dataset(600, 3);
    let mut settings = small_settings(160, 96);
    settings.tlm = tlm_settings(64.0, 16);
    let mut r = renderer(&dataset, settings);
    let ranges = height_tile_ranges(&r.dataset);
    let [w, h] = r.dataset.manifest.extent_m();
    let (cx, cy) = (0.5 * w, 0.5 * h);
    let top = peak(&r);
    // Low, 2.5 km from the peak, looking at it: its flanks hide the ground behind.
    let foot = DVec3::new(top.x - 2500.0, top.y - 1200.0, 0.0);
    let foot = DVec3::new(foot.x.clamp(50.0, w - 50.0), foot.y.clamp(50.0, h - 50.0), 0.0);
    let to_peak = top - foot;
    let yaw = to_peak.x.atan2(to_peak.y).to_degrees();
    let cameras = [
        ("high oblique", over(&r, [cx, cy], 2500.0, 30.0, -35.0)),
        ("low grazing", over(&r, [cx, cy], 3.0, 200.0, -2.0)),
        ("mountain", over(&r, [foot.x, foot.y], 5.0, yaw, 2.0)),
        ("outside looking in", camera_at(&r, DVec3::new(-2000.0, -1500.0, top.z + 600.0), 50.0, -12.0)),
        ("sky", camera_at(&r, DVec3::new(cx, cy, top.z + 30.0), 80.0, 40.0)),
        ("low, up the slopes", over(&r, [cx, cy], 20.0, 80.0, 25.0)),
        ("straight down", over(&r, [cx, cy], 800.0, 0.0, -90.0)),
    ];
    for (what, camera) in &cameras {
        let run = run(&mut r, camera, &ranges);
        assert_gpu_equals_twin(&run, what);
        assert_no_false_culls(&r, &run, what);
        assert_levels_match_f64(&r, &run, camera, what);
        let culled_by_depth = {
            let clear = HizMips {
                levels: run.hiz.levels.iter().map(|l| vec![0.0; l.len()]).collect(),
                ..run.hiz.clone()
            };
            visible(&tile_load_map(&run.frame.uniforms, &run.frame.spans, &run.ranges, &clear))
                - visible(&run.gpu)
        };
        println!(
            "{what}: {} rings, {} visible of {} cells, {culled_by_depth} occluded",
            run.layout.rings,
            visible(&run.gpu),
            run.gpu.len()
        );
        match *what {
            "sky" => assert_eq!(visible(&run.gpu), 0, "{what}: above the highest peak, looking up"),
            "low, up the slopes" => {}
            _ => assert!(visible(&run.gpu) > 0, "{what}: nothing visible"),
        }
        if *what == "outside looking in" {
            assert!(run.layout.rings > 1);
        }
    }
}

/// A wall of depth 600 m away over the whole screen: cells beyond it (and the tolerance) go,
/// cells before it stay, on the GPU as in the twin.
#[test]
fn cells_behind_a_wall_are_occluded() {
    let dataset = synth_dataset(600, 3);
    let mut settings = small_settings(160, 96);
    settings.tlm = tlm_settings(64.0, 16);
    let mut r = renderer(&dataset, settings);
    let ranges = height_tile_ranges(&r.dataset);
    let [w, h] = r.dataset.manifest.extent_m();
    let camera = over(&r, [0.5 * w, 0.3 * h], 60.0, 10.0, -6.0);
    let (wall_m, tolerance_m) = (600.0, r.settings.tlm.occlusion_tolerance_m);
    let open = run(&mut r, &camera, &ranges);
    let walled = run_with(&mut r, &camera, &ranges, Some(wall_m));
    assert_gpu_equals_twin(&walled, "wall");
    let (mut kept, mut hidden) = (0, 0);
    for (i, (before, after)) in
        open.gpu.iter().zip(&walled.gpu).enumerate().filter(|(_, (b, _))| b.visibility != TLM_CULLED)
    {
        // The box's nearest view depth (w), in f64: where it is clearly before or behind the wall,
        // the pass must agree.
        let (ring, cx, cy) = walled.layout.cell_of(i);
        let (min, max) = walled.layout.cell_rect_m(ring, cx, cy);
        let z = cell_height_range(&walled, ring, cx, cy);
        let nearest_w = (0..8)
            .map(|c: u32| {
                let p = DVec3::new(
                    if c & 1 != 0 { max[0].min(walled.layout.dataset_max_m[0]) } else { min[0].max(0.0) },
                    if c & 2 != 0 { max[1].min(walled.layout.dataset_max_m[1]) } else { min[1].max(0.0) },
                    f64::from(z[usize::from(c & 4 != 0)]),
                ) - walled.camera_grid_m;
                (walled.clip * p.extend(1.0)).w
            })
            .fold(f64::INFINITY, f64::min);
        if nearest_w < wall_m + tolerance_m - 1.0 {
            assert_eq!(after, before, "cell {:?} before the wall", (ring, cx, cy));
            kept += 1;
        } else if nearest_w > wall_m + tolerance_m + 1.0 {
            assert_eq!(after.visibility, TLM_CULLED, "cell {:?} behind the wall", (ring, cx, cy));
            hidden += 1;
        }
    }
    println!("wall: {kept} kept, {hidden} hidden");
    assert!(kept > 0 && hidden > 0);
}

#[test]
fn default_settings_one_ring_over_a_small_dataset() {
    let dataset = synth_dataset(300, 7);
    let mut r = renderer(&dataset, small_settings(160, 96));
    let [w, h] = r.dataset.manifest.extent_m();
    let camera = over(&r, [0.3 * w, 0.4 * h], 150.0, 60.0, -15.0);
    let ranges = height_tile_ranges(&r.dataset);
    let run = run(&mut r, &camera, &ranges);
    assert_eq!(run.layout.rings, 1, "a 3 km dataset fits in ring 0 (16 km)");
    assert_gpu_equals_twin(&run, "defaults");
    assert_no_false_culls(&r, &run, "defaults");
    assert_levels_match_f64(&r, &run, &camera, "defaults");
}

#[test]
fn rings_cover_the_dataset_and_nest_exactly() {
    let settings = tlm_settings(50.0, 10);
    let dataset = ([0.0, 0.0], [4990.0, 3000.0]);
    for camera in [[2500.0, 1500.0], [10.0, 2999.0], [-3000.0, 8000.0], [4990.0, -0.5], [1.0e7, -3.0e6]] {
        let layout = TlmLayout::new(&settings, dataset, camera);
        let last = layout.rings - 1;
        let (o, c) = (layout.ring_origin_m(last), layout.ring_cell_m(last));
        let covers = (0..2).all(|a| o[a] <= dataset.0[a] && o[a] + 10.0 * c >= dataset.1[a]);
        assert!(covers || layout.rings == settings.max_rings, "{camera:?}");
        for ring in 0..layout.rings {
            assert!(layout.origin_cell[ring as usize].iter().all(|g| g % 2 == 0));
            // The camera is within a cell of the ring's centre.
            let centre = (0..2).map(|a| layout.ring_origin_m(ring)[a] + 5.0 * layout.ring_cell_m(ring));
            assert!(centre.zip(camera).all(|(m, v)| (m - v).abs() <= layout.ring_cell_m(ring)), "{camera:?}");
            if ring == 0 {
                continue;
            }
            // Ring k − 1's square is exactly the union of ring k's covered cells.
            let (inner_min, inner_c) = (layout.ring_origin_m(ring - 1), layout.ring_cell_m(ring - 1));
            let inner_max = inner_min.map(|v| v + 10.0 * inner_c);
            for cy in 0..10 {
                for cx in 0..10 {
                    let (min, max) = layout.cell_rect_m(ring, cx, cy);
                    let inside = (0..2).all(|a| min[a] >= inner_min[a] && max[a] <= inner_max[a]);
                    let outside = (0..2).any(|a| min[a] >= inner_max[a] || max[a] <= inner_min[a]);
                    assert!(inside || outside, "cell straddles the inner ring");
                    assert_eq!(layout.is_covered(ring, cx, cy), inside);
                }
            }
        }
        // Every point of the dataset lies in exactly one uncovered cell (when the rings reach it).
        for i in 0..40 {
            let p = [
                dataset.1[0] * f64::from(i) / 39.0 * 0.999 + 0.7,
                dataset.1[1] * f64::from(i * 7 % 40) / 40.0,
            ];
            let Some((ring, cx, cy)) = layout.locate(p) else { continue };
            assert!(!layout.is_covered(ring, cx, cy));
            let (min, max) = layout.cell_rect_m(ring, cx, cy);
            assert!((0..2).all(|a| min[a] <= p[a] && p[a] < max[a]));
        }
    }
}

#[test]
fn snapping_moves_rings_two_cells_at_a_time() {
    let settings = tlm_settings(64.0, 16);
    let dataset = ([0.0, 0.0], [6000.0, 6000.0]);
    let mut previous = TlmLayout::new(&settings, dataset, [3000.0, 3000.0]);
    let mut unchanged = 0;
    for step in 1..400 {
        // Less than a cell each step, diagonally.
        let camera = [3000.0 + 13.7 * f64::from(step), 3000.0 + 5.3 * f64::from(step)];
        let layout = TlmLayout::new(&settings, dataset, camera);
        for (now, before) in layout.origin_cell.iter().zip(&previous.origin_cell) {
            for a in 0..2 {
                assert!([0, 2].contains(&(now[a] - before[a])), "{step}: {now:?} after {before:?}");
            }
        }
        unchanged += usize::from(layout.origin_cell[0] == previous.origin_cell[0]);
        // A global address names the same square of ground whatever the ring's position.
        let (min, _) = layout.cell_rect_m(1, 3, 4);
        let g = layout.global_address(1, 3, 4);
        assert_eq!(min, [g.x as f64 * 128.0, g.y as f64 * 128.0]);
        previous = layout;
    }
    // Ring 0 re-snaps when the camera crosses a line every 2 cells (128 m): about one step in 9
    // along x (13.7 m steps) and one in 24 along y.
    assert!(unchanged > 300, "ring 0 must stay put while the camera moves within its snap interval");
}

#[test]
fn tlm_settings_are_checked_and_named() {
    let with = |text: &str| Settings::from_layers(&[("test.toml".into(), text.into())]);
    let defaults = Settings::default().tlm;
    assert_eq!((defaults.cell_m, defaults.cells, defaults.max_rings, defaults.patterns), (256.0, 64, 12, 16));
    assert_eq!(defaults.radial_bands_m, [700.0, 1400.0, 3000.0]);
    for (text, key) in [
        ("[tlm]\ncells = 63\n", "tlm.cells"),
        ("[tlm]\nmax_rings = 17\n", "tlm.max_rings"),
        ("[tlm]\npatterns = 256\n", "tlm.patterns"),
        ("[tlm]\npatterns = 20\n", "C⁴ for C corner colours: 1, 16 or 81"),
        ("[tlm]\nradial_bands_m = [700.0, 300.0, 3000.0]\n", "tlm.radial_bands_m"),
        ("[tlm]\ncell_m = 0\n", "tlm.cell_m"),
    ] {
        let error = with(text).unwrap_err().to_string();
        assert!(error.contains(key), "{error}");
    }
    assert_eq!(with("[tlm]\ncells = 32\n").unwrap().tlm.cells, 32);
    for (patterns, colours) in [(1, 1), (16, 2), (81, 3)] {
        assert_eq!(with(&format!("[tlm]\npatterns = {patterns}\n")).unwrap().tlm.corner_colours(), colours);
    }
}

#[test]
fn cell_patterns_are_deterministic_spread_over_every_pattern_and_agree_with_their_neighbours() {
    for colours in [2u32, 3] {
        let patterns = colours.pow(4);
        let mut counts = vec![0u32; patterns as usize];
        for y in -64i32..64 {
            for x in -64i32..64 {
                let p = cell_pattern([x, y], 1, colours);
                assert_eq!(p, cell_pattern([x, y], 1, colours));
                counts[p as usize] += 1;
                // The shared corners of the east and north neighbours have the same colours.
                let [_, c10, c01, c11] = corner_colours_of(p, colours);
                let [e00, _, e01, _] = corner_colours_of(cell_pattern([x + 1, y], 1, colours), colours);
                let [n00, n10, ..] = corner_colours_of(cell_pattern([x, y + 1], 1, colours), colours);
                assert_eq!((c10, c11, c01, c11), (e00, e01, n00, n10), "cell {x}, {y}");
            }
        }
        let mean = 128.0 * 128.0 / f64::from(patterns);
        // Within a quarter of the mean: 8 standard deviations of a fair hash's count at 16 patterns
        // (1,024 cells each), 3.5 at 81 (202 each); a pattern never chosen, or twice as often, fails.
        assert!(counts.iter().all(|&c| (f64::from(c) - mean).abs() < 0.25 * mean), "{counts:?}");
        // Another germ, another assignment.
        let moved = (0..256)
            .filter(|&x| cell_pattern([x, 7], 1, colours) != cell_pattern([x, 7], 2, colours))
            .count();
        assert!(moved > 200);
    }
    // Addresses wrap like the shader's u32 arithmetic.
    assert!(cell_pattern([i32::MAX, i32::MIN], 1, 3) < 81);
}

#[test]
fn depth_pyramid_equals_a_cpu_min_reduction_at_odd_sizes() {
    let dataset = synth_dataset(300, 7);
    for (w, h) in [(157, 93), (33, 7), (1, 5)] {
        let mut r = renderer(&dataset, small_settings(w, h));
        let [ew, eh] = r.dataset.manifest.extent_m();
        let camera = over(&r, [0.5 * ew, 0.5 * eh], 120.0, 20.0, -8.0);
        r.render(&camera).unwrap();
        let hiz = DepthPyramid::new(&r.gpu.device, w, h);
        let mut encoder = r.gpu.device.create_command_encoder(&Default::default());
        hiz.encode(&mut encoder, &r.depth_texture().create_view(&Default::default()), Counting::OFF);
        r.gpu.queue.submit([encoder.finish()]);
        let gpu_mips = hiz.read_back(&r.gpu).unwrap();
        let cpu_mips = depth_pyramid(&r.read_depth().unwrap(), w, h);
        assert_eq!(gpu_mips.sizes, cpu_mips.sizes);
        assert_eq!(gpu_mips.sizes.last(), Some(&[1, 1]));
        assert!(gpu_mips == cpu_mips, "{w}×{h}: GPU and CPU pyramids differ");
        // Conservative: the top texel is the farthest depth of the whole frame.
        let depth = r.read_depth().unwrap();
        assert_eq!(gpu_mips.levels.last().unwrap()[0], depth.iter().copied().fold(f32::INFINITY, f32::min));
    }
}

#[test]
fn readback_ring_never_waits_and_delivers_frames_in_order() {
    let gpu = gpu();
    let source = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("source"),
        size: 1024,
        usage: wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let mut ring = ReadbackRing::new(&gpu.device, "test", 1024, 3);
    let mut taken = Vec::new();
    // Five frames without reading: three fit, two are skipped.
    for frame in 0..5u64 {
        gpu.queue.write_buffer(&source, 0, bytemuck::cast_slice(&[frame as u32; 256]));
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let copied = ring.encode_copy(&mut encoder, &source, 1024, frame);
        assert_eq!(copied, frame < 3);
        gpu.queue.submit([encoder.finish()]);
        ring.submitted();
    }
    assert_eq!((ring.skipped(), ring.in_flight()), (2, 3));
    // Then a frame loop that reads what has arrived, never waiting.
    for frame in 5..40u64 {
        gpu.queue.write_buffer(&source, 0, bytemuck::cast_slice(&[frame as u32; 256]));
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        ring.encode_copy(&mut encoder, &source, 1024, frame);
        gpu.queue.submit([encoder.finish()]);
        ring.submitted();
        while let Some(readback) = ring.try_take(&gpu.device).unwrap() {
            taken.push(readback);
        }
    }
    gpu.wait().unwrap();
    while let Some(readback) = ring.try_take(&gpu.device).unwrap() {
        taken.push(readback);
    }
    assert_eq!(ring.in_flight(), 0);
    assert_eq!(taken.len() as u64 + ring.skipped(), 40);
    assert!(taken.windows(2).all(|w| w[0].tag < w[1].tag), "frames out of order");
    for readback in &taken {
        assert!(
            readback.cast::<u32>().iter().all(|&v| u64::from(v) == readback.tag),
            "frame {}",
            readback.tag
        );
    }
}
