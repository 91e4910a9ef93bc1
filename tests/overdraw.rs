//! Counting the foliage passes' fragments (`gpu.count_fragments`) over a small synthetic dataset
//! with the shared models baked:
//! - the pixels draw_seeds covers are exactly those where the frame differs from the ground-only
//!   frame of the same view, and it shades at least one fragment for each;
//! - counting changes no pixel: the frame equals the one drawn without counting, bit for bit;
//! - a view with no seed in it counts nothing (the query holds the pass's draws alone);
//! - a depth prepass changes no pixel, single-sampled or multisampled, and its shading draws
//!   write each sample the seeds show once (the occlusion query), where the draw without one
//!   writes some twice or more;
//! - multisampled, the same: covered pixels where the frame differs, counting changes nothing;
//! - a full-screen triangle covers every pixel and counts each at least once, and at most the 4 × 4
//!   blocks along one diagonal more (llvmpipe clips it to the screen, two triangles, and runs
//!   whole blocks: those the shared edge crosses, twice); half the screen covers half of it, with
//!   at least a fragment for each pixel. That accounting is llvmpipe's: on another adapter the
//!   test says it is skipped (`lavapipe_only`).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::frame::FrameReport;
use terramp::gpu::Gpu;
use terramp::gpu::counter::Counter;
use terramp::gpu::counts::Part;
use terramp::gpu::fragments::{FragmentCounter, with_counts};
use terramp_testkit::{camera, lavapipe_only, renderer, small_settings, synth_dataset};

const IMAGE_PX: [u32; 2] = [320, 180];

fn settings(impostors: &str, count_fragments: bool) -> Settings {
    let mut s = small_settings(IMAGE_PX[0], IMAGE_PX[1]);
    s.draw_seeds.impostors = impostors.to_owned();
    s.gpu.count_fragments = count_fragments;
    s
}

fn multisampled(mut s: Settings) -> Settings {
    s.draw_seeds.samples = 4;
    s
}

/// The settled frame of `settings` from the pose `view` gives, its light as the passes wrote it
/// (`Renderer::read_light`: what the fragment counter compares, before the display rounds it to
/// 8 bits), and the last frame's report.
fn frame(
    dir: &std::path::Path,
    settings: Settings,
    view: fn(&terramp::frame::Renderer) -> Camera,
) -> (Vec<[f32; 3]>, FrameReport) {
    let mut r = renderer(dir, settings);
    let camera = view(&r);
    let (report, _) = r.render_resolved(&camera).unwrap();
    (r.read_light().unwrap(), report)
}

fn into_the_trees(r: &terramp::frame::Renderer) -> Camera {
    camera::over_fraction(r, [0.45, 0.35], 25.0, 20.0, -10.0)
}

fn at_the_sky(r: &terramp::frame::Renderer) -> Camera {
    camera::over_fraction(r, [0.45, 0.35], 25.0, 20.0, 60.0)
}

