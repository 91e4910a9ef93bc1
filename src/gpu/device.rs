//! How it works: terramp renders headless, so it asks wgpu for every adapter rather than one tied
//! to a surface, and picks by policy: a hardware GPU when there is one, else a software rasteriser
//! (Mesa lavapipe on Linux), unless the setting or `TERRAMP_ADAPTER` forces one kind. `WGPU_BACKEND`
//! narrows the backends as usual (CI sets `vulkan`, so a silent fallback to GL cannot hide).
//!
//! Mesa's device-select layer (implicit, installed with its Vulkan drivers) picks a default GPU by
//! connecting to the Wayland and X11 servers whenever an instance enables their surface
//! extensions, which wgpu always does; on a server that prints two lines of errors no one can act
//! on. terramp picks its adapter itself, so its binaries turn the layer off before they start
//! ([`skip_device_select_layer`]).
//!
//! A window (`terramp view`) opens its GPU the other way round: the instance knows the display,
//! the window's surface is made first, and only adapters that can present to it are candidates
//! ([`Gpu::for_surface`]); the policy among them is the same.
//!
//! With no usable adapter the error says what is missing and how to install it. wgpu's default
//! uncaptured-error handler panics; ours records the error (and prints it once), so a validation
//! error surfaces as a `GpuError` from `Gpu::check`, never a backtrace.

use std::sync::{Arc, Mutex};

use serde::{Deserialize, Serialize};
use thiserror::Error;

/// The environment variable Mesa's device-select layer reads to stay out of the way.
const NO_DEVICE_SELECT: &str = "NODEVICE_SELECT";

/// Turns off Mesa's device-select layer for this process (unless the user's environment says
/// otherwise), so that opening a GPU does not probe a window system.
///
/// # Safety
/// It sets an environment variable: call it before any other thread starts (first thing in
/// `main`), as `std::env::set_var` requires.
pub unsafe fn skip_device_select_layer() {
    if std::env::var_os(NO_DEVICE_SELECT).is_none() {
        // SAFETY: the caller guarantees no other thread is running.
        unsafe { std::env::set_var(NO_DEVICE_SELECT, "1") };
    }
}

/// Which kind of adapter to use.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AdapterChoice {
    /// A hardware GPU if there is one, else a software adapter.
    #[default]
    Auto,
    /// Any adapter but a software rasteriser (discrete first, then integrated, then virtual).
    Hardware,
    /// A software rasteriser only (Mesa lavapipe on Linux), even where a GPU is present.
    Software,
}

impl AdapterChoice {
    /// The `TERRAMP_ADAPTER` environment variable, when set, overrides the setting.
    pub fn with_env(self) -> Result<Self, GpuError> {
        self.overridden_by(std::env::var(ADAPTER_VARIABLE).ok().as_deref())
    }

    /// `self`, unless `value` (what `TERRAMP_ADAPTER` holds, if it is set) names another kind:
    /// `auto` (or empty), `hardware` or `software`, in any case.
    pub fn overridden_by(self, value: Option<&str>) -> Result<Self, GpuError> {
        let Some(value) = value else { return Ok(self) };
        match value.to_ascii_lowercase().as_str() {
            "auto" | "" => Ok(Self::Auto),
            "hardware" => Ok(Self::Hardware),
            "software" => Ok(Self::Software),
            _ => Err(GpuError::BadChoice(value.to_owned())),
        }
    }

    /// The lowercase word `TERRAMP_ADAPTER` takes for this kind.
    pub fn name(self) -> &'static str {
        match self {
            Self::Auto => "auto",
            Self::Hardware => "hardware",
            Self::Software => "software",
        }
    }

    fn accepts(self, device_type: wgpu::DeviceType) -> bool {
        let software = device_type == wgpu::DeviceType::Cpu;
        match self {
            Self::Auto => true,
            Self::Hardware => !software,
            Self::Software => software,
        }
    }

    /// Which of `candidates` (each adapter's device type and backend, in the order wgpu listed
    /// them) this choice picks: among those it accepts, hardware first (discrete, integrated,
    /// virtual or other, then a software rasteriser), Vulkan before other backends, then the
    /// first listed. `None` when it accepts none. The order is the policy.
    pub fn pick(self, candidates: &[(wgpu::DeviceType, wgpu::Backend)]) -> Option<usize> {
        let rank = |(device_type, backend): (wgpu::DeviceType, wgpu::Backend)| {
            let kind = match device_type {
                wgpu::DeviceType::DiscreteGpu => 0,
                wgpu::DeviceType::IntegratedGpu => 1,
                wgpu::DeviceType::VirtualGpu | wgpu::DeviceType::Other => 2,
                wgpu::DeviceType::Cpu => 3,
            };
            (kind, backend != wgpu::Backend::Vulkan)
        };
        (0..candidates.len())
            .filter(|&i| self.accepts(candidates[i].0))
            .min_by_key(|&i| (rank(candidates[i]), i))
    }
}

