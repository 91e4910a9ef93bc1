//! The display pass (`shaders/display.wgsl`) against its twin (`reference::display`): light from
//! 12 stops under white ground to the sun's disk, grey and coloured, through every tone curve
//! and at two exposures, as the GPU shows it and as the twin computes it; and the same light
//! shown over a host's colour (`fs_display_over`) at coverages from none to whole, and written
//! exposed over a host's linear HDR colour (`fs_display_over_linear`).
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::Vec3;
use terramp::config::{DisplaySettings, ToneCurve};
use terramp::gpu::readback::read_texture;
use terramp::passes::display::gpu::DisplayPass;
use terramp::passes::display::uniforms;
use terramp::passes::{COLOUR_FORMAT, DISPLAY_FORMAT, HOST_HDR_FORMAT};
use terramp::reference::display::{exposed_over, shown, shown_over, tone};
use terramp::texcell::pyramid::{decode_srgb, encode_srgb};
use terramp_testkit::{gpu, texture_2d};

/// The GPU's displayed pixels against the twin's, 8-bit levels (the adapter's log2 and pow, and
/// its rounding to 8 bits).
const DISPLAY_LEVELS: i32 = 1;

/// Light steps per row: 2^(k / 16 − 12) for k in 0..`STEPS`, up to 2^18.
const STEPS: u32 = 481;

/// The rows' hues: grey, then saturated red, green, blue and a foliage green.
const HUES: [[f32; 3]; 5] =
    [[1.0, 1.0, 1.0], [1.0, 0.05, 0.02], [0.03, 1.0, 0.05], [0.02, 0.04, 1.0], [0.25, 0.45, 0.12]];

/// The light's coverage per row, for the display over a host's colour.
const COVERAGES: [f32; 5] = [0.0, 0.2, 0.5, 0.8, 1.0];

/// The host's colour under the display, sRGB.
const UNDER: [u8; 4] = [200, 120, 60, 255];

/// The GPU's exposed light over a host's linear HDR colour against the twin's, both rounded to
/// half floats, relative to it, in f16's relative steps of 2^-11 (the blend's own rounding).
const HDR_STEPS: f32 = 4.0;

/// Where `displayed` draws: the display target, or over a host's colour of `DISPLAY_FORMAT` or
/// `HOST_HDR_FORMAT` that starts as `UNDER`.
#[derive(Clone, Copy, PartialEq)]
enum Target {
    Display,
    Over(wgpu::TextureFormat),
}

/// A row per hue of light steps, as the colour target holds it (f16: past 65,504, infinite, as
/// the sun's disk might be).
fn light_steps() -> Vec<Vec3> {
    let f16 = |v: f32| half::f16::from_f32(v).to_f32();
    (0..HUES.len())
        .flat_map(|row| {
            (0..STEPS).map(move |k| Vec3::from_array(HUES[row]) * ((k as f32) / 16.0 - 12.0).exp2())
        })
        .map(|l| Vec3::from_array(l.to_array().map(f16)))
        .collect()
}