#[test]
fn draw_seeds_counts_its_fragments_and_exactly_the_pixels_it_changes() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let impostors = impostors.to_str().unwrap();
    let dir = synth_dataset(300, 7);
    let (ground, _) = frame(&dir, settings("", false), into_the_trees);
    let (plain, plain_report) = frame(&dir, settings(impostors, false), into_the_trees);
    let (counted, report) = frame(&dir, settings(impostors, true), into_the_trees);
    assert!(plain_report.fragments.is_empty(), "counted without gpu.count_fragments");
    assert_eq!(plain, counted, "counting changed the frame");

    let [seeds] = report.fragments.as_slice() else { panic!("not one counted pass: {:?}", report.fragments) };
    assert_eq!(seeds.label, "draw_seeds");
    let changed = counted.iter().zip(&ground).filter(|(a, b)| a != b).count() as u64;
    println!("draw_seeds: {} fragments shaded, {} pixels covered", seeds.shaded, seeds.covered_px);
    assert!(changed > 500, "only {changed} pixels show trees: a weak test");
    assert_eq!(seeds.covered_px, changed, "covered pixels against the frame's difference from the ground");
    assert!(seeds.shaded >= seeds.covered_px, "{seeds:?}: fewer fragments than pixels covered");
    assert!(seeds.vertices > 0 && seeds.triangles > 0, "{seeds:?}");

    let (_, sky) = frame(&dir, settings(impostors, true), at_the_sky);
    assert_eq!(
        sky.fragments.iter().map(|f| (f.shaded, f.covered_px)).collect::<Vec<_>>(),
        [(0, 0)],
        "{sky:?}"
    );

    // Multisampled (`draw_seeds.samples` = 4): the same, through the pass that fills and resolves
    // its own targets (the fill's full-screen triangle not counted).
    let (plain, _) = frame(&dir, multisampled(settings(impostors, false)), into_the_trees);
    let (counted, report) = frame(&dir, multisampled(settings(impostors, true)), into_the_trees);
    assert_eq!(plain, counted, "counting changed the multisampled frame");
    let [seeds] = report.fragments.as_slice() else { panic!("not one counted pass: {:?}", report.fragments) };
    let changed = counted.iter().zip(&ground).filter(|(a, b)| a != b).count() as u64;
    println!(
        "multisampled draw_seeds: {} fragments shaded, {} pixels covered",
        seeds.shaded, seeds.covered_px
    );
    assert_eq!(seeds.covered_px, changed, "covered pixels against the frame's difference from the ground");
    let pixels = u64::from(IMAGE_PX[0] * IMAGE_PX[1]);
    assert!(seeds.shaded >= seeds.covered_px && seeds.shaded < 200 * pixels, "{seeds:?}");
}

#[test]
fn a_depth_prepass_changes_no_pixel_and_lights_each_sample_once() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let impostors = impostors.to_str().unwrap();
    let dir = synth_dataset(300, 7);
    let draw = |depth_prepass: bool, samples: u32| {
        let mut s = settings(impostors, true);
        (s.draw_seeds.depth_prepass, s.draw_seeds.samples) = (depth_prepass, samples);
        let (image, report) = frame(&dir, s, into_the_trees);
        let [seeds] = report.fragments[..] else { panic!("not one counted pass: {:?}", report.fragments) };
        (image, seeds)
    };
    for samples in [1, 4] {
        let (plain_image, plain) = draw(false, samples);
        let (image, prepassed) = draw(true, samples);
        println!("{samples} samples: without a prepass {plain:?}\n           with one {prepassed:?}");
        assert_eq!(plain_image, image, "the prepass changed the frame ({samples} samples)");
        assert!(plain.covered_px > 500, "{plain:?}: a weak test");
        assert_eq!((plain.prepass_shaded, prepassed.covered_px), (0, plain.covered_px));
        assert!(prepassed.prepass_shaded >= prepassed.covered_px, "{prepassed:?}");
        // Each sample a seed shows is lit once (ties of two fragments at one depth aside), where
        // the draw without a prepass overwrites those a nearer fragment comes to later.
        let covered = u64::from(samples) * prepassed.covered_px;
        assert!(
            (prepassed.covered_px..=covered + covered / 100).contains(&prepassed.written),
            "{prepassed:?}"
        );
        assert!(plain.written >= prepassed.written, "{plain:?} against {prepassed:?}");
    }
}

