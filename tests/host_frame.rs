//! `Renderer::render_into`: terramp drawn over a host's frame, on a synthetic dataset with the
//! shared trees (multisampled). The host clears its colour and depth and draws a wall over the
//! left half of the view, nearer than any ground, then terramp draws over it:
//! - without the wall, the host's colour is terramp's own display of the same view, pixel for
//!   pixel on lavapipe (every pixel is terramp's);
//! - with it, the left half is the wall's colour in every pixel, the right half terramp's view
//!   within a stated PSNR, and pass 3 culls the seeds behind the wall (fewer selected, more
//!   culled by occlusion): the host's depth is in the culling, not only in the drawing;
//! - afterwards the host's depth holds the wall on the left and terramp's depth on the right
//!   (the terrain's: multisampled trees keep theirs in their own target);
//! - targets of another size, a linear 8-bit colour or a depth that cannot be copied are
//!   refused, naming the target (a linear HDR colour is `tests/host_hdr.rs`'s).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use terramp::camera::Camera;
use terramp::frame::{FrameReport, HostTargetError, HostTargets, RenderError, Renderer};
use terramp::gpu::TimeSource;
use terramp::gpu::readback::read_texture;
use terramp::passes::DEPTH_FORMAT;
use terramp_testkit::{
    camera, differing_pixels, lavapipe_only, psnr, renderer, small_settings, synth_dataset, texture_2d,
};

const SIZE: [u32; 2] = [256, 144];
/// The wall's depth (reversed-Z: nearer than any ground the view shows) and colour.
const WALL_DEPTH: f32 = 0.9;
const WALL: [u8; 4] = [255, 0, 255, 255];
/// Least PSNR of the right half beside the wall against terramp's view without it, dB: the
/// wall changes what streams (tiles behind it are not asked for) and which seeds pass 3 keeps.
const BESIDE_WALL_PSNR_DB: f64 = 35.0;
/// Most frames a view is given to settle.
const SETTLE_FRAMES: u32 = 200;

const WALL_WGSL: &str = "
@vertex
fn vs(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    var corners = array<vec2<f32>, 6>(vec2(-1.0, -1.0), vec2(0.0, -1.0), vec2(-1.0, 1.0),
                                      vec2(-1.0, 1.0), vec2(0.0, -1.0), vec2(0.0, 1.0));
    return vec4<f32>(corners[i], WALL_DEPTH, 1.0);
}
@fragment
fn fs() -> @location(0) vec4<f32> { return vec4<f32>(1.0, 0.0, 1.0, 1.0); }
";

/// Who submits terramp's frame.
#[derive(Clone, Copy)]
enum Submit {
    /// terramp, after the host's (`render_into`).
    Terramp,
    /// The host, with its own geometry in one encoder (`encode_frame`), saying so (`submitted`).
    Host,
    /// As `Host`, never saying so: each frame's readbacks start at the next frame.
    HostUnsaid,
}

/// The host: its targets and the pipeline of its wall.
struct Host {
    colour: wgpu::Texture,
    depth: wgpu::Texture,
    wall: wgpu::RenderPipeline,
}

const TARGET: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::COPY_SRC)
    .union(wgpu::TextureUsages::COPY_DST);

