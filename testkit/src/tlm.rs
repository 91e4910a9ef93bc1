//! The Tile Load Map's GPU-vs-twin harness: render a view, run the depth pyramid and pass 1 on
//! its depth (or on a wall at a chosen distance), read the cells back and run the CPU twin on the
//! same inputs; and the checks every TLM test makes of such a run: GPU == twin in every field of
//! every cell, no ground pixel in a culled cell, and levels equal to an f64 computation.

use glam::{DMat4, DVec3, DVec4};
use terramp::camera::Camera;
use terramp::earth::placing::ExactPlacing;
use terramp::frame::Renderer;
use terramp::gpu::counter::Counting;
use terramp::gpu::gpu_types::TlmCell;
use terramp::gpu::layout::{
    LevelRange, RADIAL_INACTIVE, TLM_CULLED, TLM_FIRST_PATTERN, TLM_SPAN_INSIDE, TileSpan, tlm_visibility,
};
use terramp::passes::depth_pyramid::frame::HizMips;
use terramp::passes::depth_pyramid::gpu::DepthPyramid;
use terramp::passes::terrain::select::Lods;
use terramp::passes::tile_load_map::frame::{TlmFrame, TlmImagery, TlmInputs};
use terramp::passes::tile_load_map::gpu::TileLoadMapPass;
use terramp::passes::tile_load_map::layout::TlmLayout;
use terramp::reference::tile_load_map::{bent_box, tile_load_map};
use terramp::seeds::cell_pattern;

/// One view's Tile Load Map, from the GPU and from the twin, with what both were computed from.
pub struct Run {
    pub layout: TlmLayout,
    pub frame: TlmFrame,
    pub lods: Lods,
    pub ranges: Vec<[f32; 2]>,
    pub hiz: HizMips,
    pub gpu: Vec<TlmCell>,
    pub twin: Vec<TlmCell>,
    pub clip: DMat4,
    pub camera_grid_m: DVec3,
    /// The renderer's placing from this camera: what takes a drawn point back to the grid.
    pub placing: ExactPlacing,
}

/// Renders `camera`, then runs the depth pyramid and the TLM on its depth, and the twin.
pub fn run(r: &mut Renderer, camera: &Camera, ranges: &[[f32; 2]]) -> Run {
    run_with(r, camera, ranges, None)
}

/// As `run`, but with `wall_m`, on a depth target cleared to a wall that far away instead.
pub fn run_with(r: &mut Renderer, camera: &Camera, ranges: &[[f32; 2]], wall_m: Option<f64>) -> Run {
    r.render(camera).unwrap();
    let s = r.settings.clone();
    let (w, h) = (s.render.width, s.render.height);
    let device = &r.gpu.device;
    let hiz = DepthPyramid::new(device, w, h);
    let pass = TileLoadMapPass::new(device, &s);
    let ranges = ranges.to_vec();
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
        earth: r.tlm_earth(camera),
    };
    let frame = pass.prepare(&r.gpu.queue, &inputs).unwrap();
    let mut encoder = device.create_command_encoder(&Default::default());
    let wall = wall_m.map(|distance_m| {
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("wall"),
            size: wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: wgpu::TextureFormat::Depth32Float,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
            view_formats: &[],
        });
        let view = texture.create_view(&Default::default());
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("wall"),
            color_attachments: &[],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &view,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear((camera.near_m / distance_m) as f32),
                    store: wgpu::StoreOp::Store,
                }),
                stencil_ops: None,
            }),
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        view
    });
    let depth = wall.unwrap_or_else(|| r.depth_texture().create_view(&Default::default()));
    hiz.encode(&mut encoder, &depth, Counting::OFF);
    pass.encode(&mut encoder, &bindings, &frame, Counting::OFF);
    r.gpu.queue.submit([encoder.finish()]);
    let gpu_cells = pass.read_back(&r.gpu, &frame).unwrap();
    let mips = hiz.read_back(&r.gpu).unwrap();
    let twin = tile_load_map(&frame.uniforms, &frame.spans, &ranges, &mips);
    let clip = camera.clip_from_view(w, h).unwrap() * camera.view_from_world();
    let placing = r.exact_placing(camera);
    Run { layout, frame, lods, ranges, hiz: mips, gpu: gpu_cells, twin, clip, camera_grid_m, placing }
}

pub fn assert_gpu_equals_twin(run: &Run, what: &str) {
    assert_eq!(run.gpu.len(), run.layout.cell_count(), "{what}");
    let differ: Vec<_> = (0..run.gpu.len()).filter(|&i| run.gpu[i] != run.twin[i]).collect();
    let show: Vec<_> =
        differ.iter().take(5).map(|&i| (run.layout.cell_of(i), run.gpu[i], run.twin[i])).collect();
    assert!(
        differ.is_empty(),
        "{what}: {} cells differ, e.g. (ring, x, y), GPU, twin: {show:?}",
        differ.len()
    );
}