/// A display on the GPU over `light`, premultiplied by its row's coverage when over a host's
/// colour (each row of `STEPS`), into a target that starts as `UNDER` everywhere; its bytes.
fn displayed(settings: &DisplaySettings, light: &[Vec3], daylight: Vec3, target: Target) -> Vec<u8> {
    let over = target != Target::Display;
    let format = match target {
        Target::Display => DISPLAY_FORMAT,
        Target::Over(format) => format,
    };
    let gpu = gpu();
    let device = &gpu.device;
    let (width, height) = (STEPS, HUES.len() as u32);
    let texels: Vec<u16> = light
        .iter()
        .enumerate()
        .flat_map(|(i, l)| {
            let a = if over { COVERAGES[i / STEPS as usize] } else { 1.0 };
            [l.x * a, l.y * a, l.z * a, a].map(|v| half::f16::from_f32(v).to_bits())
        })
        .collect();
    let copy_dst = wgpu::TextureUsages::COPY_DST;
    let scene =
        texture_2d(device, [width, height], COLOUR_FORMAT, wgpu::TextureUsages::TEXTURE_BINDING | copy_dst);
    let write = |texture: &wgpu::Texture, bytes: &[u8], texel_bytes: u32| {
        let layout = wgpu::TexelCopyBufferLayout {
            offset: 0,
            bytes_per_row: Some(width * texel_bytes),
            rows_per_image: None,
        };
        gpu.queue.write_texture(texture.as_image_copy(), bytes, layout, texture.size());
    };
    write(&scene, bytemuck::cast_slice(&texels), 8);
    let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC | copy_dst;
    let display = texture_2d(device, [width, height], format, usage);
    let texel_bytes = format.block_copy_size(None).unwrap();
    if format == HOST_HDR_FORMAT {
        let under = UNDER.map(decode_srgb).map(|v| half::f16::from_f32(v).to_bits());
        let under = [under[0], under[1], under[2], half::f16::ONE.to_bits()];
        write(&display, bytemuck::cast_slice(&under.repeat(light.len())), texel_bytes);
    } else {
        write(&display, &UNDER.repeat(light.len()), texel_bytes);
    }
    let daylight_buffer = wgpu::util::DeviceExt::create_buffer_init(
        device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("daylight"),
            contents: bytemuck::cast_slice(&daylight.extend(1.0).to_array()),
            usage: wgpu::BufferUsages::UNIFORM,
        },
    );
    let mut pass =
        DisplayPass::new(&gpu, settings, &scene.create_view(&Default::default()), &daylight_buffer);
    let mut encoder = device.create_command_encoder(&Default::default());
    let (display_view, off) =
        (display.create_view(&Default::default()), terramp::gpu::counter::Counting::OFF);
    if over {
        pass.prepare_over(device, format);
        pass.encode_over(&mut encoder, &display_view, off);
    } else {
        pass.encode(&mut encoder, &display_view, off);
    }
    gpu.queue.submit([encoder.finish()]);
    read_texture(&gpu, &display, wgpu::TextureAspect::All, texel_bytes).unwrap()
}

/// The largest difference between `shown_gpu` and the twin's `expected` display light, 8-bit
/// levels, and the index of the light where it is.
fn worst(shown_gpu: &[u8], expected: impl Iterator<Item = Vec3>) -> (i32, usize) {
    let (mut worst, mut at) = (0, 0);
    for (i, e) in expected.enumerate() {
        let e = e.to_array().map(encode_srgb);
        for c in 0..3 {
            let off = (i32::from(shown_gpu[i * 4 + c]) - i32::from(e[c])).abs();
            if off > worst {
                (worst, at) = (off, i);
            }
        }
    }
    (worst, at)
}

/// A daylight balance of the model's order (bluer light is weaker, so blue's gain is larger).
const DAYLIGHT: Vec3 = Vec3::new(1.48, 1.58, 1.67);

