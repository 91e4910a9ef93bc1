//! A frame's counts (`gpu::counts`), exact where a count can be had another way:
//! - a hand-made frame of known draws, indirect draws (arguments written by the test), a dispatch
//!   and an upload: draw calls, indirect draws, dispatches, triangles submitted and bytes
//!   uploaded are the known ones; on lavapipe its clipper passes every triangle (all inside the
//!   view, none culled) and its compute invocations are the dispatch's workgroups × their size;
//!   counted as an adapter without pipeline statistics, the same counts and those four absent;
//! - a renderer's frame over the synthetic dataset, trees drawn: draw_seeds' triangles submitted
//!   are those of compaction's CPU twin over the frame's own inputs (each group's indices over 3
//!   times its seeds, twice with the depth prepass), its indirect draws one per draw with geometry
//!   (twice with the prepass), pass 3's bytes uploaded its uniforms and cells, and the ground and
//!   the terrain submit the same mesh; every frame's counts arrive, in order.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use terramp::gpu::counter::{Counter, Counting};
use terramp::gpu::counts::{FrameCounts, Part, Statistics};
use terramp::gpu::gpu_types::{SeedCell, SeedUniforms};
use terramp::gpu::{Gpu, layout::SEED_DRAWS};
use terramp_testkit::{camera, gpu, lavapipe_only, renderer, small_settings, synth_dataset};
use wgpu::util::DeviceExt;

const SHADER: &str = "
@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4f {
    // A small triangle well inside the view, whatever the index.
    let corner = array(vec2f(-0.5, -0.5), vec2f(0.5, -0.5), vec2f(0.0, 0.5));
    return vec4f(corner[i % 3u], 0.5, 1.0);
}
@fragment fn fs() -> @location(0) vec4f { return vec4f(1.0); }
@compute @workgroup_size(8) fn cs() {}
";

/// Workgroups of the test's dispatch, and invocations per workgroup (`cs`).
const WORKGROUPS: [u32; 3] = [2, 3, 1];
const WORKGROUP_SIZE: u64 = 8;

/// The known frame, counted by a counter with `statistics` (if the adapter has them).
fn known_frame(gpu: &Gpu, statistics: bool) -> FrameCounts {
    let device = &gpu.device;
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: None,
        source: wgpu::ShaderSource::Wgsl(SHADER.into()),
    });
    let format = wgpu::TextureFormat::Rgba8Unorm;
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: None,
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState { cull_mode: None, ..Default::default() },
        depth_stencil: None,
        multisample: Default::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(format.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    let compute = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: None,
        layout: None,
        module: &module,
        entry_point: Some("cs"),
        compilation_options: Default::default(),
        cache: None,
    });
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: None,
        size: wgpu::Extent3d { width: 32, height: 32, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    });
    let view = target.create_view(&Default::default());
    let init = |contents: &[u8], usage| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: None, contents, usage })
    };
    let indices = init(bytemuck::cast_slice(&[0u32, 1, 2, 0, 1, 2, 0, 1, 2]), wgpu::BufferUsages::INDEX);
    // Two draws' arguments: 6 indices × 7 instances, then 3 × 4.
    let args = [6u32, 7, 0, 0, 0, 3, 4, 0, 0, 0];
    let args = init(bytemuck::cast_slice(&args), wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_SRC);
    let uploaded = device.create_buffer(&wgpu::BufferDescriptor {
        label: None,
        size: 256,
        usage: wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });

    let mut counter = Counter::new(gpu, statistics);
    counter.begin_frame(5);
    counter.uploads(&gpu.queue, "upload", || gpu.queue.write_buffer(&uploaded, 0, &[7; 100]));
    let mut encoder = device.create_command_encoder(&Default::default());
    let record = |encoder: &mut wgpu::CommandEncoder, c: Counting<'_>| {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                    store: wgpu::StoreOp::Store,
                },
            })],
            ..Default::default()
        });
        pass.set_pipeline(&pipeline);
        pass.set_index_buffer(indices.slice(..), wgpu::IndexFormat::Uint32);
        c.begin(&mut pass, Part::Whole);
        c.draw(&mut pass, 0..6, 0..5); // 2 triangles × 5
        c.draw_indexed(&mut pass, 0..9, 0, 1..3); // 3 × 2
        c.draw_indexed_indirect(&mut pass, &args, 0); // 2 × 7
        c.draw_indexed_indirect(&mut pass, &args, 0); // again: 2 × 7
        c.draw_indexed_indirect(&mut pass, &args, 20); // 1 × 4
        c.end(&mut pass);
    };
    record(&mut encoder, counter.pass("draw"));
    // Recorded outside the count: the same commands, nothing counted.
    record(&mut encoder, Counting::OFF);
    {
        let c = counter.pass("compute");
        let mut pass = encoder.begin_compute_pass(&Default::default());
        pass.set_pipeline(&compute);
        c.begin(&mut pass, Part::Whole);
        c.dispatch(&mut pass, WORKGROUPS);
        c.end(&mut pass);
    }
    counter.resolve(&mut encoder);
    gpu.queue.submit([encoder.finish()]);
    counter.submitted();
    gpu.wait().unwrap();
    let frames = counter.collect(device).unwrap();
    gpu.check().unwrap();
    let [frame] = frames.as_slice() else { panic!("not one frame: {frames:?}") };
    frame.clone()
}