pub fn visible(cells: &[TlmCell]) -> usize {
    cells.iter().filter(|c| c.visibility != TLM_CULLED).count()
}

/// Every pixel showing ground lies in a cell the TLM keeps (no false culls), checked for points
/// well inside a cell and within the dataset's height range (skirts hang below it).
pub fn assert_no_false_culls(r: &Renderer, run: &Run, what: &str) {
    let (w, h) = (r.settings.render.width, r.settings.render.height);
    let depth = r.read_depth().unwrap();
    let inverse = run.clip.inverse();
    let [low, high] = [r.dataset.manifest.height.min_m, r.dataset.manifest.height.max_m].map(f64::from);
    let mut checked = 0;
    for (i, &d) in depth.iter().enumerate().filter(|(_, d)| **d > 0.0) {
        let (px, py) = ((i as u32 % w) as f64 + 0.5, (i as u32 / w) as f64 + 0.5);
        let ndc = DVec4::new(px / f64::from(w) * 2.0 - 1.0, 1.0 - py / f64::from(h) * 2.0, f64::from(d), 1.0);
        let rel = inverse * ndc;
        let p = run.placing.grid_m(rel.truncate() / rel.w);
        if p.z < low - 1.0 || p.z > high + 1.0 {
            continue;
        }
        let Some((ring, cx, cy)) = run.layout.locate([p.x, p.y]) else { continue };
        let (min, max) = run.layout.cell_rect_m(ring, cx, cy);
        let margin = (0..2).map(|a| (p[a] - min[a]).min(max[a] - p[a])).fold(f64::INFINITY, f64::min);
        if margin < 1.0 {
            continue;
        }
        let cell = run.gpu[run.layout.index(ring, cx, cy)];
        assert!(
            cell.visibility != TLM_CULLED,
            "{what}: pixel ({px}, {py}) shows ground of culled cell {:?}",
            (ring, cx, cy)
        );
        checked += 1;
    }
    assert!(checked > 0 || depth.iter().all(|&d| d == 0.0), "{what}: no pixel checked");
}

/// The union of the ranges of the height tiles the cell's column and row overlap.
pub fn cell_height_range(run: &Run, ring: u32, cx: u32, cy: u32) -> [f32; 2] {
    let u = &run.frame.uniforms;
    let (sx, sy) = (
        run.frame.spans[((ring * 2) * u.cells + cx) as usize],
        run.frame.spans[((ring * 2 + 1) * u.cells + cy) as usize],
    );
    let level = u.height_levels[u.rings_info[ring as usize].height_level as usize];
    let mut range = [f32::MAX, f32::MIN];
    let (xs, ys) = (TileSpan::unpack(sx.height_tiles), TileSpan::unpack(sy.height_tiles));
    for ty in ys.first..=ys.last {
        for tx in xs.first..=xs.last {
            let r = run.ranges[(level[0] + ty * level[1] + tx) as usize];
            range = [range[0].min(r[0]), range[1].max(r[1])];
        }
    }
    range
}

