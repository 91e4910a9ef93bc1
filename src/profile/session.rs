//! How it works: a `Session` wraps the renderer for a profiled flight. Before each frame it waits
//! until at most `FRAMES_IN_FLIGHT − 1` earlier frames are still on the GPU (each frame ends with an
//! empty submit whose index marks it), as a double-buffered swapchain would: a headless loop with
//! nothing to present would otherwise let the CPU run ahead and time nothing but itself. A
//! frame's wall time runs from its start to the next one's, so it includes those waits.
//!
//! The profiler keeps its history on, and the session files each finished frame's scopes under
//! the renderer's frame number (mapped from the profiler's own count, taken before each render).
//! `finish` waits for the GPU and drains the profiler and the counts, so the last frames' timings
//! and counts arrive too; seed counters only arrive inside frames, so the last frame or two may
//! have none.
//!
//! Paths: without `--path`, the embedded `config/paths/default.toml` when the dataset is the
//! synthetic one and holds every keyframe of it; else `orbit_path`, a loop around the dataset's
//! centre.

use std::collections::{HashMap, VecDeque};
use std::path::Path;

use glam::DVec3;

use super::{ProfileError, Recording, SeedSample};
use crate::camera::Camera;
use crate::dataset::{Dataset, PackError};
use crate::earth::pose::GeoPose;
use crate::frame::{FrameReport, Renderer};
use crate::gpu::counts::FrameCounts;
use crate::gpu::{GpuError, TimeSource};
use crate::path::{CameraPath, EarthKey, Keyframe, PathError};

/// Frames that may be queued on the GPU at once.
pub const FRAMES_IN_FLIGHT: usize = 2;

/// The camera path `terramp fly` and `profile` use over the default synthetic dataset.
pub const DEFAULT_PATH_TOML: &str = include_str!("../../config/paths/default.toml");

/// Height of the orbit above the highest ground under its arc, metres.
const ORBIT_CLEARANCE_M: f64 = 120.0;

/// A profiled flight in progress: renders frames through `renderer`, at most `FRAMES_IN_FLIGHT`
/// on the GPU at once, and records each profiled frame's wall time, pass timings and seed counters.
pub struct Session<'r> {
    renderer: &'r mut Renderer,
    warmup: u32,
    rendered: u32,
    in_flight: VecDeque<wgpu::SubmissionIndex>,
    /// The profiled frame whose wall time is still running: its number and start.
    open: Option<(u64, f64)>,
    /// Renderer frame numbers by profiler frame number.
    frame_of: HashMap<u64, u64>,
    recording: Recording,
}

impl<'r> Session<'r> {
    /// A session whose first `warmup` frames are not profiled.
    pub fn new(renderer: &'r mut Renderer, warmup: u32) -> Self {
        renderer.profiler.keep_history(true);
        Self {
            renderer,
            warmup,
            rendered: 0,
            in_flight: VecDeque::new(),
            open: None,
            frame_of: HashMap::new(),
            recording: Recording::default(),
        }
    }

    /// The renderer being profiled, for its settings and latest timings between frames.
    pub fn renderer(&self) -> &Renderer {
        self.renderer
    }

    /// Sets the scene's time (wind, clouds) of the next frames (`Renderer::set_time_s`).
    pub fn set_time_s(&mut self, time_s: f64) {
        self.renderer.set_time_s(time_s);
    }

    /// Whether the next frame is a warm-up frame.
    pub fn warming_up(&self) -> bool {
        self.rendered < self.warmup
    }

    /// Renders one frame from `camera`.
    pub fn frame(&mut self, camera: &Camera) -> Result<FrameReport, ProfileError> {
        self.throttle(FRAMES_IN_FLIGHT - 1)?;
        let start_ms = self.renderer.profiler.now_ms();
        self.close_open(start_ms);
        let profiler_frame = self.renderer.profiler.frame();
        let report = self.renderer.render(camera)?;
        self.frame_of.insert(profiler_frame, report.frame);
        self.in_flight.push_back(self.renderer.gpu.queue.submit(std::iter::empty()));
        if !self.warming_up() {
            self.open = Some((report.frame, start_ms));
        }
        self.rendered += 1;
        if let Some(seeds) = &report.seeds {
            self.recording.seeds.insert(seeds.frame, SeedSample::from(seeds));
        }
        if !report.fragments.is_empty() {
            self.recording.fragments.insert(report.frame, report.fragments.clone());
        }
        self.file_counts(report.counts.iter().cloned());
        self.absorb_history();
        Ok(report)
    }