/// The environment variable that overrides `gpu.adapter`: auto, hardware or software.
pub const ADAPTER_VARIABLE: &str = "TERRAMP_ADAPTER";

/// What to install when no adapter is usable, and the variables that force an adapter kind or a
/// backend: the tail of `GpuError::NoAdapter`'s message.
pub const INSTALL_HINT: &str = "terramp needs a GPU adapter. With no GPU driver, install Mesa's software Vulkan \
driver: `sudo apt-get install mesa-vulkan-drivers libvulkan1` (Debian/Ubuntu). Force one kind with \
TERRAMP_ADAPTER=software|hardware, and a backend with WGPU_BACKEND=vulkan.";

/// Why the GPU could not be opened, or what went wrong on it since the last check.
#[derive(Debug, Error)]
pub enum GpuError {
    /// No adapter of the kind asked for is present (or wgpu sees none at all).
    #[error("no {wanted} GPU adapter found (adapters seen: {seen}). {INSTALL_HINT}")]
    NoAdapter {
        /// The kind asked for: `usable` (any), `hardware` or `software`.
        wanted: &'static str,
        /// Every adapter wgpu listed, as name and backend, or `none`.
        seen: String,
    },
    /// `TERRAMP_ADAPTER` holds something other than auto, hardware or software.
    #[error("TERRAMP_ADAPTER={0:?}: expected auto, hardware or software")]
    BadChoice(String),
    /// The chosen adapter refused a device with terramp's features and limits.
    #[error("the adapter {adapter} refused a device: {source}")]
    Device {
        /// The adapter's name.
        adapter: String,
        /// wgpu's reason.
        source: wgpu::RequestDeviceError,
    },
    /// The window's surface could not be made (no display, or a handle wgpu cannot use).
    #[error("cannot draw into the window: {0}")]
    Surface(#[from] wgpu::CreateSurfaceError),
    /// wgpu raised errors (validation, out of memory) since the last `Gpu::check`, joined with
    /// `; `; also a readback that failed or never arrived.
    #[error("GPU error: {0}")]
    Validation(String),
    /// The device is gone (a driver reset, a GPU removed or switched, or `destroy`): nothing more
    /// can be drawn with it. Every later call says so, before the errors that follow from it.
    #[error("the GPU device was lost ({0}); nothing more can be drawn with it: restart terramp")]
    DeviceLost(String),
    /// Waiting for the device, or polling it, failed.
    #[error("waiting for the GPU: {0}")]
    Poll(#[from] wgpu::PollError),
    /// A staging buffer of a readback could not be mapped.
    #[error("reading a GPU buffer back: {0}")]
    Map(#[from] wgpu::BufferAsyncError),
}

/// The device terramp renders with, and what it can do. Clones share the device (wgpu's handles
/// are reference-counted), so a renderer can be remade on the same device.
#[derive(Clone)]
pub struct Gpu {
    /// The logical device every pass creates its buffers, textures and pipelines on.
    pub device: wgpu::Device,
    /// The device's queue: uploads (counted) and submissions.
    pub queue: super::Queue,
    /// The chosen adapter: name, backend, device type and driver (`describe` prints them).
    pub info: wgpu::AdapterInfo,
    /// The adapter itself: what a window's surface can be configured with is asked of it.
    pub adapter: wgpu::Adapter,
    /// GPU timestamps can be written inside encoders (else the profiler times on the CPU).
    pub has_timestamps: bool,
    errors: Arc<Mutex<Vec<String>>>,
    /// Why the device was lost, once it is.
    lost: Arc<Mutex<Option<String>>>,
}

impl Gpu {
    /// Picks an adapter by `choice` (`TERRAMP_ADAPTER` overrides it; hardware first, Vulkan before
    /// other backends) and opens a headless device on it whose GPU errors `check` reports.
    pub fn new(choice: AdapterChoice) -> Result<Self, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        Self::open(pick_adapter(&instance, choice, None)?)
    }

    /// The adapter `new` would open for `choice`, without opening it: for a command to learn that
    /// it has one before work that is no use without it.
    pub fn probe(choice: AdapterChoice) -> Result<wgpu::AdapterInfo, GpuError> {
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        Ok(pick_adapter(&instance, choice, None)?.get_info())
    }

    /// Opens a device that can present to a window: `display` is the window system's connection
    /// (winit's `OwnedDisplayHandle`), `window` the window. Among the adapters that can present
    /// to its surface, `choice` picks as in `new`.
    pub fn for_surface(
        choice: AdapterChoice,
        display: Box<dyn wgpu::wgt::WgpuHasDisplayHandle>,
        window: impl Into<wgpu::SurfaceTarget<'static>>,
    ) -> Result<(Self, wgpu::Surface<'static>), GpuError> {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(display));
        let surface = instance.create_surface(window)?;
        let gpu = Self::open(pick_adapter(&instance, choice, Some(&surface))?)?;
        Ok((gpu, surface))
    }

    /// terramp on a device the host made (`adapter` the one it was made on): the host's frame and
    /// terramp's share the device and queue. terramp uses the features the device has (each pass
    /// that needs one says so when it is made) and `Renderer::new` refuses a device short of
    /// `passes::limits::needed_limits`, naming the limit. The device's error and loss callbacks
    /// stay the host's: terramp installs none on it, so its errors reach the host's handler and
    /// `check` and `lost` report nothing.
    pub fn from_host(adapter: wgpu::Adapter, device: wgpu::Device, queue: wgpu::Queue) -> Self {
        let has_timestamps = times_inside_encoders(device.features());
        Self {
            device,
            queue: super::Queue::new(queue),
            info: adapter.get_info(),
            adapter,
            has_timestamps,
            errors: Arc::default(),
            lost: Arc::default(),
        }
    }

    /// A device on `adapter` with terramp's features and limits, as far as the adapter has them.
    fn open(adapter: wgpu::Adapter) -> Result<Self, GpuError> {
        let info = adapter.get_info();
        let wanted = wgpu_profiler::GpuProfiler::ALL_WGPU_TIMER_FEATURES
            | wgpu::Features::TEXTURE_ADAPTER_SPECIFIC_FORMAT_FEATURES
            // Imagery sampled as the dataset stores it, in BC1/BC7 blocks (else decoded on load).
            | wgpu::Features::TEXTURE_COMPRESSION_BC
            // The seed draws start at compaction's slots (`first_instance` of indirect draws).
            | wgpu::Features::INDIRECT_FIRST_INSTANCE
            // The foliage passes' fragments counted (`gpu.count_fragments`).
            | wgpu::Features::PIPELINE_STATISTICS_QUERY;
        let features = adapter.features() & wanted;
        let has_timestamps = times_inside_encoders(features);
        // Cache texture arrays and seed buffers want what the adapter has, not WebGPU's minimums.
        let adapter_limits = adapter.limits();
        let limits = wgpu::Limits {
            max_texture_array_layers: adapter_limits.max_texture_array_layers.min(2048),
            max_storage_buffer_binding_size: adapter_limits.max_storage_buffer_binding_size,
            max_buffer_size: adapter_limits.max_buffer_size,
            // Seed selection reads three page tables and its tables beside its outputs.
            max_storage_buffers_per_shader_stage: adapter_limits.max_storage_buffers_per_shader_stage.min(16),
            ..wgpu::Limits::default()
        };
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("terramp"),
            required_features: features,
            required_limits: limits,
            ..Default::default()
        }))
        .map_err(|source| GpuError::Device { adapter: info.name.clone(), source })?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let lost = Arc::new(Mutex::new(None));
        let (sink, lost_sink, was_lost) = (Arc::clone(&errors), Arc::clone(&lost), Arc::clone(&lost));
        device.set_device_lost_callback(move |reason, message| {
            let why =
                if message.is_empty() { format!("{reason:?}") } else { format!("{reason:?}: {message}") };
            eprintln!("terramp: the GPU device was lost ({why})");
            if let Ok(mut lost) = lost_sink.lock() {
                *lost = Some(why);
            }
        });
        device.on_uncaptured_error(Arc::new(move |error: wgpu::Error| {
            // After a loss every call fails on invalid objects: the loss is the one error to tell.
            if was_lost.lock().is_ok_and(|lost| lost.is_some()) {
                return;
            }
            let text = error.to_string();
            eprintln!("terramp: GPU error: {text}");
            if let Ok(mut errors) = sink.lock() {
                errors.push(text);
            }
        }));
        Ok(Self { device, queue: super::Queue::new(queue), info, adapter, has_timestamps, errors, lost })
    }

    /// One line naming the adapter, for logs.
    pub fn describe(&self) -> String {
        format!(
            "{} ({:?}, {:?}, {})",
            self.info.name, self.info.backend, self.info.device_type, self.info.driver
        )
    }

    /// Blocks until the GPU has finished everything submitted so far.
    pub fn wait(&self) -> Result<(), GpuError> {
        self.device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(())
    }

    /// Why the device was lost, if it was.
    pub fn lost(&self) -> Option<String> {
        self.lost.lock().ok().and_then(|lost| lost.clone())
    }

    /// The GPU errors raised since the last check, as one error; a lost device first.
    pub fn check(&self) -> Result<(), GpuError> {
        if let Some(why) = self.lost() {
            return Err(GpuError::DeviceLost(why));
        }
        let mut errors = self.errors.lock().map_err(|_| GpuError::Validation("error log poisoned".into()))?;
        if errors.is_empty() {
            return Ok(());
        }
        let joined = errors.join("; ");
        errors.clear();
        Err(GpuError::Validation(joined))
    }
}

