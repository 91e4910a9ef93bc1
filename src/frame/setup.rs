//! How it works: what a renderer makes once, before its first frame: the render targets (checked
//! against the adapter's limits, so a bad viewport is an error here rather than a GPU error
//! later) and the three tile caches, whose coarsest levels load now, synchronously, because every
//! later frame falls back on them. Block-compressed imagery goes to a cache of its own format
//! where the adapter samples it, else to an RGBA8 cache that the loader feeds decoded tiles.

use crate::config::Settings;
use crate::dataset::{Dataset, IMAGERY_MIPS, LayerPack, LayerSpec};
use crate::gpu::Gpu;
use crate::gpu::layout::MAX_LEVELS;
use crate::passes::seed_select::march::BLOCK_TOPS;
use crate::passes::{COLOUR_FORMAT, DEPTH_FORMAT, DISPLAY_FORMAT};
use crate::streaming::loader::imagery_tile;
use crate::streaming::wants::pinned_tiles;
use crate::streaming::{Delivery, LayerKind, TileCache};

use super::{Caches, RenderError, Renderer, Targets};
use crate::camera::CameraError;
use crate::gpu::fragments::FragmentCounter;
use crate::passes::depth_pyramid::gpu::DepthPyramid;
use crate::passes::tile_load_map::frame::height_tile_ranges;

/// Tiles of the coarsest levels each cache keeps resident from the start, at most: the three
/// coarsest levels of a square layer (1 + 4 + 16), a fallback everywhere at a quarter of the
/// finest pinned detail, for a few MiB.
const MAX_PINNED_TILES: usize = 21;

impl Targets {
    /// The colour, depth and display targets of `settings.render`'s size.
    pub(super) fn new(device: &wgpu::Device, settings: &Settings) -> Result<Self, RenderError> {
        let (width, height, max) =
            (settings.render.width, settings.render.height, device.limits().max_texture_dimension_2d);
        if width == 0 || height == 0 {
            return Err(CameraError::Viewport(width, height).into());
        }
        if width.max(height) > max {
            return Err(RenderError::ViewportTooLarge { width, height, max });
        }
        let target = |label, format, view_formats: &[wgpu::TextureFormat]| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                // Copied into as well: a host's depth is (`Renderer::render_into`).
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT
                    | wgpu::TextureUsages::TEXTURE_BINDING
                    | wgpu::TextureUsages::COPY_SRC
                    | wgpu::TextureUsages::COPY_DST,
                view_formats,
            })
        };
        let colour = target("colour", COLOUR_FORMAT, &[]);
        let depth = target("depth", DEPTH_FORMAT, &[]);
        // A window samples the display's bytes as they are (`Renderer::display_bytes_view`).
        let display = target("display", DISPLAY_FORMAT, &[DISPLAY_FORMAT.remove_srgb_suffix()]);
        let [colour_view, depth_view, display_view] =
            [&colour, &depth, &display].map(|t| t.create_view(&Default::default()));
        Ok(Self { colour, depth, display, colour_view, depth_view, display_view })
    }
}

impl Renderer {
    /// Resizes the frame to `width` × `height` pixels. The targets and what their size shapes
    /// are made again (the depth pyramid and the Tile Load Map's bindings to it, pass 3's
    /// binding of the depth, pass 4's multisampled targets, the display's binding of the
    /// light, the fragment counter); the caches and their tiles, the loader, the tables and the
    /// pipelines stay, so the next frame streams on from what is resident. A size the adapter
    /// cannot hold is refused and the renderer left as it was.
    pub fn resize(&mut self, width: u32, height: u32) -> Result<(), RenderError> {
        let mut settings = self.settings.clone();
        (settings.render.width, settings.render.height) = (width, height);
        let targets = Targets::new(&self.gpu.device, &settings)?;
        let fragments = match &self.fragments {
            Some(counter) => {
                let fresh = FragmentCounter::new(&self.gpu, counter.labels(), &targets.colour);
                Some(fresh.ok_or(RenderError::NoFragmentCounts)?)
            }
            None => None,
        };
        let device = &self.gpu.device;
        self.depth_pyramid = DepthPyramid::new(device, width, height);
        self.tlm_bindings =
            self.tlm.bind_group(device, &height_tile_ranges(&self.dataset), &self.depth_pyramid);
        if let Some(stage) = self.seeds.as_mut() {
            stage.resize(device, &self.caches, &targets);
        }
        self.display.rebind(device, &targets.colour_view);
        (self.targets, self.fragments, self.settings.render) = (targets, fragments, settings.render);
        // What the last frame recorded was for the old size.
        self.last = None;
        Ok(())
    }
}