    /// Ends the last frame, waits for the GPU and collects every timing still in flight.
    pub fn finish(mut self) -> Result<Recording, ProfileError> {
        self.throttle(FRAMES_IN_FLIGHT - 1)?;
        let end_ms = self.renderer.profiler.now_ms();
        self.close_open(end_ms);
        self.renderer.gpu.wait()?;
        let counts = self.renderer.take_counts()?;
        self.file_counts(counts.into_iter());
        self.renderer.profiler.drain(&self.renderer.gpu)?;
        self.absorb_history();
        self.renderer.profiler.keep_history(false);
        Ok(std::mem::take(&mut self.recording))
    }

    fn file_counts(&mut self, counts: impl Iterator<Item = FrameCounts>) {
        self.recording.counts.extend(counts.map(|c| (c.frame, c)));
    }

    fn throttle(&mut self, keep: usize) -> Result<(), ProfileError> {
        while self.in_flight.len() > keep {
            if let Some(index) = self.in_flight.pop_front() {
                let wait = wgpu::PollType::Wait { submission_index: Some(index), timeout: None };
                self.renderer.gpu.device.poll(wait).map_err(GpuError::from)?;
            }
        }
        Ok(())
    }

    fn close_open(&mut self, now_ms: f64) {
        if let Some((frame, start_ms)) = self.open.take() {
            let wall_ms = now_ms - start_ms;
            self.recording.frames.push(super::FrameSample { frame, start_ms, wall_ms });
        }
    }

    fn absorb_history(&mut self) {
        for timings in self.renderer.profiler.take_history() {
            if let Some(&frame) = self.frame_of.get(&timings.frame) {
                self.recording.scopes.entry(frame).or_default().extend(timings.scopes);
            }
        }
    }
}

/// Flies `path` with `renderer`: `warmup` unprofiled frames at its start, then `frames` profiled
/// frames spread evenly from its start to its end. With `log`, writes one JSON object per frame
/// (warm-up included) on its own line: `frame`, `warmup`, `camera`, `report` (the `FrameReport`),
/// `render_ms` (the `render` call) and `passes` (the latest timings that arrived, as `fly` logs).
pub fn fly(
    renderer: &mut Renderer,
    path: &CameraPath,
    warmup: u32,
    frames: u32,
    mut log: Option<&mut dyn std::io::Write>,
) -> Result<Recording, ProfileError> {
    let (fov_deg, near_m) = (renderer.settings.render.fov_deg, renderer.settings.render.near_m);
    let mut session = Session::new(renderer, warmup);
    for i in 0..warmup.saturating_add(frames) {
        let t = f64::from(i.saturating_sub(warmup)) / f64::from(frames.max(2) - 1);
        let camera = path.camera_at(t, fov_deg, near_m);
        let time_s = session.renderer().settings.wind.time_of_frame_s(i as usize);
        session.set_time_s(time_s);
        let warming_up = session.warming_up();
        let start = std::time::Instant::now();
        let report = session.frame(&camera)?;
        let render_ms = start.elapsed().as_secs_f64() * 1000.0;
        let Some(log) = log.as_mut() else { continue };
        let p = camera.position_m;
        let record = serde_json::json!({
            "frame": report.frame,
            "warmup": warming_up,
            "camera": { "x_m": p.x, "y_m": p.y, "z_m": p.z, "yaw_deg": camera.yaw_deg, "pitch_deg": camera.pitch_deg },
            "report": report,
            "render_ms": render_ms,
            "passes": session.renderer().last_timings(),
        });
        serde_json::to_writer(&mut *log, &record).map_err(|e| ProfileError::Log(e.into()))?;
        log.write_all(b"\n").map_err(ProfileError::Log)?;
    }
    session.finish()
}

