//! How it works: the window's side of the viewer. The renderer draws into its own colour target
//! at the window's size in physical pixels; the screen shows it as egui's background (sampled as
//! plain bytes, `Renderer::display_bytes_view`, nearest texel, into a non-sRGB surface, so the
//! window shows the renderer's bytes unchanged) and draws egui's overlay over it, in one render
//! pass onto the surface's texture, then presents. A lost or outdated surface is configured
//! again and the frame skipped; HiDPI is egui's pixels per point, from the window's scale factor.

use std::sync::Arc;

use anyhow::{Context, Result, bail};
use winit::window::Window;

use terramp::frame::Renderer;
use terramp::gpu::Gpu;
use terramp::gpu::readback_ring::ReadbackRing;

/// The GPU time of the screen's pass (the frame shown, the overlay over it): two timestamps
/// around it, read back a frame or two later without waiting.
struct PassTimer {
    queries: wgpu::QuerySet,
    resolved: wgpu::Buffer,
    readback: ReadbackRing<()>,
    /// Nanoseconds per timestamp tick.
    period_ns: f64,
}

impl PassTimer {
    fn new(gpu: &Gpu) -> Option<Self> {
        if !gpu.device.features().contains(wgpu::Features::TIMESTAMP_QUERY) {
            return None;
        }
        let queries = gpu.device.create_query_set(&wgpu::QuerySetDescriptor {
            label: Some("view pass timer"),
            ty: wgpu::QueryType::Timestamp,
            count: 2,
        });
        let resolved = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("view pass timestamps"),
            size: 16,
            usage: wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let readback = ReadbackRing::new(&gpu.device, "view pass timestamps", 16, 3);
        Some(Self { queries, resolved, readback, period_ns: f64::from(gpu.queue.get_timestamp_period()) })
    }
}

/// The window, its surface and the overlay's painter.
pub struct Screen {
    pub window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    pub egui: egui::Context,
    pub input: egui_winit::State,
    painter: egui_wgpu::Renderer,
    /// The renderer's colour target as egui sees it.
    frame_texture: egui::TextureId,
    timer: Option<PassTimer>,
    /// The latest GPU time of the screen's pass that has come back, ms.
    pub pass_gpu_ms: Option<f64>,
    /// CPU time of the latest frame's overlay: egui's pass, tessellation and uploads, ms.
    pub overlay_cpu_ms: f64,
}

