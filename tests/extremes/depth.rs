//! Depth range: a near plane of 0.1 m and ground 500 km away share one Depth32Float buffer. The
//! projection is reversed-Z with an infinite far plane (`Camera::clip_from_view`), so a depth is
//! `near / distance`, and f32 keeps the same relative precision at every distance: surfaces a
//! hundred-thousandth of their distance apart stay distinct from 0.1 m to 500 km, in the f32
//! arithmetic the GPU does and on the rasteriser itself. Cameras 2 m and 100 / 500 km above the
//! ground render ground and sky where rays through the DEM say they must, and the depth they keep
//! puts every ground pixel back on the mesh: within 0.1 mm at 2 m, 2 cm at 100 km and 11 cm at
//! 500 km (f32 camera-relative vertices, a few ulps at that distance). A forward-Z projection over
//! the same range merges 930 254 of the 1 542 503 distance steps the first test walks.

use glam::{DVec3, Mat4, Vec4};
use terramp::camera::Camera;
use terramp::gpu::Gpu;
use terramp::passes::DEPTH_FORMAT;
use wgpu::util::DeviceExt;

use terramp_testkit::audit::{Dem, Tolerance, audit, camera_at};
use terramp_testkit::small_settings;

const NEAR_M: f64 = 0.1;
const FAR_M: f64 = 500_000.0;
/// Two surfaces this fraction of their distance apart must resolve at every distance.
const GAP: f64 = 1e-5;

fn level_camera() -> Camera {
    Camera {
        position_m: DVec3::ZERO,
        yaw_deg: 0.0,
        pitch_deg: 0.0,
        roll_deg: 0.0,
        fov_deg: 60.0,
        near_m: NEAR_M,
    }
}

/// Depth of a point `distance_m` straight ahead, as the GPU computes it: the f32 matrix times
/// the f32 camera-relative position, then z / w.
fn depth_f32(clip: &Mat4, distance_m: f64) -> f32 {
    let p = *clip * Vec4::new(0.0, distance_m as f32, 0.0, 1.0);
    p.z / p.w
}

#[test]
fn reversed_z_keeps_depths_distinct_from_10_cm_to_500_km() {
    let clip = level_camera().clip_from_view_world(320, 180).unwrap();
    // A conventional projection (depth 0 at the near plane, 1 at 500 km), for contrast.
    let forward_z =
        (glam::dcamera::rh::proj::directx::perspective(60f64.to_radians(), 320.0 / 180.0, NEAR_M, FAR_M)
            * level_camera().view_from_world())
        .as_mat4();
    let (mut d, mut steps, mut forward_collisions) = (NEAR_M, 0u64, 0u64);
    let (mut previous, mut previous_forward) = (depth_f32(&clip, d), depth_f32(&forward_z, d));
    assert!((previous - 1.0).abs() < 1e-6, "the near plane is at depth {previous}");
    while d < FAR_M {
        d *= 1.0 + GAP;
        let (depth, forward) = (depth_f32(&clip, d), depth_f32(&forward_z, d));
        assert!(depth < previous && depth > 0.0, "{d} m: depth {depth} after {previous}");
        forward_collisions += u64::from(forward <= previous_forward);
        (previous, previous_forward, steps) = (depth, forward, steps + 1);
    }
    println!(
        "{steps} distances {GAP:e} apart from {NEAR_M} m to {FAR_M} m: all distinct reversed (500 km at \
         {previous:e}); a forward-Z projection merges {forward_collisions} of them"
    );
    // The test can tell: without reversed-Z most of them would merge.
    assert!(forward_collisions > steps / 2, "{forward_collisions} of {steps}");
}

/// A test pipeline drawing flat-coloured triangles through the camera's f32 matrix into the
/// renderer's depth format, depth-tested as the terrain is (greater wins, cleared to 0).
struct Quads {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
}

const SHADER: &str = "
struct Uniforms { clip_from_view_world: mat4x4<f32> }
@group(0) @binding(0) var<uniform> u: Uniforms;
struct Out { @builtin(position) position: vec4<f32>, @location(0) colour: vec4<f32> }
@vertex fn vs(@location(0) p: vec3<f32>, @location(1) colour: vec4<f32>) -> Out {
    return Out(u.clip_from_view_world * vec4<f32>(p, 1.0), colour);
}
@fragment fn fs(v: Out) -> @location(0) vec4<f32> { return v.colour; }
";

const SIZE_PX: u32 = 64;