#[test]
fn the_gpu_displays_the_twins_light_through_every_curve() {
    let light = light_steps();
    for curve in ToneCurve::ALL {
        for ev100 in [15.0, 9.0] {
            let settings = DisplaySettings { ev100, tone_curve: curve };
            let shown_gpu = displayed(&settings, &light, DAYLIGHT, Target::Display);
            let u = uniforms(&settings);
            let (worst, at) = worst(&shown_gpu, light.iter().map(|l| shown(&u, curve, DAYLIGHT, *l)));
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

#[test]
fn over_a_hosts_colour_the_gpu_shows_the_twins_light_by_its_coverage() {
    let light = light_steps();
    let under = Vec3::from_array([UNDER[0], UNDER[1], UNDER[2]].map(decode_srgb));
    for curve in ToneCurve::ALL {
        let settings = DisplaySettings { ev100: 15.0, tone_curve: curve };
        let shown_gpu = displayed(&settings, &light, DAYLIGHT, Target::Over(DISPLAY_FORMAT));
        let u = uniforms(&settings);
        let expected = premultiplied(&light).map(|lit| shown_over(&u, curve, DAYLIGHT, lit, under));
        let (worst, at) = worst(&shown_gpu, expected);
        println!(
            "{} over the host's colour: worst {worst} levels (light {}, row {})",
            curve.name(),
            light[at],
            at / STEPS as usize
        );
        assert!(worst <= DISPLAY_LEVELS, "{}: {worst} levels at light {}", curve.name(), light[at]);
        // Where terramp drew nothing the host's pixel is as it was.
        assert!(shown_gpu[..STEPS as usize * 4].chunks(4).all(|p| p == UNDER));
    }
}

/// The light premultiplied by its row's coverage as the colour target holds it, and the coverage.
fn premultiplied(light: &[Vec3]) -> impl Iterator<Item = (Vec3, f32)> + '_ {
    let f16 = |v: f32| half::f16::from_f32(v).to_f32();
    light.iter().enumerate().map(move |(i, l)| {
        let a = COVERAGES[i / STEPS as usize];
        (Vec3::from_array((*l * a).to_array().map(f16)), f16(a))
    })
}

#[test]
fn over_a_hosts_linear_hdr_colour_the_gpu_writes_the_twins_exposed_light() {
    let light = light_steps();
    let under = Vec3::from_array([UNDER[0], UNDER[1], UNDER[2]].map(decode_srgb));
    let f16 = |v: f32| half::f16::from_f32(v).to_f32();
    for curve in ToneCurve::ALL {
        for ev100 in [15.0, 9.0] {
            let settings = DisplaySettings { ev100, tone_curve: curve };
            let bytes = displayed(&settings, &light, DAYLIGHT, Target::Over(HOST_HDR_FORMAT));
            let hdr: Vec<f32> = bytemuck::cast_slice::<u8, u16>(&bytes)
                .iter()
                .map(|&b| half::f16::from_bits(b).to_f32())
                .collect();
            let u = uniforms(&settings);
            let (mut worst, mut at) = (0.0f32, 0);
            for (i, lit) in premultiplied(&light).enumerate() {
                let expected = exposed_over(&u, DAYLIGHT, lit, under).to_array().map(f16);
                for c in 0..3 {
                    let (gpu, twin) = (hdr[i * 4 + c], expected[c]);
                    let off = if gpu == twin { 0.0 } else { (gpu - twin).abs() / twin.abs().max(1e-4) };
                    if off > worst || off.is_nan() {
                        (worst, at) = (off, i);
                    }
                }
            }
            println!(
                "{} at EV100 {ev100}, linear HDR: worst {worst:.2e} relative (light {})",
                curve.name(),
                light[at]
            );
            assert!(
                worst <= HDR_STEPS / 2048.0,
                "{} at EV100 {ev100}: {worst} at light {}",
                curve.name(),
                light[at]
            );
            assert!(hdr.iter().all(|v| v.is_finite()), "the host gets infinity or NaN");
            // Where terramp drew nothing the host's pixel is as it was; the tone curve changes nothing.
            assert!(hdr[..STEPS as usize * 4].chunks(4).all(|p| p[..3] == under.to_array().map(f16)));
        }
    }
}

#[test]
fn the_linear_hdr_light_through_the_twins_curve_is_what_the_display_ready_target_shows() {
    // Where terramp covers the pixel whole, the host's curve over the exposed light (here the
    // twin's) and terramp's display-ready output must agree: the two targets, one frame's light.
    let light = light_steps();
    let whole = (COVERAGES.len() - 1) * STEPS as usize;
    for curve in [ToneCurve::Agx, ToneCurve::Aces] {
        let settings = DisplaySettings { ev100: 15.0, tone_curve: curve };
        let u = uniforms(&settings);
        let ready = displayed(&settings, &light, DAYLIGHT, Target::Over(DISPLAY_FORMAT));
        let bytes = displayed(&settings, &light, DAYLIGHT, Target::Over(HOST_HDR_FORMAT));
        let hdr: Vec<f32> = bytemuck::cast_slice::<u8, u16>(&bytes)
            .iter()
            .map(|&b| half::f16::from_bits(b).to_f32())
            .collect();
        let toned = (whole..light.len())
            .map(|i| tone(&u, curve, Vec3::new(hdr[i * 4], hdr[i * 4 + 1], hdr[i * 4 + 2])));
        let (worst, at) = worst(&ready[whole * 4..], toned);
        println!(
            "{}: the HDR light through the curve against the display-ready target: worst {worst} levels",
            curve.name()
        );
        assert!(
            worst <= DISPLAY_LEVELS + 1,
            "{}: {worst} levels at light {}",
            curve.name(),
            light[whole + at]
        );
    }
}
