//! How it works: the ground truths a sweep judges its points against, one per sample pose and
//! seeded world (one `truth::TruthRenderer` per world renders all its poses). A point is judged
//! against the truth of its own world (its cell size, patterns, germ, seeds per pattern, class
//! table and placement): its selection by seed identity, its frame pixel by pixel, so a point that
//! grows another, equally dense forest (other patterns) is not charged for trees standing
//! elsewhere, while one that grows fewer (`seeds.density_scale`) or stops sooner is. Worlds are
//! keyed by those settings, and their truths rendered once and shared by every point of that
//! world. Popping is judged against the reference world's truth along the popping flight (its
//! images only: motion's changes, whatever the forest). Without impostors the truths grow no seeds
//! (there is no mesh to draw them with): every point's frame is judged against the reference's
//! truth (the ground alone), selections are not.

use super::measure::Flight;
use super::{Progress, SweepError};
use crate::config::Settings;
use crate::dataset::Dataset;
use crate::gpu::Gpu;
use crate::truth::{Truth, TruthOptions, TruthRenderer};

/// What makes two settings grow the same seeds, in the same places, seen through the same viewport
/// under the same sky.
fn world_key(s: &Settings) -> String {
    let (t, seeds) = (&s.tlm, &s.seeds);
    format!(
        "{}|{}|{}|{}|{}|{}|{}|{}x{}|{}|{}|{}|{:?}",
        t.cell_m,
        t.patterns,
        t.seed,
        seeds.seeds_per_pattern,
        seeds.class_table,
        seeds.sink_fraction,
        seeds.ground_colour_radius_m,
        s.render.width,
        s.render.height,
        s.render.fov_deg,
        s.wind.speed_m_s,
        s.wind.from_deg,
        s.clouds
    )
}

/// The worlds the truths of `reference` and `points` grow: how many truths per pose a sweep renders.
pub(super) fn world_count(reference: &Settings, points: &[Settings]) -> usize {
    let mut keys: Vec<String> = std::iter::once(reference).chain(points).map(world_key).collect();
    keys.sort();
    keys.dedup();
    keys.len()
}

/// The truths rendered so far, by world.
pub(super) struct Truths {
    options: TruthOptions,
    by_world: Vec<(String, Vec<Truth>)>,
    reference: String,
    /// The reference world's truth images along the popping flight (empty without one).
    flight: Vec<image::RgbaImage>,
}

impl Truths {
    /// The truths of `reference`'s world at every pose of `flight` and along its popping flight,
    /// rendered now.
    pub fn new(
        flight: &Flight,
        reference: &Settings,
        options: TruthOptions,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Self, SweepError> {
        let mut truths =
            Self { options, by_world: Vec::new(), reference: world_key(reference), flight: Vec::new() };
        truths.ensure(flight, reference, progress)?;
        if !flight.popping.is_empty() {
            let mut renderer = truths.renderer(flight, reference)?;
            for (i, camera) in flight.popping.iter().enumerate() {
                let n = flight.popping.len();
                progress(Progress::Step(&format!("truth: popping flight, frame {} of {n}", i + 1)));
                renderer.set_time_s(reference.wind.time_of_frame_s(i));
                truths.flight.push(renderer.render(camera)?.colour);
            }
        }
        Ok(truths)
    }

    fn renderer(&self, flight: &Flight, settings: &Settings) -> Result<TruthRenderer, SweepError> {
        let dataset = Dataset::open(flight.dataset_dir)?;
        let gpu = Gpu::new(settings.gpu.adapter)?;
        Ok(TruthRenderer::new(gpu, dataset, settings, &self.options)?)
    }

    /// The reference world's truth images along the popping flight, in flight order.
    pub fn flight_images(&self) -> &[image::RgbaImage] {
        &self.flight
    }

    /// What the truths grow and draw with.
    pub fn options(&self) -> &TruthOptions {
        &self.options
    }

    /// The reference world's truths, one per pose: what images are judged against when the truths
    /// grow no seeds.
    pub fn images(&self) -> &[Truth] {
        self.by_world.iter().find(|(k, _)| *k == self.reference).map_or(&[], |(_, t)| t)
    }

    /// Renders the truths of `settings`' world, one per pose, unless they are already here.
    pub fn ensure(
        &mut self,
        flight: &Flight,
        settings: &Settings,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<(), SweepError> {
        let key = world_key(settings);
        if self.by_world.iter().any(|(k, _)| *k == key) {
            return Ok(());
        }
        let mut truths = Vec::with_capacity(flight.poses.len());
        let mut renderer = self.renderer(flight, settings)?;
        for (i, (t, camera)) in flight.poses.iter().enumerate() {
            let n = flight.poses.len();
            progress(Progress::Step(&format!("truth: pose {} of {n} (t = {t:.2})", i + 1)));
            truths.push(renderer.render(camera)?);
        }
        self.by_world.push((key, truths));
        Ok(())
    }

    /// The truths of `settings`' world, one per pose (empty before `ensure`).
    pub fn of_world(&self, settings: &Settings) -> &[Truth] {
        let key = world_key(settings);
        self.by_world.iter().find(|(k, _)| *k == key).map_or(&[], |(_, t)| t)
    }
}