impl Host {
    fn new(device: &wgpu::Device) -> Self {
        let colour = texture_2d(device, SIZE, wgpu::TextureFormat::Rgba8UnormSrgb, TARGET);
        let depth = texture_2d(device, SIZE, DEPTH_FORMAT, TARGET);
        let source = WALL_WGSL.replace("WALL_DEPTH", &format!("{WALL_DEPTH:?}"));
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("wall"),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let wall = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("wall"),
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
                targets: &[Some(colour.format().into())],
            }),
            primitive: Default::default(),
            depth_stencil: Some(wgpu::DepthStencilState {
                format: DEPTH_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Greater),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            multiview_mask: None,
            cache: None,
        });
        Self { colour, depth, wall }
    }

    /// The host's frame (cleared, the wall drawn or not), then terramp's over it: submitted by
    /// terramp after the host's, or recorded into the host's encoder and submitted with it.
    fn frame(&self, r: &mut Renderer, pose: &Camera, wall: bool, submit: Submit) -> FrameReport {
        let mut encoder = r.gpu.device.create_command_encoder(&Default::default());
        self.record(&mut encoder, wall);
        let targets = HostTargets { colour: &self.colour, depth: &self.depth };
        match submit {
            Submit::Terramp => {
                r.gpu.queue.submit([encoder.finish()]);
                r.render_into(pose, &targets).unwrap()
            }
            Submit::Host | Submit::HostUnsaid => {
                let report = r.encode_frame(pose, &mut encoder, &targets).unwrap();
                r.gpu.queue.submit([encoder.finish()]);
                if matches!(submit, Submit::Host) {
                    r.submitted();
                }
                report
            }
        }
    }

    /// Records the host's geometry: its targets cleared, the wall drawn or not.
    fn record(&self, encoder: &mut wgpu::CommandEncoder, wall: bool) {
        {
            let (colour, depth) =
                (self.colour.create_view(&Default::default()), self.depth.create_view(&Default::default()));
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("the host's geometry"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &colour,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLUE),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if wall {
                pass.set_pipeline(&self.wall);
                pass.draw(0..6, 0..1);
            }
        }
    }

    /// The host's frame settled: every tile it asks for resident, and pass 3's counters (a frame
    /// or two late) the same two frames running.
    fn settled(
        &self,
        r: &mut Renderer,
        pose: &Camera,
        wall: bool,
        submit: Submit,
    ) -> (FrameReport, image::RgbaImage) {
        let mut report = self.frame(r, pose, wall, submit);
        // Counters of this call's frames only: the view before it may have had other ones.
        let first = report.frame;
        let counters = |report: &FrameReport| {
            report.seeds.filter(|s| s.frame >= first && s.counters.checked > 0).map(|s| s.counters)
        };
        let mut last = None;
        for _ in 0..SETTLE_FRAMES {
            let arrived = report.height.needed_resident == report.height.needed
                && report.imagery.needed_resident == report.imagery.needed;
            if arrived && counters(&report).is_some() && counters(&report) == last {
                return (report, self.colour(r));
            }
            last = counters(&report);
            report = self.frame(r, pose, wall, submit);
        }
        panic!("the view did not settle in {SETTLE_FRAMES} frames")
    }

    fn colour(&self, r: &Renderer) -> image::RgbaImage {
        let bytes = read_texture(&r.gpu, &self.colour, wgpu::TextureAspect::All, 4).unwrap();
        image::RgbaImage::from_raw(SIZE[0], SIZE[1], bytes).unwrap()
    }

    fn depth(&self, r: &Renderer) -> Vec<f32> {
        bytemuck::pod_collect_to_vec(
            &read_texture(&r.gpu, &self.depth, wgpu::TextureAspect::DepthOnly, 4).unwrap(),
        )
    }
}

fn half(image: &image::RgbaImage, right: bool) -> image::RgbaImage {
    let w = image.width() / 2;
    image::imageops::crop_imm(image, if right { w } else { 0 }, 0, w, image.height()).to_image()
}

