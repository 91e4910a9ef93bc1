//! How it works: one point of a sweep, and the reference it is judged against. Each gets a fresh
//! renderer (own device, cold caches), so points do not inherit each other's resident tiles.
//! - The reference: the accurate preset with caches as large as the layers and every tile pinned
//!   (`pin_everything`); at each sample pose its frame is rendered until resolved and read back.
//!   When seeds are drawn (`draw_seeds.impostors` set), a second such renderer without impostors gives
//!   the ground alone.
//! - A point: the timed flight through `profile::Session` (one step per frame), its summary; then
//!   at each sample pose the settled view's seeds go to the oracle and its frame is read back; with
//!   seeds drawn, a second renderer of the same settings without impostors settles the same poses
//!   for the ground alone.

use std::path::Path;

use glam::DVec3;
use image::RgbaImage;

use super::report::{PassTime, SampleFigures, SeedFigures, TradePoint};
use super::{Point, Progress, SweepError};
use crate::camera::Camera;
use crate::config::Settings;
use crate::dataset::Dataset;
use crate::frame::Renderer;
use crate::gpu::Gpu;
use crate::path::CameraPath;
use crate::profile::{Meta, Session, Summary, timing_of};
use crate::reference::accuracy::{HeightError, SeedAgreement};
use crate::reference::image_metrics::{capped_psnr_db, mse, psnr_of_mse, ssim};
use crate::reference::oracle::{OracleInputs, visible_seeds};

pub(super) struct Flight<'a> {
    pub dataset_dir: &'a Path,
    pub path: &'a CameraPath,
    /// Sample poses: path parameter and camera.
    pub poses: &'a [(f64, Camera)],
    pub warmup: u32,
    pub frames: u32,
}

/// The reference images of one pose: the frame, and the ground alone (`None`: the frame is it).
pub(super) struct Images {
    frame: RgbaImage,
    ground: Option<RgbaImage>,
}

impl Images {
    fn ground(&self) -> &RgbaImage {
        self.ground.as_ref().unwrap_or(&self.frame)
    }
}

/// A measured point, with how it was timed.
pub(super) struct Measured {
    pub adapter: String,
    pub timing_note: String,
    pub point: TradePoint,
}

fn without_impostors(settings: &Settings) -> Settings {
    let mut s = settings.clone();
    s.draw_seeds.impostors.clear();
    s
}