/// Fragments shaded and pixels covered by one triangle (clip-space corners `corners`) drawn in a
/// constant colour over a black `size` target.
fn count_triangle(gpu: &Gpu, size: [u32; 2], corners: [[f32; 2]; 3]) -> (u64, u64) {
    let device = &gpu.device;
    let target = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("counted target"),
        size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8Unorm,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let [a, b, c] = corners.map(|[x, y]| format!("vec2<f32>({x:?}, {y:?})"));
    let source = format!(
        "@vertex fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {{
             var corners = array<vec2<f32>, 3>({a}, {b}, {c});
             return vec4<f32>(corners[i], 0.5, 1.0);
         }}
         @fragment fn fs() -> @location(0) vec4<f32> {{ return vec4<f32>(1.0, 0.5, 0.25, 1.0); }}"
    );
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("triangle"),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("triangle"),
        layout: None,
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs"),
            compilation_options: Default::default(),
            buffers: &[],
        },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs"),
            compilation_options: Default::default(),
            targets: &[Some(wgpu::TextureFormat::Rgba8Unorm.into())],
        }),
        primitive: Default::default(),
        depth_stencil: None,
        multisample: Default::default(),
        multiview_mask: None,
        cache: None,
    });
    let counter = FragmentCounter::new(gpu, &["triangle"], &target).expect("pipeline-statistics queries");
    // The invocations are the frame's counts'; the pixels and samples the fragment counter's.
    let mut counts = Counter::new(gpu, true);
    counts.begin_frame(0);
    let counting = counts.pass("triangle");
    let view = target.create_view(&Default::default());
    let mut encoder = device.create_command_encoder(&Default::default());
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("clear"),
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
    FragmentCounter::around(Some(&counter), "triangle", &mut encoder, &target, &|e, count| {
        let count = count.expect("the triangle pass is counted");
        let mut pass = e.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("triangle"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &view,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            occlusion_query_set: Some(count.occlusion_set()),
            ..Default::default()
        });
        counting.begin(&mut pass, Part::Shading);
        count.begin(&mut pass);
        pass.set_pipeline(&pipeline);
        counting.draw(&mut pass, 0..3, 0..1);
        count.end(&mut pass);
        counting.end(&mut pass);
    });
    counter.resolve(&mut encoder);
    counts.resolve(&mut encoder);
    gpu.queue.submit([encoder.finish()]);
    counts.submitted();
    let pixels = counter.read(gpu).unwrap();
    let frame = counts.collect(device).unwrap().pop().expect("the frame's counts, after a wait");
    let [counted] = with_counts(pixels, &frame)[..] else { panic!("one pass counted") };
    // Nothing tests depth or discards: every pixel covered is written, once; one triangle of 3
    // vertices (a fan of a few, where the clipper cuts it at the screen's edge).
    assert_eq!((counted.written, counted.prepass_shaded), (counted.covered_px, 0), "{counted:?}");
    assert!(counted.vertices >= 3 && (1..=4).contains(&counted.triangles), "{counted:?}");
    (counted.shaded, counted.covered_px)
}

#[test]
fn a_full_screen_triangle_counts_each_pixel_once_and_half_the_screen_covers_half() {
    let gpu = terramp_testkit::gpu();
    if !lavapipe_only(&gpu, "llvmpipe's fragments in whole 4 × 4 blocks along a clipped diagonal") {
        return;
    }
    let size = [64, 48];
    let pixels = u64::from(size[0] * size[1]);
    // 4 × 4 blocks a diagonal of the screen crosses, 16 fragments each.
    let diagonal = 16 * u64::from(size[0] / 4 + size[1] / 4);
    let (shaded, covered) = count_triangle(&gpu, size, [[-1.0, -1.0], [3.0, -1.0], [-1.0, 3.0]]);
    println!("the whole screen: {shaded} fragments shaded, {covered} pixels covered");
    assert_eq!(covered, pixels);
    assert!((pixels..=pixels + diagonal).contains(&shaded), "{shaded} fragments for {pixels} pixels");
    // The lower-left half, corner to corner: the diagonal's pixels go to one side or the other.
    let (shaded, covered) = count_triangle(&gpu, size, [[-1.0, -1.0], [1.0, -1.0], [-1.0, 1.0]]);
    println!("half the screen: {shaded} fragments shaded, {covered} pixels covered");
    assert!(covered.abs_diff(pixels / 2) <= u64::from(size[0]), "{covered} of {pixels} pixels covered");
    assert!((covered..=covered + diagonal).contains(&shaded), "{shaded} fragments for {covered} pixels");
}
