//! A host with a window of its own (winit + wgpu) that draws its own geometry, cubes, with
//! terramp's terrain and trees around them, depth-correct, in one command encoder a frame.
//!
//! How it works: the host makes the instance, the window's surface, the adapter and the device
//! (with `needed_limits`), and hands terramp the device (`Gpu::from_host`). Each frame it clears
//! its own colour (sRGB, the surface's format) and reversed-Z depth, draws its cubes with the
//! camera's matrices (camera-relative: each cube's centre is subtracted from the camera in f64),
//! then lets terramp record its frame into the same encoder over those targets (`encode_frame`):
//! terramp culls and draws against the host's depth, so a cube hides the trees behind it and the
//! terrain hides a cube behind a ridge. The host submits, tells terramp (`submitted`), copies its
//! colour to the surface and presents. On a flat dataset grid metres are the camera-relative
//! frame's; on the round Earth a host places its geometry in the camera's local frame.
//!
//! ```text
//! cargo run --example winit_host -- [DATASET] [--settings FILE] [--camera X,Y,Z,YAW,PITCH]
//!     [--cube X,Y,Z,SIZE]... [--size WxH] [--frames N --save FRAME.png]
//! ```
//!
//! Without a dataset it synthesises a small one into the system's temporary directory first.
//! With `--save` it draws `--frames` frames, saves the last one and exits.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, Result, anyhow, bail};
use terramp::host::glam::{DVec3, Mat4};
use terramp::host::{
    Camera, DEPTH_FORMAT, Dataset, Gpu, HostTargets, Renderer, Settings, SynthParams, bytemuck,
    needed_limits, read_texture, synthesize, wgpu,
};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

const CUBE_WGSL: &str = include_str!("winit_host_cube.wgsl");

#[derive(Default)]
struct Args {
    dataset: Option<PathBuf>,
    camera: Option<String>,
    settings: Option<PathBuf>,
    cubes: Vec<[f64; 4]>,
    size: [u32; 2],
    frames: u32,
    save: Option<PathBuf>,
}

fn numbers(text: &str, n: usize, what: &str) -> Result<Vec<f64>> {
    let values: Vec<f64> = text.split(',').map(|v| v.trim().parse()).collect::<Result<_, _>>()?;
    if values.len() != n || !values.iter().all(|v| v.is_finite()) {
        bail!("{what}: {n} numbers, not `{text}`");
    }
    Ok(values)
}

fn parse_args() -> Result<Args> {
    let mut args = Args { size: [640, 360], frames: 60, ..Default::default() };
    let mut it = std::env::args().skip(1);
    while let Some(arg) = it.next() {
        let mut value = |name: &str| it.next().with_context(|| format!("{name} needs a value"));
        match arg.as_str() {
            "--camera" => args.camera = Some(value("--camera")?),
            "--settings" => args.settings = Some(PathBuf::from(value("--settings")?)),
            "--cube" => {
                let v = numbers(&value("--cube")?, 4, "--cube X,Y,Z,SIZE")?;
                args.cubes.push([v[0], v[1], v[2], v[3]]);
            }
            "--size" => {
                let text = value("--size")?;
                let (w, h) = text.split_once('x').with_context(|| format!("--size WxH, not `{text}`"))?;
                args.size = [w.parse()?, h.parse()?];
            }
            "--frames" => args.frames = value("--frames")?.parse().context("--frames: a whole number")?,
            "--save" => args.save = Some(PathBuf::from(value("--save")?)),
            flag if flag.starts_with("--") => bail!("unknown option {flag}"),
            path => args.dataset = Some(PathBuf::from(path)),
        }
    }
    Ok(args)
}

fn main() -> Result<()> {
    let args = parse_args()?;
    let Some(dir) = args.dataset.clone() else {
        let dir = std::env::temp_dir().join(format!("terramp-example-{}", std::process::id()));
        eprintln!("no dataset given: synthesising one into {}", dir.display());
        synthesize(&dir, &SynthParams { size: 256, ..Default::default() }, false)?;
        let ran = run(&dir, args);
        std::fs::remove_dir_all(&dir).with_context(|| format!("removing {}", dir.display()))?;
        return ran;
    };
    run(&dir, args)
}

fn run(dir: &Path, args: Args) -> Result<()> {
    let dataset = Dataset::open(dir).with_context(|| format!("opening {}", dir.display()))?;
    let event_loop = EventLoop::new().context("no display to open a window on")?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App { args, dataset: Some(dataset), host: None, error: None, drawn: 0 };
    event_loop.run_app(&mut app).context("the event loop failed")?;
    app.error.map_or(Ok(()), Err)
}