impl Flight<'_> {
    fn renderer(&self, settings: Settings) -> Result<Renderer, SweepError> {
        let dataset = Dataset::open(self.dataset_dir)?;
        let gpu = Gpu::new(settings.gpu.adapter)?;
        Ok(Renderer::new(gpu, dataset, settings)?)
    }

    /// Each pose settled in `renderer`, read back after `each` has looked at it.
    fn settle(
        &self,
        renderer: &mut Renderer,
        what: &str,
        progress: &mut dyn FnMut(Progress),
        mut each: impl FnMut(&Renderer, &Camera) -> Result<(), SweepError>,
    ) -> Result<Vec<RgbaImage>, SweepError> {
        let mut images = Vec::with_capacity(self.poses.len());
        for (i, (t, camera)) in self.poses.iter().enumerate() {
            progress(Progress::Step(&format!("{what}: pose {} of {} (t = {t:.2})", i + 1, self.poses.len())));
            renderer.render_resolved(camera)?;
            each(renderer, camera)?;
            images.push(renderer.read_colour()?);
        }
        Ok(images)
    }

    /// The all-resident renders of every pose, with `settings` (the accurate preset's).
    pub fn references(
        &self,
        settings: &Settings,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Vec<Images>, SweepError> {
        let pinned = |settings: Settings| -> Result<Renderer, SweepError> {
            let mut settings = settings;
            let dataset = Dataset::open(self.dataset_dir)?;
            let tiles = |layer: Option<&crate::dataset::LayerPack>| {
                layer.map_or(16, |l| l.pyramid.tile_count().min(u64::from(u32::MAX)) as u32).max(16)
            };
            let c = &mut settings.cache;
            c.height_slots = c.height_slots.max(tiles(Some(&dataset.height)));
            c.imagery_slots = c.imagery_slots.max(tiles(dataset.imagery.as_ref()));
            c.landcover_slots = c.landcover_slots.max(tiles(dataset.landcover.as_ref()));
            let mut renderer = Renderer::new(Gpu::new(settings.gpu.adapter)?, dataset, settings)?;
            renderer.pin_everything()?;
            Ok(renderer)
        };
        let none = |_: &Renderer, _: &Camera| Ok(());
        let frames = self.settle(&mut pinned(settings.clone())?, "reference", progress, none)?;
        let grounds = match settings.draw_seeds.impostors.is_empty() {
            true => vec![None; frames.len()],
            false => {
                let mut r = pinned(without_impostors(settings))?;
                self.settle(&mut r, "reference ground", progress, none)?.into_iter().map(Some).collect()
            }
        };
        Ok(frames.into_iter().zip(grounds).map(|(frame, ground)| Images { frame, ground }).collect())
    }

    /// Times `point` along the path, then measures it at every pose against `references`.
    pub fn measure(
        &self,
        point: &Point,
        settings: Settings,
        references: &[Images],
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Measured, SweepError> {
        let label = point.label();
        let draws_seeds = !settings.draw_seeds.impostors.is_empty();
        let mut renderer = self.renderer(settings.clone())?;
        let adapter = renderer.gpu.describe();
        let (timing, timing_note) = timing_of(&renderer);
        let summary = {
            let (fov_deg, near_m) = (settings.render.fov_deg, settings.render.near_m);
            let mut session = Session::new(&mut renderer, self.warmup);
            for i in 0..self.warmup + self.frames {
                // As `profile::fly`: warm-up at the start, timed frames spread over the whole path.
                let t = f64::from(i.saturating_sub(self.warmup)) / f64::from(self.frames.max(2) - 1);
                let what = if session.warming_up() { "warm-up" } else { "timed" };
                progress(Progress::Step(&format!(
                    "{label}: {what} frame {} of {}",
                    i + 1,
                    self.warmup + self.frames
                )));
                session.frame(&self.path.camera_at(t, fov_deg, near_m))?;
            }
            let recording = session.finish()?;
            let r = &settings.render;
            let meta = Meta {
                adapter: adapter.clone(),
                timing,
                timing_note: timing_note.clone(),
                resolution: [r.width, r.height],
                preset: label.clone(),
                settings: None,
                dataset: self.dataset_dir.display().to_string(),
                path: String::new(),
                warmup: self.warmup,
            };
            Summary::new(&recording, meta)
        };

        let mut seeds: Option<(SeedAgreement, HeightError)> = None;
        let mut per_pose: Vec<(SeedAgreement, HeightError)> = Vec::new();
        let frames = self.settle(&mut renderer, &label, progress, |r, camera| {
            let figures = seed_figures(r, camera)?;
            if let Some((agreement, height)) = figures {
                let (a, h) = seeds.get_or_insert_default();
                a.add(&agreement);
                h.add(&height);
                per_pose.push((agreement, height));
            }
            Ok(())
        })?;
        drop(renderer);
        let grounds = match draws_seeds {
            false => None,
            true => {
                let mut r = self.renderer(without_impostors(&settings))?;
                Some(self.settle(&mut r, &format!("{label} ground"), progress, |_, _| Ok(()))?)
            }
        };

        let mut samples = Vec::with_capacity(frames.len());
        let (mut frame_mse, mut ground_mse, mut ssim_sum) = (0.0, 0.0, 0.0);
        for (i, (frame, reference)) in frames.iter().zip(references).enumerate() {
            let ground = grounds.as_ref().map_or(frame, |g| &g[i]);
            let (f_mse, g_mse) = (mse(frame, &reference.frame)?, mse(ground, reference.ground())?);
            let s = ssim(frame, &reference.frame)?;
            (frame_mse, ground_mse, ssim_sum) = (frame_mse + f_mse, ground_mse + g_mse, ssim_sum + s);
            let seeds = per_pose.get(i).map(|(a, h)| SeedFigures::of(a, h));
            samples.push(SampleFigures {
                t: self.poses[i].0,
                ground_psnr_db: capped_psnr_db(psnr_of_mse(g_mse)),
                frame_psnr_db: capped_psnr_db(psnr_of_mse(f_mse)),
                frame_ssim: s,
                seeds,
            });
        }
        let n = samples.len().max(1) as f64;
        let passes = summary
            .passes
            .iter()
            .map(|p| PassTime { label: p.label.clone(), source: p.source, median_ms: p.stat.median_ms })
            .collect();
        let median = |s: &Option<crate::profile::stats::Stat>| s.as_ref().map(|s| s.median_ms);
        let point = TradePoint {
            label,
            preset: point.preset.clone(),
            knobs: point.knobs.iter().cloned().collect(),
            frame_ms: median(&summary.totals.frame_wall).unwrap_or(f64::NAN),
            gpu_ms: median(&summary.totals.gpu),
            cpu_ms: median(&summary.totals.cpu),
            fps: summary.fps.map(|f| f.median),
            seeds_selected: summary.seeds.selected_median,
            passes,
            seeds: seeds.map(|(a, h)| SeedFigures::of(&a, &h)),
            ground_psnr_db: capped_psnr_db(psnr_of_mse(ground_mse / n)),
            frame_psnr_db: capped_psnr_db(psnr_of_mse(frame_mse / n)),
            frame_ssim: ssim_sum / n,
            samples,
        };
        Ok(Measured { adapter, timing_note, point })
    }
}

/// The settled view's seeds against the oracle (`None` without land cover).
fn seed_figures(r: &Renderer, camera: &Camera) -> Result<Option<(SeedAgreement, HeightError)>, SweepError> {
    let (Some((tables, patterns)), Some((kept, _))) = (r.seed_world(), r.read_seeds()?) else {
        return Ok(None);
    };
    let inputs = OracleInputs {
        dataset: &r.dataset,
        settings: &r.settings,
        tables,
        patterns,
        camera,
        viewport_px: [r.settings.render.width, r.settings.render.height],
    };
    let (visible, _) = visible_seeds(&inputs)?;
    let origin = r.dataset.manifest.origin_m;
    let camera_grid_m = camera.position_m - DVec3::new(origin[0], origin[1], 0.0);
    Ok(Some((SeedAgreement::of(&kept, &visible), HeightError::of(&r.dataset, camera_grid_m, &kept)?)))
}
