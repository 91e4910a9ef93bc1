//! How it works: one point of a sweep, timed and judged against the ground truths (`truths`).
//! Every flight gets a fresh renderer (own device, cold caches), so points do not inherit each
//! other's resident tiles. `time_round` flies one timing round (warm-up, then its share of the
//! timed frames through `profile::Session`, one step per frame); the rounds' recordings pool into
//! one `Timed`. `measure` then settles each sample pose: its seeds go to the exact summit oracle
//! (height error, and agreement with pass 3's rule) and to the any-part oracle of its world's
//! truth (rendered first, in a renderer of its own), and its frame is judged against that truth,
//! whole and per distance band (`truth::compare`). Then, from the popping flight's first pose
//! settled, it flies the popping flight frame by frame as a user would (streaming and readbacks a
//! frame or two behind), and its frames' changes are judged against the truth's along the same
//! flight (`frame_change::Popping`). With seeds drawn, a second renderer of the same settings
//! with nothing grown (no impostors, `photo::photograph_settings`) settles the same poses for the
//! ground alone, judged against the truth's ground; it is also the photograph frame each pose's
//! frame is measured against (`photo::measure`: CIEDE2000 of 5 × 5 block means, pooled over the
//! poses). Without seeds drawn the frame is its own photograph.

use std::path::Path;

use image::RgbaImage;

use super::report::{AnyPartFigures, PassTime, SampleFigures, SeedFigures, TradePoint};
use super::truths::Truths;
use super::{Point, Progress, SweepError};
use crate::camera::Camera;
use crate::config::Settings;
use crate::dataset::Dataset;
use crate::frame::Renderer;
use crate::gpu::Gpu;
use crate::gpu::TimeSource;
use crate::gpu::gpu_types::SeedRecord;
use crate::path::CameraPath;
use crate::photo::measure::DeltaE;
use crate::photo::{PixelKeys, measure, photograph_settings, pixel_keys};
use crate::profile::{Meta, Recording, Session, Summary, timing_of};
use crate::reference::accuracy::{HeightError, SeedAgreement};
use crate::reference::frame_change::Popping;
use crate::reference::image_metrics::{capped_psnr_db, mse, psnr_of_mse};
use crate::reference::oracle::visible_seeds;
use crate::truth::compare::{bands, frame_error, pool};
use crate::truth::visibility::{Missed, Visibility, judge, missed};

pub(super) struct Flight<'a> {
    pub dataset_dir: &'a Path,
    pub path: &'a CameraPath,
    /// Sample poses: path parameter and camera.
    pub poses: &'a [(f64, Camera)],
    /// The popping flight: consecutive frames at a steady speed (empty: not measured).
    pub popping: &'a [Camera],
    pub warmup: u32,
    pub frames: u32,
}

/// A point's timed frames (one round, or its rounds pooled by `Recording::append`), with how
/// they were timed.
pub(super) struct Timed {
    pub adapter: String,
    pub timing: TimeSource,
    pub timing_note: String,
    pub recording: Recording,
}