struct App {
    args: Args,
    dataset: Option<Dataset>,
    host: Option<Host>,
    error: Option<anyhow::Error>,
    drawn: u32,
}

/// Everything the host owns: its window, device, targets and cube pipeline, and terramp.
struct Host {
    window: Arc<Window>,
    device: wgpu::Device,
    queue: wgpu::Queue,
    surface: wgpu::Surface<'static>,
    colour: wgpu::Texture,
    depth: wgpu::Texture,
    cubes: wgpu::RenderPipeline,
    cube_bind: wgpu::BindGroup,
    cube_buffer: wgpu::Buffer,
    renderer: Renderer,
    camera: Camera,
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        let Some(dataset) = self.dataset.take() else { return };
        match Host::open(event_loop, &self.args, dataset) {
            Ok(host) => self.host = Some(host),
            Err(error) => {
                self.error = Some(error);
                event_loop.exit();
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        let Some(host) = self.host.as_mut() else { return };
        let result = match event {
            WindowEvent::CloseRequested => {
                event_loop.exit();
                Ok(())
            }
            WindowEvent::RedrawRequested => host.frame(&self.args.cubes).map(|()| self.drawn += 1),
            _ => Ok(()),
        };
        let done = self.args.save.as_ref().filter(|_| self.drawn >= self.args.frames);
        let result = match (result, done) {
            (Ok(()), Some(path)) => host.save(path).map(|()| event_loop.exit()),
            (result, _) => result,
        };
        if let Err(error) = result {
            self.error = Some(error);
            event_loop.exit();
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(host) = &self.host {
            host.window.request_redraw();
        }
    }
}

/// The colour and depth usages the host gives its targets: drawn into, and copied (the depth by
/// terramp, the colour to the surface and to a saved frame).
const TARGET: wgpu::TextureUsages = wgpu::TextureUsages::RENDER_ATTACHMENT
    .union(wgpu::TextureUsages::COPY_SRC)
    .union(wgpu::TextureUsages::COPY_DST);

impl Host {
    fn open(event_loop: &ActiveEventLoop, args: &Args, dataset: Dataset) -> Result<Self> {
        let [width, height] = args.size;
        let attributes = Window::default_attributes()
            .with_title("terramp inside a host")
            .with_inner_size(winit::dpi::PhysicalSize::new(width, height))
            .with_resizable(false);
        let window = Arc::new(event_loop.create_window(attributes)?);
        let display = Box::new(event_loop.owned_display_handle());
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(display));
        let surface = instance.create_surface(Arc::clone(&window))?;
        // The adapter `WGPU_ADAPTER_NAME` names, if set, else the default one for the surface.
        let adapter = pollster::block_on(wgpu::util::initialize_adapter_from_env_or_default(
            &instance,
            Some(&surface),
        ))?;
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("the host's device"),
            required_limits: needed_limits(),
            required_features: adapter.features() & wgpu::Features::INDIRECT_FIRST_INSTANCE,
            ..Default::default()
        }))?;
        let format = surface
            .get_capabilities(&adapter)
            .formats
            .into_iter()
            .find(wgpu::TextureFormat::is_srgb)
            .ok_or_else(|| anyhow!("the window's surface offers no sRGB format"))?;
        surface.configure(
            &device,
            &wgpu::SurfaceConfiguration {
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_DST,
                format,
                width,
                height,
                present_mode: wgpu::PresentMode::AutoNoVsync,
                desired_maximum_frame_latency: 2,
                alpha_mode: wgpu::CompositeAlphaMode::Auto,
                view_formats: vec![],
                color_space: wgpu::SurfaceColorSpace::Auto,
            },
        );
        let texture = |format, label| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: TARGET,
                view_formats: &[],
            })
        };
        let (colour, depth) =
            (texture(format, "the host's colour"), texture(DEPTH_FORMAT, "the host's depth"));
        let mut settings = Settings::load("balanced", args.settings.as_deref())?;
        (settings.render.width, settings.render.height) = (width, height);
        let gpu = Gpu::from_host(adapter, device.clone(), queue.clone());
        let renderer = Renderer::new(gpu, dataset, settings.clone())?;
        let camera = match &args.camera {
            Some(text) => {
                renderer.dataset.camera_from(text, settings.render.fov_deg, settings.render.near_m)?
            }
            None => default_camera(&renderer, &settings)?,
        };
        let (cubes, cube_bind, cube_buffer) = cube_pipeline(&device, format, args.cubes.len().max(1));
        Ok(Self {
            window,
            device,
            queue,
            surface,
            colour,
            depth,
            cubes,
            cube_bind,
            cube_buffer,
            renderer,
            camera,
        })
    }

    /// One frame: the host's cubes, terramp over them, the colour onto the window.
    fn frame(&mut self, cubes: &[[f64; 4]]) -> Result<()> {
        let [width, height] = [self.colour.width(), self.colour.height()];
        let clip_from_rel = self.camera.clip_from_view(width, height)? * self.camera.view_from_world();
        // Camera-relative in f64, then f32 for the GPU: the cubes stay put to the millimetre.
        let mut uniforms: Vec<f32> = clip_from_rel.as_mat4().to_cols_array().to_vec();
        for &[x, y, z, size] in cubes {
            let rel = DVec3::new(x, y, z) - self.camera.position_m;
            uniforms.extend([rel.x as f32, rel.y as f32, rel.z as f32, 0.5 * size as f32]);
        }
        self.queue.write_buffer(&self.cube_buffer, 0, bytemuck::cast_slice(&uniforms));
        let mut encoder = self.device.create_command_encoder(&Default::default());
        {
            let colour = self.colour.create_view(&Default::default());
            let depth = self.depth.create_view(&Default::default());
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("the host's cubes"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &colour,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &depth,
                    // Reversed-Z: the far plane is 0.
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(0.0),
                        store: wgpu::StoreOp::Store,
                    }),
                    stencil_ops: None,
                }),
                ..Default::default()
            });
            pass.set_pipeline(&self.cubes);
            pass.set_bind_group(0, &self.cube_bind, &[]);
            pass.draw(0..36, 0..cubes.len() as u32);
        }
        self.renderer.encode_frame(
            &self.camera,
            &mut encoder,
            &HostTargets { colour: &self.colour, depth: &self.depth },
        )?;
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => Some(t),
            _ => None,
        };
        if let Some(frame) = &frame {
            encoder.copy_texture_to_texture(
                self.colour.as_image_copy(),
                frame.texture.as_image_copy(),
                self.colour.size(),
            );
        }
        self.queue.submit([encoder.finish()]);
        self.renderer.submitted();
        if let Some(frame) = frame {
            self.window.pre_present_notify();
            self.queue.present(frame);
        }
        Ok(())
    }

    /// Saves the host's colour as a PNG.
    fn save(&self, path: &Path) -> Result<()> {
        let gpu = &self.renderer.gpu;
        let bytes = read_texture(gpu, &self.colour, wgpu::TextureAspect::All, 4)?;
        let [width, height] = [self.colour.width(), self.colour.height()];
        let bgra = matches!(self.colour.format(), wgpu::TextureFormat::Bgra8UnormSrgb);
        let rgba: Vec<u8> =
            if bgra { bytes.chunks(4).flat_map(|p| [p[2], p[1], p[0], p[3]]).collect() } else { bytes };
        let image = image::RgbaImage::from_raw(width, height, rgba).context("the frame's bytes")?;
        image.save(path).with_context(|| format!("saving {}", path.display()))
    }
}

