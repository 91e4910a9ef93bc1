//! The software adapter tests run on (CI forces `WGPU_BACKEND=vulkan`), settings sized for tests,
//! and renderers over a dataset folder.

use std::path::Path;

use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::gpu::{AdapterChoice, Gpu};

/// The adapter tests run on: a hardware GPU if there is one, else lavapipe.
pub fn gpu() -> Gpu {
    Gpu::new(AdapterChoice::Auto).expect("tests need a GPU adapter; install mesa-vulkan-drivers")
}

/// The default settings with a `width` × `height` viewport.
pub fn small_settings(width: u32, height: u32) -> Settings {
    let mut settings = Settings::default();
    settings.render.width = width;
    settings.render.height = height;
    settings
}

/// As `small_settings`, with no seeds grown (`seeds.density_scale` 0: pass 3 checks no rank), for
/// tests of the ground alone. At test sizes a pixel spans tens of metres, so most seeds sit within
/// a pixel of a silhouette and pass 3 settles each with a march over the DEM: on the software
/// adapter, seconds a frame while the caches fill, spent on nothing such a test looks at.
pub fn ground_settings(width: u32, height: u32) -> Settings {
    let mut settings = small_settings(width, height);
    settings.seeds.density_scale = 0.0;
    settings
}

/// A renderer over the dataset in `dataset`.
pub fn renderer(dataset: &Path, settings: Settings) -> Renderer {
    Renderer::new(gpu(), Dataset::open(dataset).unwrap(), settings).unwrap()
}

/// The frame `r` settles on from `camera` (every tile it asks for resident), as an sRGB image.
pub fn settled_colour(r: &mut Renderer, camera: &Camera) -> image::RgbaImage {
    r.render_resolved(camera).unwrap();
    r.read_colour().unwrap()
}
