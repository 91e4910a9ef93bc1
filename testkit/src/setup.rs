//! The adapter tests run on, settings sized for tests, and renderers over a dataset folder.
//!
//! Tests run on the software adapter (Mesa lavapipe; CI forces `WGPU_BACKEND=vulkan`) whatever
//! else the machine has, so a developer with a GPU runs what CI runs. `TERRAMP_ADAPTER`
//! (`hardware`, `auto`) runs them on another adapter: in the test process (`gpu`, through
//! `Gpu::new`'s override) and in the binaries they start (`command`). Checks that hold only on
//! lavapipe (its golden images, llvmpipe's 4 × 4 blocks) ask `lavapipe_only` first, which says on
//! the terminal what it skipped elsewhere.

use std::ffi::OsStr;
use std::io::Write as _;
use std::path::Path;
use std::process::Command;
use std::sync::atomic::{AtomicUsize, Ordering};

use terramp::camera::Camera;
use terramp::config::Settings;
use terramp::dataset::Dataset;
use terramp::frame::Renderer;
use terramp::gpu::{ADAPTER_VARIABLE, AdapterChoice, Gpu};

/// The adapter kind tests ask for, unless `TERRAMP_ADAPTER` names another.
pub const TEST_ADAPTER: AdapterChoice = AdapterChoice::Software;

/// The adapter tests run on: the software one (lavapipe), unless `TERRAMP_ADAPTER` says otherwise.
pub fn gpu() -> Gpu {
    Gpu::new(TEST_ADAPTER).unwrap_or_else(|e| {
        let asked = TEST_ADAPTER.with_env().map_or("a valid", AdapterChoice::name);
        panic!(
            "the tests found no {asked} adapter: they run on the software one (lavapipe: install \
             mesa-vulkan-drivers) unless {ADAPTER_VARIABLE} names another kind ({e})"
        )
    })
}

/// A command that runs `program` (one of the workspace's binaries) on the tests' adapter:
/// `TERRAMP_ADAPTER=software` unless the tests' own environment sets it (then the binary inherits
/// that).
pub fn command(program: impl AsRef<OsStr>) -> Command {
    let mut command = Command::new(program);
    if std::env::var_os(ADAPTER_VARIABLE).is_none() {
        command.env(ADAPTER_VARIABLE, TEST_ADAPTER.name());
    }
    command
}

/// Whether `info` is Mesa's lavapipe: llvmpipe, its CPU rasteriser, on Vulkan.
/// A built example of the crate, as `cargo test` leaves it beside the test binaries
/// (`target/<profile>/examples/`); fails, saying how to build it, where it is not.
pub fn example(name: &str) -> std::path::PathBuf {
    let exe = std::env::current_exe().unwrap();
    let path = exe.parent().and_then(Path::parent).unwrap().join("examples").join(name);
    assert!(
        path.is_file(),
        "{} is not built: `cargo test` builds the examples (or `cargo build --example {name}`)",
        path.display()
    );
    path
}

pub fn is_lavapipe(info: &wgpu::AdapterInfo) -> bool {
    let llvmpipe = info.name.contains("llvmpipe") || info.driver.contains("llvmpipe");
    info.device_type == wgpu::DeviceType::Cpu && info.backend == wgpu::Backend::Vulkan && llvmpipe
}

/// Checks of this binary skipped for running on another adapter than lavapipe.
static OFF_LAVAPIPE: AtomicUsize = AtomicUsize::new(0);

/// Whether the checks `what` describes may run on `gpu`: they hold only on lavapipe (its own
/// rasteriser's rounding, blocks or references). On any other adapter they are skipped, and the
/// skip is printed past the harness's capture, with the adapter and the count so far, so that a
/// green run there is never mistaken for one that made them.
pub fn lavapipe_only(gpu: &Gpu, what: &str) -> bool {
    if is_lavapipe(&gpu.info) {
        return true;
    }
    let skipped = OFF_LAVAPIPE.fetch_add(1, Ordering::Relaxed) + 1;
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED (lavapipe only, on {}): {what}; {skipped} such check(s) of this binary skipped so far",
        gpu.describe()
    );
    false
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

/// A 2D texture of one mip level and one sample, `size` pixels, for a test's own targets.
pub fn texture_2d(
    device: &wgpu::Device,
    size: [u32; 2],
    format: wgpu::TextureFormat,
    usage: wgpu::TextureUsages,
) -> wgpu::Texture {
    device.create_texture(&wgpu::TextureDescriptor {
        label: Some("a test's texture"),
        size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage,
        view_formats: &[],
    })
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tests_ask_for_lavapipe_on_a_machine_with_a_gpu_and_so_do_their_binaries() {
        use wgpu::{Backend, DeviceType};
        let machine = [(DeviceType::DiscreteGpu, Backend::Vulkan), (DeviceType::Cpu, Backend::Vulkan)];
        assert_eq!(TEST_ADAPTER.pick(&machine), Some(1));
        let command = command("true");
        let set: Vec<_> = command.get_envs().filter(|(name, _)| *name == ADAPTER_VARIABLE).collect();
        match std::env::var_os(ADAPTER_VARIABLE) {
            // The binary inherits what the tests were told.
            Some(_) => assert!(set.is_empty(), "{set:?}"),
            None => assert_eq!(set, [(OsStr::new(ADAPTER_VARIABLE), Some(OsStr::new("software")))]),
        }
    }
}
