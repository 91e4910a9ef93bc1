//! The display pass (`shaders/display.wgsl`) against its twin (`reference::display`): light from
//! 12 stops under white ground to the sun's disk, grey and coloured, through every tone curve
//! and at two exposures, as the GPU shows it and as the twin computes it.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::Vec3;
use terramp::config::{DisplaySettings, ToneCurve};
use terramp::gpu::readback::read_texture;
use terramp::passes::display::gpu::DisplayPass;
use terramp::passes::display::uniforms;
use terramp::passes::{COLOUR_FORMAT, DISPLAY_FORMAT};
use terramp::reference::display::shown;
use terramp::texcell::pyramid::encode_srgb;
use terramp_testkit::gpu;

/// The GPU's displayed pixels against the twin's, 8-bit levels (the adapter's log2 and pow, and
/// its rounding to 8 bits).
const DISPLAY_LEVELS: i32 = 1;

/// Light steps per row: 2^(k / 16 − 12) for k in 0..`STEPS`, up to 2^18.
const STEPS: u32 = 481;

/// The rows' hues: grey, then saturated red, green, blue and a foliage green.
const HUES: [[f32; 3]; 5] =
    [[1.0, 1.0, 1.0], [1.0, 0.05, 0.02], [0.03, 1.0, 0.05], [0.02, 0.04, 1.0], [0.25, 0.45, 0.12]];

#[test]
fn the_gpu_displays_the_twins_light_through_every_curve() {
    let gpu = gpu();
    let device = &gpu.device;
    let (width, height) = (STEPS, HUES.len() as u32);
    // As the colour target holds it: f16 (past 65,504, infinite, as the sun's disk might be).
    let f16 = |v: f32| half::f16::from_f32(v).to_f32();
    let light: Vec<Vec3> = (0..height)
        .flat_map(|row| {
            (0..width).map(move |k| Vec3::from_array(HUES[row as usize]) * ((k as f32) / 16.0 - 12.0).exp2())
        })
        .map(|l| Vec3::from_array(l.to_array().map(f16)))
        .collect();
    let texels: Vec<u16> =
        light.iter().flat_map(|l| [l.x, l.y, l.z, 1.0].map(|v| half::f16::from_f32(v).to_bits())).collect();
    let target = |label, format, usage| {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage,
            view_formats: &[],
        })
    };
    let scene =
        target("scene", COLOUR_FORMAT, wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST);
    gpu.queue.write_texture(
        scene.as_image_copy(),
        bytemuck::cast_slice(&texels),
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(width * 8), rows_per_image: None },
        scene.size(),
    );
    let display = target(
        "display",
        DISPLAY_FORMAT,
        wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
    );
    // A daylight balance of the model's order (bluer light is weaker, so blue's gain is larger).
    let daylight = Vec3::new(1.48, 1.58, 1.67);
    let daylight_buffer = wgpu::util::DeviceExt::create_buffer_init(
        device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("daylight"),
            contents: bytemuck::cast_slice(&daylight.extend(1.0).to_array()),
            usage: wgpu::BufferUsages::UNIFORM,
        },
    );
    let scene_view = scene.create_view(&Default::default());
    let display_view = display.create_view(&Default::default());
    for curve in ToneCurve::ALL {
        for ev100 in [15.0, 9.0] {
            let settings = DisplaySettings { ev100, tone_curve: curve };
            let pass = DisplayPass::new(&gpu, &settings, &scene_view, &daylight_buffer);
            let mut encoder = device.create_command_encoder(&Default::default());
            pass.encode(&mut encoder, &display_view, terramp::gpu::counter::Counting::OFF);
            gpu.queue.submit([encoder.finish()]);
            let shown_gpu = read_texture(&gpu, &display, wgpu::TextureAspect::All, 4).unwrap();
            let u = uniforms(&settings);
            let (mut worst, mut at) = (0, 0);
            for (i, l) in light.iter().enumerate() {
                let expected = shown(&u, curve, daylight, *l).to_array().map(encode_srgb);
                for c in 0..3 {
                    let off = (i32::from(shown_gpu[i * 4 + c]) - i32::from(expected[c])).abs();
                    if off > worst {
                        (worst, at) = (off, i);
                    }
                }
            }
            println!("{} at EV100 {ev100}: worst {worst} levels (light {})", curve.name(), light[at]);
            assert!(
                worst <= DISPLAY_LEVELS,
                "{} at EV100 {ev100}: {worst} levels at light {}",
                curve.name(),
                light[at]
            );
        }
    }
}