#[test]
fn terramp_over_a_hosts_frame_meets_its_geometry_in_depth_and_in_culling() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let dir = synth_dataset(300, 7);
    let mut settings = small_settings(SIZE[0], SIZE[1]);
    settings.draw_seeds.impostors = impostors.to_str().unwrap().to_owned();
    settings.draw_seeds.samples = 4;
    let mut r = renderer(&dir, settings);
    let pose = camera::over_fraction(&r, [0.45, 0.35], 25.0, 20.0, -10.0);
    let host = Host::new(&r.gpu.device);

    let (plain, plain_image) = host.settled(&mut r, &pose, false, Submit::Terramp);
    r.render(&pose).unwrap();
    let own = r.read_colour().unwrap();
    let plain_db = psnr(&plain_image, &own);
    println!("no wall: the host's colour against terramp's own display: {plain_db:.1} dB");
    if lavapipe_only(&r.gpu, "the host's colour pixel for pixel") {
        assert_eq!(differing_pixels(&plain_image, &own), 0);
    }

    let (walled, walled_image) = host.settled(&mut r, &pose, true, Submit::Terramp);
    let left = half(&walled_image, false);
    assert!(left.pixels().all(|p| p.0 == WALL), "the wall is covered somewhere");
    let beside_db = psnr(&half(&walled_image, true), &half(&plain_image, true));
    let [plain_seeds, walled_seeds] = [plain, walled].map(|r| r.seeds.unwrap().counters);
    println!(
        "beside the wall: {beside_db:.1} dB; seeds selected {} without the wall, {} with it; culled by occlusion {} and {}",
        plain_seeds.selected, walled_seeds.selected, plain_seeds.occlusion, walled_seeds.occlusion
    );
    assert!(beside_db >= BESIDE_WALL_PSNR_DB, "{beside_db:.1} dB");
    assert!(walled_seeds.selected < plain_seeds.selected && walled_seeds.occlusion > plain_seeds.occlusion);

    let (host_depth, own_depth) = (host.depth(&r), r.read_depth().unwrap());
    let w = SIZE[0] as usize;
    for (i, (&host_d, &own_d)) in host_depth.iter().zip(&own_depth).enumerate() {
        let expected = if i % w < w / 2 { WALL_DEPTH } else { own_d };
        assert_eq!(host_d, expected, "pixel {i}");
    }
    assert!(
        own_depth.iter().enumerate().any(|(i, &d)| i % w >= w / 2 && d > 0.0),
        "no ground beside the wall"
    );
}

#[test]
fn targets_terramp_cannot_draw_over_are_refused_naming_them() {
    let dir = synth_dataset(64, 3);
    let mut r = renderer(&dir, small_settings(SIZE[0], SIZE[1]));
    let pose = camera::over_fraction(&r, [0.5, 0.5], 50.0, 0.0, -10.0);
    let device = r.gpu.device.clone();
    let good = Host::new(&device);
    let small = texture_2d(&device, [128, 72], wgpu::TextureFormat::Rgba8UnormSrgb, TARGET);
    let linear = texture_2d(&device, SIZE, wgpu::TextureFormat::Rgba8Unorm, TARGET);
    let uncopyable = texture_2d(&device, SIZE, DEPTH_FORMAT, wgpu::TextureUsages::RENDER_ATTACHMENT);
    let cases = [
        (&small, &good.depth, "colour"),
        (&linear, &good.depth, "colour"),
        (&good.colour, &uncopyable, "depth"),
    ];
    for (colour, depth, named) in cases {
        let refused = r.render_into(&pose, &HostTargets { colour, depth }).unwrap_err();
        let RenderError::Host(error) = &refused else { panic!("{refused}") };
        let target = match error {
            HostTargetError::Size { target, .. } | HostTargetError::Unusable { target, .. } => *target,
        };
        println!("{refused}");
        assert_eq!(target, named);
    }
    // Refusals draw nothing and leave the renderer working.
    r.render_into(&pose, &HostTargets { colour: &good.colour, depth: &good.depth }).unwrap();
}

