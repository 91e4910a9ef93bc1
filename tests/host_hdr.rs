//! A host's linear HDR colour (`HOST_HDR_FORMAT`): terramp writes its light exposed, through no
//! tone curve, for the host's own. The same settled view drawn into a display-ready (sRGB) host
//! target and into a linear HDR one: the HDR frame brought through the display's tone curve on
//! the CPU (the twin's `tone`) is the display-ready frame, where terramp covers each pixel whole
//! (everywhere here: the host draws nothing, and the sky is terramp's). The control, the HDR
//! frame shown without the curve (clamped and encoded), must fail.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::Vec3;
use terramp::camera::Camera;
use terramp::frame::{HostTargets, Renderer};
use terramp::gpu::readback::read_texture;
use terramp::passes::display::uniforms;
use terramp::passes::{DEPTH_FORMAT, HOST_HDR_FORMAT};
use terramp::reference::display::tone;
use terramp::texcell::pyramid::encode_srgb;
use terramp_testkit::{camera, renderer, small_settings, synth_dataset, texture_2d};

const SIZE: [u32; 2] = [256, 144];
/// The HDR frame through the twin's curve against the display-ready frame, 8-bit levels: the
/// display's own 1 level against its twin, and f16's rounding of the exposed light.
const TONED_LEVELS: i32 = 2;
/// Least share of pixels the control (no curve) must put further off than `TONED_LEVELS`.
const CONTROL_SHARE: f64 = 0.5;

const TARGET: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::COPY_SRC)
    .union(wgpu::TextureUsages::COPY_DST);

/// The settled view drawn over a host's colour of `format`, cleared to black, and a depth cleared
/// to the far plane; the colour's bytes.
fn host_frame(r: &mut Renderer, pose: &Camera, format: wgpu::TextureFormat) -> Vec<u8> {
    let device = r.gpu.device.clone();
    let colour = texture_2d(&device, SIZE, format, TARGET);
    let depth = texture_2d(&device, SIZE, DEPTH_FORMAT, TARGET);
    r.render_resolved(pose).unwrap();
    let mut encoder = device.create_command_encoder(&Default::default());
    let (colour_view, depth_view) =
        (colour.create_view(&Default::default()), depth.create_view(&Default::default()));
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("the host's clear"),
        color_attachments: &[Some(wgpu::RenderPassColorAttachment {
            view: &colour_view,
            depth_slice: None,
            resolve_target: None,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                store: wgpu::StoreOp::Store,
            },
        })],
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: &depth_view,
            depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(0.0), store: wgpu::StoreOp::Store }),
            stencil_ops: None,
        }),
        ..Default::default()
    });
    r.gpu.queue.submit([encoder.finish()]);
    r.render_into(pose, &HostTargets { colour: &colour, depth: &depth }).unwrap();
    let texel_bytes = format.block_copy_size(None).unwrap();
    read_texture(&r.gpu, &colour, wgpu::TextureAspect::All, texel_bytes).unwrap()
}

#[test]
fn the_linear_hdr_frame_through_the_display_curve_is_the_display_ready_frame() {
    let dir = synth_dataset(300, 7);
    let mut r = renderer(&dir, small_settings(SIZE[0], SIZE[1]));
    let pose = camera::over_fraction(&r, [0.45, 0.35], 120.0, 20.0, -5.0);
    let ready = host_frame(&mut r, &pose, wgpu::TextureFormat::Rgba8UnormSrgb);
    let hdr_bytes = host_frame(&mut r, &pose, HOST_HDR_FORMAT);
    let hdr: Vec<f32> = bytemuck::cast_slice::<u8, u16>(&hdr_bytes)
        .iter()
        .map(|&b| half::f16::from_bits(b).to_f32())
        .collect();
    let display = &r.settings.display;
    let u = uniforms(display);
    let (mut worst, mut control_off, mut brightest) = (0, 0usize, 0.0f32);
    for (i, pixel) in hdr.chunks(4).enumerate() {
        assert!(pixel.iter().all(|v| v.is_finite()), "pixel {i}: {pixel:?}");
        assert!((pixel[3] - 1.0).abs() < 1e-3, "pixel {i} is not terramp's whole: coverage {}", pixel[3]);
        let light = Vec3::new(pixel[0], pixel[1], pixel[2]);
        brightest = brightest.max(light.max_element());
        let toned = tone(&u, display.tone_curve, light).to_array().map(encode_srgb);
        let raw = light.clamp(Vec3::ZERO, Vec3::ONE).to_array().map(encode_srgb);
        let shown = &ready[i * 4..i * 4 + 3];
        let off = |e: [u8; 3]| (0..3).map(|c| (i32::from(shown[c]) - i32::from(e[c])).abs()).max().unwrap();
        worst = worst.max(off(toned));
        control_off += usize::from(off(raw) > TONED_LEVELS);
    }
    let pixels = hdr.len() / 4;
    let control_share = control_off as f64 / pixels as f64;
    println!(
        "{pixels} pixels through {}: worst {worst} levels off the display-ready frame; without the curve \
         {:.1} % further than {TONED_LEVELS}; the brightest exposed light {brightest}",
        display.tone_curve.name(),
        100.0 * control_share
    );
    assert!(worst <= TONED_LEVELS, "{worst} levels");
    assert!(control_share >= CONTROL_SHARE, "the control passes: {control_share}");
}