impl Caches {
    /// The caches of `dataset`'s layers, sized by `settings.cache`, their pinned tiles loaded.
    pub(super) fn new(gpu: &Gpu, dataset: &Dataset, settings: &Settings) -> Result<Self, RenderError> {
        let device = &gpu.device;
        let slots = &settings.cache;
        // Each cache is one texture array, a slot a layer: past the limit, wgpu would only report
        // an invalid texture, at every use.
        let max = device.limits().max_texture_array_layers;
        let asked = [
            ("height_slots", slots.height_slots, true),
            ("imagery_slots", slots.imagery_slots, dataset.imagery.is_some()),
            ("landcover_slots", slots.landcover_slots, dataset.landcover.is_some()),
        ];
        if let Some(&(key, slots, _)) = asked.iter().find(|&&(_, n, used)| used && n > max) {
            return Err(RenderError::CacheTooLarge { key, slots, max });
        }
        let mut heights = TileCache::new(
            device,
            "height cache",
            LayerKind::Height,
            dataset.height.pyramid,
            1,
            wgpu::TextureFormat::R32Float,
            slots.height_slots,
        )
        .with_summary(device, BLOCK_TOPS);
        let imagery_delivery = dataset.imagery.as_ref().map_or(Delivery::Stored, |layer| {
            let software = gpu.info.device_type == wgpu::DeviceType::Cpu;
            imagery_delivery(layer, device.features(), settings.imagery.decode_blocks_on(software))
        });
        let mut imagery = match &dataset.imagery {
            Some(layer) if layer.pyramid.levels > MAX_LEVELS => {
                return Err(RenderError::TooManyLevels { levels: layer.pyramid.levels });
            }
            Some(layer) => TileCache::new(
                device,
                "imagery cache",
                LayerKind::Imagery,
                layer.pyramid,
                layer.mips,
                match (imagery_delivery, layer.block_format) {
                    (Delivery::Stored, Some(format)) => format.texture_format(),
                    _ => wgpu::TextureFormat::Rgba8UnormSrgb,
                },
                slots.imagery_slots,
            ),
            // The shader reads imagery through the same bindings either way; a one-slot cache
            // that stays empty costs 1.5 MiB and keeps one code path.
            None => TileCache::new(
                device,
                "no imagery",
                LayerKind::Imagery,
                LayerSpec::imagery([1, 1]).pyramid,
                IMAGERY_MIPS,
                wgpu::TextureFormat::Rgba8UnormSrgb,
                1,
            ),
        };
        let pin =
            |cache: &TileCache| pinned_tiles(cache.pyramid(), MAX_PINNED_TILES.min(cache.capacity() / 4));
        let pinned_heights = pin(&heights);
        heights.load_now(&gpu.queue, &pinned_heights, 0, |id| dataset.height.tile_bytes(id));
        let pinned_imagery = match &dataset.imagery {
            Some(layer) => {
                let pinned = pin(&imagery);
                imagery.load_now(&gpu.queue, &pinned, 0, |id| imagery_tile(layer, id, imagery_delivery));
                pinned
            }
            None => Vec::new(),
        };
        let landcover = match (&dataset.landcover, &dataset.manifest.landcover) {
            (Some(layer), Some(meta)) => Some(TileCache::new(
                device,
                "land-cover cache",
                LayerKind::Landcover,
                layer.pyramid,
                1,
                meta.coding.texture_format(),
                slots.landcover_slots,
            )),
            _ => None,
        };
        Ok(Self {
            heights,
            imagery,
            imagery_delivery,
            landcover,
            pinned_heights,
            pinned_imagery,
            pinned_landcover: Vec::new(),
        })
    }
}

/// How the imagery cache takes `layer`'s tiles on a device with `features`: as stored, unless
/// they are blocks the device cannot sample (said once, here) or `decode` asks for plain texels.
fn imagery_delivery(layer: &LayerPack, features: wgpu::Features, decode: bool) -> Delivery {
    let Some(format) = layer.block_format else { return Delivery::Stored };
    if !features.contains(wgpu::Features::TEXTURE_COMPRESSION_BC) {
        eprintln!(
            "terramp: this adapter cannot sample {format} blocks: the imagery is decoded to RGBA8 as it \
             loads ({}× the GPU memory and uploads of a slot)",
            4 * 16 / format.texture_format().block_copy_size(None).unwrap_or(16)
        );
        return Delivery::ImageryDecoded;
    }
    if decode { Delivery::ImageryDecoded } else { Delivery::Stored }
}