/// How `renderer` times its GPU passes, and why, in words.
pub fn timing_of(renderer: &Renderer) -> (TimeSource, String) {
    if renderer.profiler.uses_gpu_timestamps() {
        return (TimeSource::GpuTimestamps, "GPU timestamp queries (wgpu-profiler)".into());
    }
    let why = if !renderer.settings.gpu.timestamps {
        "gpu.timestamps = false in the settings"
    } else if !renderer.gpu.has_timestamps {
        "this adapter has no timestamp queries inside encoders"
    } else {
        "the timestamp profiler could not start"
    };
    (TimeSource::CpuWait, format!("CPU waits, one per pass, which serialise the frame ({why})"))
}

/// The camera path in `file`, its keyframes given on the Earth placed in `dataset`'s CRS.
pub fn load_path(dataset: &Dataset, file: &Path) -> Result<CameraPath, PathError> {
    CameraPath::load_placed(file, &mut |key: &EarthKey| {
        let [lon_deg, lat_deg, height_m] = key.lonlat;
        let pose =
            GeoPose { lon_deg, lat_deg, height_m, heading_deg: key.heading_deg, pitch_deg: key.pitch_deg };
        let crs = dataset.place_on_earth(&pose, key.above_ground).map_err(|e| e.to_string())?;
        Ok(Keyframe { at: crs.position_m.to_array(), yaw_deg: crs.yaw_deg, pitch_deg: crs.pitch_deg })
    })
}

/// The path to profile `dataset` along when none is given, and its description.
pub fn default_path(dataset: &Dataset) -> Result<(CameraPath, String), ProfileError> {
    let m = &dataset.manifest;
    let (corner, extent) = (m.corner_m(), m.extent_m());
    let inside = |k: &Keyframe| (0..2).all(|i| (corner[i]..=corner[i] + extent[i]).contains(&k.at[i]));
    if m.name == "synthetic" {
        let path = CameraPath::parse(DEFAULT_PATH_TOML, "config/paths/default.toml")?;
        if path.keys.iter().all(inside) {
            return Ok((path, "config/paths/default.toml".into()));
        }
    }
    let (path, radius_m) = orbit_path(dataset)?;
    Ok((path, format!("orbit of radius {radius_m:.0} m around the dataset centre (generated)")))
}

/// A closed loop around the dataset's centre (radius 0.3 of its smaller side, eight keyframes),
/// `ORBIT_CLEARANCE_M` above the highest ground under each eighth of it, looking at the centre
/// and down by 8° to 30°. Returns the path and its radius.
pub fn orbit_path(dataset: &Dataset) -> Result<(CameraPath, f64), PackError> {
    let m = &dataset.manifest;
    let (corner, extent) = (m.corner_m(), m.extent_m());
    let centre = DVec3::new(corner[0] + 0.5 * extent[0], corner[1] + 0.5 * extent[1], 0.0);
    let radius_m = 0.3 * extent[0].min(extent[1]);
    let ground = |at: DVec3| dataset.height_at(at.x - m.origin_m[0], at.y - m.origin_m[1], 0);
    let on_circle = |deg: f64| {
        let a = deg.to_radians();
        centre + DVec3::new(a.sin(), a.cos(), 0.0) * radius_m
    };
    let centre_ground_m = ground(centre)?;
    let mut keys = Vec::with_capacity(9);
    for k in 0..8 {
        let deg = 45.0 * f64::from(k);
        let mut ground_m = f64::MIN;
        for step in -2..=2 {
            ground_m = ground_m.max(ground(on_circle(deg + 11.25 * f64::from(step)))?);
        }
        let at = on_circle(deg);
        let z_m = ground_m + ORBIT_CLEARANCE_M;
        let to_centre = centre - at;
        let down_deg = (z_m - centre_ground_m).atan2(radius_m).to_degrees().clamp(8.0, 30.0);
        keys.push(Keyframe {
            at: [at.x, at.y, z_m],
            yaw_deg: to_centre.x.atan2(to_centre.y).to_degrees().rem_euclid(360.0),
            pitch_deg: -down_deg,
        });
    }
    keys.push(keys[0]);
    Ok((CameraPath { keys }, radius_m))
}