impl Screen {
    /// The screen of `window`, whose surface `gpu` presents to; shows `renderer`'s frames.
    pub fn new(
        window: Arc<Window>,
        surface: wgpu::Surface<'static>,
        gpu: &Gpu,
        renderer: &Renderer,
        vsync: bool,
    ) -> Result<Self> {
        let caps = surface.get_capabilities(&gpu.adapter);
        // A plain (non-sRGB) 8-bit format shows the renderer's sRGB bytes as they are.
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| matches!(f, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm))
            .or_else(|| caps.formats.first().copied())
            .context("the window's surface offers no format to draw in")?;
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: if vsync { wgpu::PresentMode::AutoVsync } else { wgpu::PresentMode::AutoNoVsync },
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
            color_space: wgpu::SurfaceColorSpace::Auto,
        };
        surface.configure(&gpu.device, &config);
        let egui = egui::Context::default();
        // Shadows are wide blended margins: on a software rasteriser they cost more than the text.
        egui.all_styles_mut(|style| {
            style.visuals.window_shadow = egui::Shadow::NONE;
            style.visuals.popup_shadow = egui::Shadow::NONE;
        });
        let max_side = gpu.device.limits().max_texture_dimension_2d as usize;
        let input = egui_winit::State::new(
            egui.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            window.theme(),
            Some(max_side),
        );
        let options = egui_wgpu::RendererOptions { dithering: false, ..Default::default() };
        let mut painter = egui_wgpu::Renderer::new(&gpu.device, format, options);
        let frame_texture = painter.register_native_texture(
            &gpu.device,
            &renderer.display_bytes_view(),
            wgpu::FilterMode::Nearest,
        );
        let timer = PassTimer::new(gpu);
        Ok(Self {
            window,
            surface,
            config,
            egui,
            input,
            painter,
            frame_texture,
            timer,
            pass_gpu_ms: None,
            overlay_cpu_ms: 0.0,
        })
    }

    /// The window's size in physical pixels (at least 1 × 1).
    pub fn size_px(&self) -> [u32; 2] {
        let s = self.window.inner_size();
        [s.width.max(1), s.height.max(1)]
    }

    /// Configures the surface for the window's current size.
    pub fn resized(&mut self, gpu: &Gpu) {
        let [w, h] = self.size_px();
        if [self.config.width, self.config.height] != [w, h] {
            self.config.width = w;
            self.config.height = h;
            self.surface.configure(&gpu.device, &self.config);
        }
    }

    /// Shows the colour target of a renderer just (re)made.
    pub fn rebind(&mut self, gpu: &Gpu, renderer: &Renderer) {
        self.painter.update_egui_texture_from_wgpu_texture(
            &gpu.device,
            &renderer.display_bytes_view(),
            wgpu::FilterMode::Nearest,
            self.frame_texture,
        );
    }

    /// Runs egui for one frame, `ui` drawing the overlay over the renderer's frame (stretched
    /// over the window while a remake to its new size waits), and presents it. Returns what `ui`
    /// returned (in the last pass, when egui asks for two), or `None` when the surface had no
    /// texture to give this time.
    pub fn present<T>(&mut self, gpu: &Gpu, mut ui: impl FnMut(&egui::Context) -> T) -> Result<Option<T>> {
        let frame = match self.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.configure(&gpu.device, &self.config);
                return Ok(None);
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => return Ok(None),
            wgpu::CurrentSurfaceTexture::Validation => bail!("the window's surface refused a frame"),
        };
        let overlay_start = std::time::Instant::now();
        let raw = self.input.take_egui_input(&self.window);
        let texture = self.frame_texture;
        let mut result = None;
        let output = self.egui.run_pass(raw, |ctx| {
            let screen = ctx.content_rect();
            let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
            ctx.layer_painter(egui::LayerId::background()).image(texture, screen, uv, egui::Color32::WHITE);
            result = Some(ui(ctx));
        });
        self.input.handle_platform_output(&self.window, output.platform_output);
        let jobs = self.egui.tessellate(output.shapes, output.pixels_per_point);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [self.config.width, self.config.height],
            pixels_per_point: output.pixels_per_point,
        };
        // Every delta must be taken (egui checks): set now, freed after the frame.
        let mut textures = output.textures_delta;
        for (id, deltas) in textures.set.drain() {
            for delta in &deltas {
                self.painter.update_texture(&gpu.device, &gpu.queue, id, delta);
            }
        }
        let mut encoder = gpu.device.create_command_encoder(&Default::default());
        let mut commands = self.painter.update_buffers(&gpu.device, &gpu.queue, &mut encoder, &jobs, &screen);
        self.overlay_cpu_ms = overlay_start.elapsed().as_secs_f64() * 1000.0;
        let view = frame.texture.create_view(&Default::default());
        let timestamp_writes = self.timer.as_ref().map(|t| wgpu::RenderPassTimestampWrites {
            query_set: &t.queries,
            beginning_of_pass_write_index: Some(0),
            end_of_pass_write_index: Some(1),
        });
        {
            let mut pass = encoder
                .begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some("view overlay"),
                    color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                        view: &view,
                        resolve_target: None,
                        depth_slice: None,
                        ops: wgpu::Operations {
                            load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                            store: wgpu::StoreOp::Store,
                        },
                    })],
                    timestamp_writes,
                    ..Default::default()
                })
                .forget_lifetime();
            self.painter.render(&mut pass, &jobs, &screen);
        }
        if let Some(t) = self.timer.as_mut() {
            encoder.resolve_query_set(&t.queries, 0..2, &t.resolved, 0);
            t.readback.encode_copy(&mut encoder, &t.resolved, 16, ());
        }
        commands.push(encoder.finish());
        gpu.queue.submit(commands);
        if let Some(t) = self.timer.as_mut() {
            t.readback.submitted();
            while let Some(done) = t.readback.try_take(&gpu.device)? {
                let [start, end] = <[u64; 2]>::try_from(done.cast::<u64>()).unwrap_or_default();
                self.pass_gpu_ms = Some(end.saturating_sub(start) as f64 * t.period_ns * 1e-6);
            }
        }
        self.window.pre_present_notify();
        gpu.queue.present(frame);
        for id in textures.free.drain() {
            self.painter.free_texture(&id);
        }
        Ok(result)
    }
}