#[test]
fn a_known_frame_is_counted_exactly_with_and_without_statistics() {
    let gpu = gpu();
    let counted = known_frame(&gpu, true);
    println!("{counted:#?}");
    assert_eq!(counted.frame, 5);
    let draw = counted.pass("draw").unwrap();
    let triangles = 2 * 5 + 3 * 2 + 2 * (2 * 7) + 4;
    assert_eq!((draw.draw_calls, draw.indirect_draws, draw.dispatches), (2, 3, 0));
    assert_eq!(draw.triangles_submitted, Some(triangles));
    let compute = counted.pass("compute").unwrap();
    assert_eq!((compute.dispatches, compute.draw_calls, compute.triangles_submitted), (1, 0, Some(0)));
    assert_eq!(counted.pass("upload").unwrap().bytes_uploaded, 100);
    assert_eq!(counted.total().bytes_uploaded, 100, "only the upload uploaded");
    assert!(counted.pass("counts").unwrap().bytes_read_back > 0);

    if counted.statistics && lavapipe_only(&gpu, "llvmpipe's clipper and compute invocations counted exactly")
    {
        let s = draw.statistics.unwrap();
        assert_eq!(s.clipped_triangles, triangles, "every triangle is inside the view: {s:?}");
        assert!(s.vertex_invocations > 0 && s.fragment_invocations > 0, "{s:?}");
        let c = compute.statistics.unwrap();
        let invocations = WORKGROUPS.iter().map(|&n| u64::from(n)).product::<u64>() * WORKGROUP_SIZE;
        assert_eq!(c, Statistics { compute_invocations: invocations, ..Default::default() });
        assert_eq!(s.compute_invocations, 0);
    }

    let derived = known_frame(&gpu, false);
    assert!(!derived.statistics);
    assert!(derived.passes.iter().all(|p| p.statistics.is_none()), "{derived:?}");
    let without = |f: &FrameCounts| {
        f.passes
            .iter()
            .filter(|p| p.label != "counts")
            .map(|p| {
                (
                    p.label,
                    p.draw_calls,
                    p.indirect_draws,
                    p.dispatches,
                    p.triangles_submitted,
                    p.bytes_uploaded,
                )
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(without(&derived), without(&counted), "the derived counts depend on the statistics");
}

#[test]
fn a_renderers_frame_counts_what_it_drew() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let dir = synth_dataset(300, 7);
    for depth_prepass in [false, true] {
        let mut settings = small_settings(320, 180);
        settings.draw_seeds.impostors = impostors.to_str().unwrap().to_owned();
        settings.draw_seeds.depth_prepass = depth_prepass;
        let mut r = renderer(&dir, settings);
        let view = camera::over_fraction(&r, [0.45, 0.35], 25.0, 20.0, -10.0);
        let (report, _) = r.render_resolved(&view).unwrap();
        let (_, compacted) = r.compact_twin().unwrap().unwrap();
        let templates = r.seed_draw_templates().unwrap();
        r.gpu.wait().unwrap();
        let mut arrived: Vec<FrameCounts> = r.take_counts().unwrap();
        let frames: Vec<u64> = arrived.iter().map(|c| c.frame).collect();
        assert!(frames.windows(2).all(|w| w[0] + 1 == w[1]), "{frames:?}");
        let counts = arrived.pop().unwrap();
        assert_eq!(counts.frame, report.frame, "after a wait, the last frame's counts are in");

        let times = 1 + u64::from(depth_prepass);
        let seeds = counts.pass("draw_seeds").unwrap();
        let twin: u64 =
            compacted.args.iter().map(|a| u64::from(a.index_count / 3) * u64::from(a.instance_count)).sum();
        println!("prepass {depth_prepass}: draw_seeds {seeds:?}");
        assert!(twin > 1000, "{twin} triangles: a weak test");
        assert_eq!(seeds.triangles_submitted, Some(times * twin), "against compaction's twin");
        let with_geometry = templates.iter().filter(|t| t.index_count > 0).count() as u64;
        assert!(with_geometry > 0 && with_geometry <= u64::from(SEED_DRAWS));
        assert_eq!((seeds.indirect_draws, seeds.draw_calls), (times * with_geometry, 0));
        assert_eq!(seeds.prepass.is_some(), depth_prepass && counts.statistics);

        let select = counts.pass("seed_select").unwrap();
        let cells = report.seed_cells as u64;
        assert!(cells > 0);
        let bytes = size_of::<SeedUniforms>() as u64 + cells * size_of::<SeedCell>() as u64;
        assert_eq!(select.bytes_uploaded, bytes, "pass 3's uniforms and {cells} cells");
        assert_eq!((select.dispatches, select.indirect_dispatches), (2, 1));

        let (terrain, ground) = (counts.pass("terrain").unwrap(), counts.pass("ground").unwrap());
        assert!(terrain.triangles_submitted.unwrap() > 0 && (1..=4).contains(&terrain.draw_calls));
        assert_eq!(
            (terrain.draw_calls, terrain.triangles_submitted),
            (ground.draw_calls, ground.triangles_submitted),
            "the ground draws the terrain's mesh"
        );
        let total = counts.total();
        assert_eq!(
            total.triangles_submitted.unwrap(),
            counts.passes.iter().map(|p| p.triangles_submitted.unwrap()).sum::<u64>()
        );
    }
}