/// Whether a device with `features` can write GPU timestamps inside encoders.
fn times_inside_encoders(features: wgpu::Features) -> bool {
    features.contains(wgpu::Features::TIMESTAMP_QUERY | wgpu::Features::TIMESTAMP_QUERY_INSIDE_ENCODERS)
}

/// The adapter `choice` picks (`AdapterChoice::pick`) among those `instance` sees (those that
/// present to `surface`, when given).
fn pick_adapter(
    instance: &wgpu::Instance,
    choice: AdapterChoice,
    surface: Option<&wgpu::Surface<'_>>,
) -> Result<wgpu::Adapter, GpuError> {
    let choice = choice.with_env()?;
    let backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::all());
    let adapters = pollster::block_on(instance.enumerate_adapters(backends));
    let seen: Vec<String> =
        adapters.iter().map(|a| format!("{} ({:?})", a.get_info().name, a.get_info().backend)).collect();
    let mut usable: Vec<wgpu::Adapter> =
        adapters.into_iter().filter(|a| surface.is_none_or(|s| a.is_surface_supported(s))).collect();
    let candidates: Vec<_> =
        usable.iter().map(|a| (a.get_info().device_type, a.get_info().backend)).collect();
    choice.pick(&candidates).map(|i| usable.swap_remove(i)).ok_or_else(|| GpuError::NoAdapter {
        wanted: match (choice, surface.is_some()) {
            (AdapterChoice::Auto, false) => "usable",
            (AdapterChoice::Auto, true) => "window-presenting",
            (AdapterChoice::Hardware, _) => "hardware",
            (AdapterChoice::Software, _) => "software",
        },
        seen: if seen.is_empty() { "none".into() } else { seen.join(", ") },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use wgpu::{Backend, DeviceType};

    /// What a machine with an NVIDIA GPU and Mesa's drivers lists: the GPU on Vulkan and GL,
    /// lavapipe on Vulkan, llvmpipe on GL; lavapipe listed first.
    const GPU_MACHINE: [(DeviceType, Backend); 4] = [
        (DeviceType::Cpu, Backend::Vulkan),
        (DeviceType::DiscreteGpu, Backend::Gl),
        (DeviceType::DiscreteGpu, Backend::Vulkan),
        (DeviceType::Cpu, Backend::Gl),
    ];
    /// A server without a GPU: llvmpipe on GL first, lavapipe on Vulkan.
    const SOFTWARE_ONLY: [(DeviceType, Backend); 2] =
        [(DeviceType::Cpu, Backend::Gl), (DeviceType::Cpu, Backend::Vulkan)];

    #[test]
    fn each_choice_picks_its_kind_vulkan_first() {
        use AdapterChoice::{Auto, Hardware, Software};
        assert_eq!(Auto.pick(&GPU_MACHINE), Some(2));
        assert_eq!(Hardware.pick(&GPU_MACHINE), Some(2));
        // The software adapter even where a GPU is present: what the tests run on.
        assert_eq!(Software.pick(&GPU_MACHINE), Some(0));
        assert_eq!((Auto.pick(&SOFTWARE_ONLY), Software.pick(&SOFTWARE_ONLY)), (Some(1), Some(1)));
        assert_eq!(Hardware.pick(&SOFTWARE_ONLY), None);
        let integrated_and_discrete = [(DeviceType::IntegratedGpu, Backend::Vulkan), GPU_MACHINE[2]];
        assert_eq!(Hardware.pick(&integrated_and_discrete), Some(1));
        // Of two equal candidates, the first listed.
        assert_eq!(Software.pick(&[SOFTWARE_ONLY[1], SOFTWARE_ONLY[1]]), Some(0));
        assert_eq!(Auto.pick(&[]), None);
    }

    #[test]
    fn terramp_adapter_overrides_the_setting_in_any_case() {
        use AdapterChoice::{Auto, Hardware, Software};
        assert_eq!(Software.overridden_by(None).unwrap(), Software);
        assert_eq!(Software.overridden_by(Some("HARDWARE")).unwrap(), Hardware);
        assert_eq!(Hardware.overridden_by(Some("software")).unwrap(), Software);
        assert_eq!(Software.overridden_by(Some("")).unwrap(), Auto);
        assert_eq!(Software.overridden_by(Some("Auto")).unwrap(), Auto);
        let err = Software.overridden_by(Some("gpu")).unwrap_err();
        assert!(matches!(&err, GpuError::BadChoice(v) if v == "gpu"), "{err}");
        for choice in [Auto, Hardware, Software] {
            assert_eq!(Auto.overridden_by(Some(choice.name())).unwrap(), choice);
        }
    }
}