/// Radial, imagery and terrain levels of visible cells equal an f64 computation, away from the
/// thresholds (where f32 and f64 may round to either side).
pub fn assert_levels_match_f64(r: &Renderer, run: &Run, camera: &Camera, what: &str) {
    let s = &r.settings;
    let mpp = camera.metres_per_pixel(1.0, s.render.height);
    let imagery = r.dataset.manifest.imagery.as_ref();
    let near = |d: f64, t: f64| (d - t).abs() < 1e-3 * t.max(1.0);
    let mut checked = 0;
    for (i, cell) in run.gpu.iter().enumerate().filter(|(_, c)| c.visibility != TLM_CULLED) {
        let (ring, cx, cy) = run.layout.cell_of(i);
        let (min, max) = run.layout.cell_rect_m(ring, cx, cy);
        let height_m = cell_height_range(run, ring, cx, cy);
        let lo =
            DVec3::new(min[0].max(run.layout.dataset_min_m[0]), min[1].max(run.layout.dataset_min_m[1]), 0.0);
        let hi =
            DVec3::new(max[0].min(run.layout.dataset_max_m[0]), max[1].min(run.layout.dataset_max_m[1]), 0.0);
        let lo = DVec3::new(lo.x, lo.y, f64::from(height_m[0])) - run.camera_grid_m;
        let hi = DVec3::new(hi.x, hi.y, f64::from(height_m[1])) - run.camera_grid_m;
        let nearest = DVec3::ZERO.clamp(lo, hi).length();
        let farthest = lo.abs().max(hi.abs()).length();
        let radial =
            s.tlm.radial_bands_m.iter().position(|&t| nearest < t).map_or(RADIAL_INACTIVE, |k| k as u32);
        let hlod = |d: f64| run.lods.range_m.iter().position(|&range| d <= range).unwrap_or(0) as u32;
        let tlod = |d: f64| {
            imagery.map_or(0, |m| {
                let level = (mpp * d / m.texel_m).log2() + s.imagery.lod_bias;
                level.floor().clamp(0.0, f64::from(m.pyramid.levels - 1)) as u32
            })
        };
        let ambiguous = s.tlm.radial_bands_m.iter().any(|&t| near(nearest, t))
            || run.lods.range_m.iter().any(|&t| near(nearest, t) || near(farthest, t))
            || imagery.is_some_and(|m| {
                [nearest, farthest].iter().any(|&d| {
                    let level = (mpp * d / m.texel_m).log2() + s.imagery.lod_bias;
                    (level - level.round()).abs() < 1e-3
                })
            });
        if ambiguous {
            continue;
        }
        assert_eq!(cell.radial_lod, radial, "{what}: radial LOD of {:?} at {nearest:.1} m", (ring, cx, cy));
        assert_eq!(
            cell.height_lod,
            LevelRange { min: hlod(nearest), max: hlod(farthest) }.pack(),
            "{what}: height LOD of {:?}",
            (ring, cx, cy)
        );
        let imagery_lod =
            if imagery.is_some() { LevelRange { min: tlod(nearest), max: tlod(farthest) }.pack() } else { 0 };
        assert_eq!(cell.imagery_lod, imagery_lod, "{what}: imagery LOD of {:?}", (ring, cx, cy));
        if ring == 0 {
            let g = run.layout.global_address(ring, cx, cy);
            let pattern = cell_pattern([g.x as i32, g.y as i32], s.tlm.seed, s.tlm.corner_colours());
            assert_eq!(cell.visibility, tlm_visibility(pattern), "{what}: pattern of {g:?}");
        } else {
            assert_eq!(cell.visibility, TLM_FIRST_PATTERN);
        }
        checked += 1;
    }
    assert!(checked > 0 || visible(&run.gpu) == 0, "{what}: nothing checked");
}

/// What `bent_boxes_hold` found.
#[derive(Debug, Clone, Copy, Default)]
pub struct BentBoxes {
    /// Cells over the dataset checked.
    pub boxes: usize,
    /// The most a bent box reaches past the points it holds, on any side, metres.
    pub slack_m: f64,
    /// The farthest point held, horizontally from the eye, metres.
    pub farthest_m: f64,
}

/// Every cell over the dataset holds, in the box the pass bends it to (`bent_box`, the twin's),
/// a 5 × 5 lattice of its ground points at its tiles' lowest and highest heights placed by the
/// exact mapping, up to f32's rounding of the box (a millionth of the point's distance).
pub fn bent_boxes_hold(run: &Run) -> BentBoxes {
    let u = &run.frame.uniforms;
    let mut out = BentBoxes::default();
    for index in 0..run.layout.cell_count() {
        let (ring, cx, cy) = run.layout.cell_of(index);
        let (sx, sy) = (
            run.frame.spans[((ring * 2) * u.cells + cx) as usize],
            run.frame.spans[((ring * 2 + 1) * u.cells + cy) as usize],
        );
        if sx.flags & sy.flags & TLM_SPAN_INSIDE == 0 {
            continue;
        }
        let heights = cell_height_range(run, ring, cx, cy);
        let lo = [sx.rel_m[0], sy.rel_m[0], heights[0] - u.camera_z_m];
        let hi = [sx.rel_m[1], sy.rel_m[1], heights[1] - u.camera_z_m];
        let (bent_lo, bent_hi) = bent_box(u, lo, hi);
        let (bent_lo, bent_hi) = (DVec3::from(bent_lo.map(f64::from)), DVec3::from(bent_hi.map(f64::from)));
        let (mut held_lo, mut held_hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for j in 0..=4 {
            for k in 0..=4 {
                for h in heights {
                    let f =
                        |a: usize, n: i32| f64::from(lo[a]) + f64::from(hi[a] - lo[a]) * f64::from(n) / 4.0;
                    let grid = run.camera_grid_m + DVec3::new(f(0, j), f(1, k), 0.0);
                    let p = run.placing.position_rel_m(DVec3::new(grid.x, grid.y, f64::from(h)));
                    // The box is f32, rounded from the camera-relative grid box: a few of f32's
                    // steps at the point's size.
                    let rounding = DVec3::splat(1e-6 * p.abs().max_element());
                    assert!(
                        (p + rounding).cmpge(bent_lo).all() && (p - rounding).cmple(bent_hi).all(),
                        "cell {:?}: {p} outside {bent_lo}..{bent_hi}",
                        (ring, cx, cy)
                    );
                    (held_lo, held_hi) = (held_lo.min(p), held_hi.max(p));
                    out.farthest_m = out.farthest_m.max(p.truncate().length());
                }
            }
        }
        out.slack_m = out.slack_m.max((held_lo - bent_lo).max(bent_hi - held_hi).max_element());
        out.boxes += 1;
    }
    out
}