/// A camera over the dataset's middle, looking north-east and down a little.
fn default_camera(renderer: &Renderer, settings: &Settings) -> Result<Camera> {
    let manifest = &renderer.dataset.manifest;
    let [w, h] = manifest.extent_m();
    let (x, y) = (0.4 * w, 0.35 * h);
    let ground_m = renderer.ground_at(x, y)?.height_m;
    let origin = manifest.origin_m;
    let pose = format!("{},{},{},45,-10", origin[0] + x, origin[1] + y, ground_m + 60.0);
    Ok(renderer.dataset.camera_from(&pose, settings.render.fov_deg, settings.render.near_m)?)
}

/// The cubes' pipeline: 36 vertices per cube, made in the shader from its centre and half size,
/// depth-tested reversed-Z and written, as the host's geometry.
fn cube_pipeline(
    device: &wgpu::Device,
    format: wgpu::TextureFormat,
    cubes: usize,
) -> (wgpu::RenderPipeline, wgpu::BindGroup, wgpu::Buffer) {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("cubes"),
        source: wgpu::ShaderSource::Wgsl(CUBE_WGSL.into()),
    });
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("cubes"),
        size: (std::mem::size_of::<Mat4>() + 16 * cubes.max(1)) as u64,
        usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("cubes"),
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
            targets: &[Some(format.into())],
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
    let bind = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("cubes"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }],
    });
    (pipeline, bind, buffer)
}