#[test]
fn a_frame_recorded_into_the_hosts_encoder_is_the_frame_terramp_submits() {
    let Some(impostors) = terramp_testkit::nc_impostors() else { return };
    let dir = synth_dataset(300, 7);
    let mut settings = small_settings(SIZE[0], SIZE[1]);
    settings.draw_seeds.impostors = impostors.to_str().unwrap().to_owned();
    settings.draw_seeds.samples = 4;
    let [mut own, mut hosted] = [(); 2].map(|()| renderer(&dir, settings.clone()));
    let pose = camera::over_fraction(&own, [0.45, 0.35], 25.0, 20.0, -10.0);
    // Each renderer has a device of its own (`renderer`), and each host its targets on it.
    let [own_host, hosted_host] = [&own, &hosted].map(|r| Host::new(&r.gpu.device));

    let (submitted, submitted_image) = own_host.settled(&mut own, &pose, true, Submit::Terramp);
    let (recorded, recorded_image) = hosted_host.settled(&mut hosted, &pose, true, Submit::Host);
    let db = psnr(&recorded_image, &submitted_image);
    let [a, b] = [submitted, recorded].map(|r| r.seeds.unwrap().counters);
    println!(
        "recorded by the host against submitted by terramp: {db:.1} dB; seeds selected {} and {}",
        a.selected, b.selected
    );
    assert_eq!(a, b, "pass 3's counters");
    if lavapipe_only(&hosted.gpu, "the recorded frame pixel for pixel") {
        assert_eq!(differing_pixels(&recorded_image, &submitted_image), 0);
    }
    // The passes were timed inside the host's encoder, where the adapter has timestamps.
    if hosted.profiler.uses_gpu_timestamps() {
        let timed = hosted
            .last_timings()
            .iter()
            .any(|t| t.label == "draw_seeds" && t.source == TimeSource::GpuTimestamps);
        assert!(timed, "{:?}", hosted.last_timings());
    }
}

#[test]
fn a_frame_in_the_hosts_encoder_reaches_the_gpu_with_the_hosts_submit() {
    let dir = synth_dataset(300, 7);
    let mut settings = small_settings(SIZE[0], SIZE[1]);
    // Without timestamps terramp would time each pass by submitting it: not in a host's encoder.
    settings.gpu.timestamps = false;
    let mut r = renderer(&dir, settings);
    let pose = camera::over_fraction(&r, [0.45, 0.35], 25.0, 20.0, -10.0);
    let host = Host::new(&r.gpu.device);
    // The host never says it submitted: each frame's readbacks start at the next one.
    let (report, walled) = host.settled(&mut r, &pose, true, Submit::HostUnsaid);
    assert!(report.tlm_frame.is_some() && report.seeds.is_some(), "no readback came back");
    assert!(half(&walled, false).pixels().all(|p| p.0 == WALL), "the wall is covered somewhere");
    assert!(
        half(&walled, true).pixels().any(|p| p.0 != WALL && p.0 != [0, 0, 255, 255]),
        "terramp drew nothing"
    );
    let untimed = r.last_timings().iter().all(|t| t.source == TimeSource::Cpu);
    assert!(untimed, "a pass was timed by submitting it: {:?}", r.last_timings());

    // A frame without the wall, recorded: until the host submits it, the GPU has none of it.
    let mut encoder = r.gpu.device.create_command_encoder(&Default::default());
    host.record(&mut encoder, false);
    r.encode_frame(&pose, &mut encoder, &HostTargets { colour: &host.colour, depth: &host.depth }).unwrap();
    assert_eq!(differing_pixels(&host.colour(&r), &walled), 0, "drawn before the host's submit");
    r.gpu.queue.submit([encoder.finish()]);
    r.submitted();
    let unwalled = host.colour(&r);
    assert!(half(&unwalled, false).pixels().any(|p| p.0 != WALL), "the host's submit drew nothing");
}

#[test]
fn counting_fragments_is_refused_in_the_hosts_encoder() {
    let dir = synth_dataset(64, 3);
    let mut settings = small_settings(SIZE[0], SIZE[1]);
    settings.gpu.count_fragments = true;
    let mut r = renderer(&dir, settings);
    let pose = camera::over_fraction(&r, [0.5, 0.5], 50.0, 0.0, -10.0);
    let host = Host::new(&r.gpu.device);
    let mut encoder = r.gpu.device.create_command_encoder(&Default::default());
    let targets = HostTargets { colour: &host.colour, depth: &host.depth };
    let refused = r.encode_frame(&pose, &mut encoder, &targets).unwrap_err();
    println!("{refused}");
    assert!(matches!(refused, RenderError::FragmentsWait), "{refused}");
    // Nothing was recorded, and terramp's own submit still draws over the host's frame.
    r.gpu.queue.submit([encoder.finish()]);
    r.render_into(&pose, &targets).unwrap();
}