impl Quads {
    fn new(device: &wgpu::Device) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("quads"),
            source: wgpu::ShaderSource::Wgsl(SHADER.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: None,
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: None,
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("quads"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: 28,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x4],
                })],
            },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::TextureFormat::Rgba8Unorm.into())],
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
        Self { pipeline, layout }
    }

    /// Draws `quads` (distance ahead, RGBA) in order, each a square facing the camera and filling
    /// half the view's height, and returns the frame (row by row, RGBA8).
    fn draw(&self, gpu: &Gpu, clip: &Mat4, quads: &[(f64, [f32; 4])]) -> Vec<u8> {
        let device = &gpu.device;
        let half_angle = (0.5 * level_camera().fov_deg).to_radians().tan();
        let mut vertices: Vec<f32> = Vec::new();
        for &(distance_m, colour) in quads {
            let s = (0.5 * distance_m * half_angle) as f32;
            let y = distance_m as f32;
            for [x, z] in [[-s, -s], [s, -s], [s, s], [-s, -s], [s, s], [-s, s]] {
                vertices.extend_from_slice(&[x, y, z]);
                vertices.extend_from_slice(&colour);
            }
        }
        let vertex_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });
        let uniforms = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: None,
            contents: bytemuck::cast_slice(&clip.to_cols_array()),
            usage: wgpu::BufferUsages::UNIFORM,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: None,
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniforms.as_entire_binding() }],
        });
        let target = |format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d { width: SIZE_PX, height: SIZE_PX, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | usage,
                view_formats: &[],
            })
        };
        let colour = target(wgpu::TextureFormat::Rgba8Unorm, wgpu::TextureUsages::COPY_SRC);
        let depth = target(DEPTH_FORMAT, wgpu::TextureUsages::empty());
        let (colour_view, depth_view) =
            (colour.create_view(&Default::default()), depth.create_view(&Default::default()));
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: None,
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
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, &bind_group, &[]);
            pass.set_vertex_buffer(0, vertex_buffer.slice(..));
            pass.draw(0..(vertices.len() / 7) as u32, 0..1);
        }
        gpu.queue.submit([encoder.finish()]);
        terramp::gpu::readback::read_texture(gpu, &colour, wgpu::TextureAspect::All, 4).unwrap()
    }
}

#[test]
fn two_surfaces_close_together_resolve_from_20_cm_to_500_km() {
    let gpu = terramp_testkit::gpu();
    let quads = Quads::new(&gpu.device);
    let clip = level_camera().clip_from_view_world(SIZE_PX, SIZE_PX).unwrap();
    let (near, far) = ([255.0, 0.0, 0.0, 255.0].map(|v| v / 255.0), [0.0, 1.0, 0.0, 1.0]);
    for distance_m in [0.2, 1.0, 1_000.0, 50_000.0, FAR_M] {
        let behind_m = distance_m * (1.0 + GAP);
        for order in [[(behind_m, far), (distance_m, near)], [(distance_m, near), (behind_m, far)]] {
            let pixels = quads.draw(&gpu, &clip, &order);
            // The middle half of the frame: both quads cover it, the nearer must win everywhere.
            let (lo, hi) = (SIZE_PX / 4 + 1, 3 * SIZE_PX / 4 - 1);
            let mut lost = 0;
            for y in lo..hi {
                for x in lo..hi {
                    let p = &pixels[((y * SIZE_PX + x) * 4) as usize..][..4];
                    lost += usize::from(p != [255, 0, 0, 255]);
                }
            }
            let gap_m = behind_m - distance_m;
            assert_eq!(lost, 0, "{distance_m} m, {gap_m:.2e} m apart, drawn {:?} first", order[0].0);
        }
    }
}

#[test]
fn cameras_2_m_and_100_km_and_500_km_up_see_ground_and_sky_where_they_must() {
    let dataset = terramp_testkit::synth_dataset(256, 7);
    let mut r = terramp_testkit::renderer(&dataset, small_settings(320, 180));
    let dem = Dem::load(&r.dataset);
    let span = dem.span_m();
    let centre = [0.5 * span[0], 0.5 * span[1]];
    // (what, camera, the mesh's tolerance, whether sky shows).
    let views = [
        ("2 m up, level", camera_at(&r, &dem, [0.3 * span[0], 0.35 * span[1]], 2.0, 30.0, 0.0), 0.05, true),
        (
            "2 m up, 30° down",
            camera_at(&r, &dem, [0.6 * span[0], 0.4 * span[1]], 2.0, 200.0, -30.0),
            0.05,
            false,
        ),
        // High up, the field of view narrowed until the dataset (2.5 km) fills about half the frame.
        (
            "100 km up",
            Camera { fov_deg: 1.2, ..camera_at(&r, &dem, centre, 100_000.0, 0.0, -90.0) },
            0.1,
            false,
        ),
        (
            "100 km away, 60° down",
            Camera { fov_deg: 1.2, ..high_oblique(&r, &dem, centre, 100_000.0) },
            0.1,
            true,
        ),
        (
            "500 km away, 60° down",
            Camera { fov_deg: 0.25, ..high_oblique(&r, &dem, centre, FAR_M) },
            0.5,
            true,
        ),
    ];
    for (what, camera, height_m, sky) in views {
        r.render_resolved(&camera).unwrap();
        let a = audit(&r, &camera, &dem, Tolerance::flat(height_m, 20.0), 4);
        println!("{what}: {a:?}");
        a.assert_sound(what);
        assert!(a.expect_ground > 100 && a.ground_px > a.pixels / 5, "{what}: too little ground ({a:?})");
        if sky {
            assert!(a.expect_sky > 100 && a.ground_px < a.pixels * 9 / 10, "{what}: no sky ({a:?})");
        }
    }
}

/// A camera `distance_m` from grid point `target` (on the ground), 60° above it, looking at it.
fn high_oblique(r: &terramp::frame::Renderer, dem: &Dem, target: [f64; 2], distance_m: f64) -> Camera {
    let (down, yaw) = (60f64.to_radians(), 0.0f64);
    let ground = dem.mesh_height_m(target[0], target[1]);
    let back = distance_m * down.cos();
    let o = r.dataset.manifest.origin_m;
    Camera {
        position_m: DVec3::new(o[0] + target[0], o[1] + target[1] - back, ground + distance_m * down.sin()),
        yaw_deg: yaw,
        pitch_deg: -60.0,
        roll_deg: 0.0,
        fov_deg: 60.0,
        near_m: NEAR_M,
    }
}