impl Timed {
    /// Pools `other`'s frames into these.
    pub fn append(&mut self, other: Timed) {
        self.recording.append(other.recording);
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

    /// The frames of the popping flight in `renderer`: the first pose settled, then one frame per
    /// pose, each read back.
    fn fly_popping(
        &self,
        renderer: &mut Renderer,
        what: &str,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Vec<RgbaImage>, SweepError> {
        let mut frames = Vec::with_capacity(self.popping.len());
        for (i, camera) in self.popping.iter().enumerate() {
            progress(Progress::Step(&format!(
                "{what}: popping flight, frame {} of {}",
                i + 1,
                self.popping.len()
            )));
            // The truth's flight sways frame for frame alike.
            renderer.set_time_s(renderer.settings.wind.time_of_frame_s(i));
            match i {
                0 => _ = renderer.render_resolved(camera)?,
                _ => _ = renderer.render(camera)?,
            }
            frames.push(renderer.read_colour()?);
        }
        Ok(frames)
    }

    /// Times one round of `label`'s flight in a fresh renderer: the `round`-th of `rounds`
    /// consecutive shares of the `frames` timed frames spread along the whole path, after `warmup`
    /// frames where the share starts. The rounds together fly every timed frame once, each share
    /// as the one block of a single round would (consecutive frames as far apart along the path),
    /// so the frames see the same streaming and culling as `profile::fly`'s.
    pub fn time_round(
        &self,
        label: &str,
        settings: &Settings,
        (round, rounds): (u32, u32),
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Timed, SweepError> {
        let mut renderer = self.renderer(settings.clone())?;
        let adapter = renderer.gpu.describe();
        let (timing, timing_note) = timing_of(&renderer);
        let (fov_deg, near_m) = (settings.render.fov_deg, settings.render.near_m);
        let share = |r: u32| (u64::from(self.frames) * u64::from(r) / u64::from(rounds.max(1))) as u32;
        let t_of = |j: u32| f64::from(j) / f64::from(self.frames.max(2) - 1);
        let timed = share(round)..share(round + 1);
        let mut session = Session::new(&mut renderer, self.warmup);
        let flown = (0..self.warmup).map(|_| t_of(timed.start)).chain(timed.clone().map(t_of));
        let total = self.warmup as usize + timed.len();
        for (i, t) in flown.enumerate() {
            let what = if session.warming_up() { "warm-up" } else { "timed" };
            progress(Progress::Step(&format!(
                "{label}: round {} of {rounds}, {what} frame {} of {total}",
                round + 1,
                i + 1
            )));
            session.set_time_s(settings.wind.time_of_frame_s(i));
            session.frame(&self.path.camera_at(t, fov_deg, near_m))?;
        }
        Ok(Timed { adapter, timing, timing_note, recording: session.finish()? })
    }

    /// Measures `point` at every pose against its truths, with its timing pooled from its rounds.
    pub fn measure(
        &self,
        point: &Point,
        settings: Settings,
        timed: Timed,
        truths: &mut Truths,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Measured, SweepError> {
        let label = point.label();
        let draws_seeds = !settings.draw_seeds.impostors.is_empty();
        let r = &settings.render;
        let meta = Meta {
            adapter: timed.adapter.clone(),
            timing: timed.timing,
            timing_note: timed.timing_note.clone(),
            resolution: [r.width, r.height],
            preset: label.clone(),
            settings: None,
            dataset: self.dataset_dir.display().to_string(),
            path: String::new(),
            warmup: self.warmup,
        };
        let summary = Summary::new(&timed.recording, meta);
        let mut renderer = self.renderer(settings.clone())?;

        // The any-part oracle, where the truth drew seeds (impostors given): the truths of the
        // point's own world, rendered before its poses are settled (a separate renderer).
        let draws_truth_seeds = truths.options().reach_m > 0.0;
        if draws_truth_seeds {
            truths.ensure(self, &settings, progress)?;
        }
        let world = truths.of_world(&settings);
        let mut seeds: Option<(SeedAgreement, HeightError)> = None;
        let mut per_pose: Vec<(SeedAgreement, HeightError)> = Vec::new();
        let mut any_part: Vec<(Visibility, Missed)> = Vec::new();
        let mut keys: Vec<PixelKeys> = Vec::new();
        let frames = self.settle(&mut renderer, &label, progress, |r, camera| {
            keys.push(pixel_keys(r, camera)?);
            let kept = r.read_seeds()?.map(|(records, _)| records);
            if let Some((agreement, height)) = seed_figures(r, camera, kept.as_deref())? {
                let (a, h) = seeds.get_or_insert_default();
                a.add(&agreement);
                h.add(&height);
                per_pose.push((agreement, height));
            }
            let selected: Vec<([i64; 2], u32)> =
                kept.iter().flatten().map(|s| (s.address.map(i64::from), s.rank)).collect();
            if let (Some(truth), Some(inputs)) = (world.get(any_part.len()), r.oracle_inputs(camera)) {
                let visibility = judge(&truth.seeds, &truth.samples, selected.iter().copied());
                let missed = missed(&inputs, &truth.seeds, &truth.samples, selected.iter().copied())?;
                any_part.push((visibility, missed));
            }
            Ok(())
        })?;
        let flown = self.fly_popping(&mut renderer, &label, progress)?;
        drop(renderer);
        let popping = match flown.is_empty() {
            true => None,
            false => Some(Popping::of(&flown, truths.flight_images())?),
        };
        let grounds = match draws_seeds {
            false => None,
            true => {
                let mut r = self.renderer(photograph_settings(&without_impostors(&settings)))?;
                Some(self.settle(&mut r, &format!("{label} ground"), progress, |_, _| Ok(()))?)
            }
        };

        // Each frame against its photograph: the ground alone, or itself when nothing is drawn.
        let mut photo_blocks = Vec::new();
        for (i, (frame, keys)) in frames.iter().zip(&keys).enumerate() {
            let photograph = grounds.as_ref().map_or(frame, |g| &g[i]);
            photo_blocks.extend(measure(frame, photograph, keys)?.blocks.values);
        }
        let mut samples = Vec::with_capacity(frames.len());
        let mut errors = Vec::with_capacity(frames.len());
        let mut ground_mse = 0.0;
        let truth_reach_m = truths.options().reach_m;
        let (near_m, bands) = (settings.render.near_m, bands(&settings, truth_reach_m));
        // Its own world's truths, or without seeds in the truths, the reference's (the ground).
        let image_truths = if world.is_empty() { truths.images() } else { world };
        for (i, (frame, truth)) in frames.iter().zip(image_truths).enumerate() {
            let ground = grounds.as_ref().map_or(frame, |g| &g[i]);
            let g_mse = mse(ground, &truth.ground)?;
            ground_mse += g_mse;
            // Forest cover where the truth grew seeds and the frame has its own ground to tell them.
            let own_ground = grounds.as_ref().filter(|_| truth_reach_m > 0.0).map(|g| &g[i]);
            let error = frame_error(truth, near_m, frame, own_ground, &bands)?;
            samples.push(SampleFigures {
                t: self.poses[i].0,
                ground_psnr_db: capped_psnr_db(psnr_of_mse(g_mse)),
                frame_psnr_db: error.frame.psnr_db,
                frame_ssim: error.frame.ssim,
                frame_flip: error.frame.flip,
                seeds: per_pose.get(i).map(|(a, h)| SeedFigures::of(a, h)),
                any_part: any_part.get(i).map(|(v, m)| AnyPartFigures::of(v, m)),
            });
            errors.push(error);
        }
        let n = samples.len().max(1) as f64;
        let error = pool(&errors).ok_or_else(|| SweepError::Options("no sample pose".into()))?;
        let any_part = (!any_part.is_empty()).then(|| {
            let (mut visibility, mut missed) = (Visibility::default(), Missed::default());
            for (v, m) in &any_part {
                visibility.add(v);
                missed.add(m);
            }
            AnyPartFigures::of(&visibility, &missed)
        });
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
            any_part,
            ground_psnr_db: capped_psnr_db(psnr_of_mse(ground_mse / n)),
            frame_psnr_db: error.frame.psnr_db,
            frame_ssim: error.frame.ssim,
            frame_flip: error.frame.flip,
            photo_de2000: DeltaE::of(&photo_blocks)?,
            popping,
            error,
            samples,
        };
        Ok(Measured { adapter: timed.adapter, timing_note: timed.timing_note, point })
    }
}

/// The settled view's kept seeds against the summit oracle (`None` without land cover).
fn seed_figures(
    r: &Renderer,
    camera: &Camera,
    kept: Option<&[SeedRecord]>,
) -> Result<Option<(SeedAgreement, HeightError)>, SweepError> {
    let (Some(inputs), Some(kept)) = (r.oracle_inputs(camera), kept) else {
        return Ok(None);
    };
    let (visible, _) = visible_seeds(&inputs)?;
    let placing = r.exact_placing(camera);
    Ok(Some((SeedAgreement::of(kept, &visible), HeightError::of(&r.dataset, &placing, kept)?)))
}
