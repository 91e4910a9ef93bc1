//! `terramp sweep`: its arguments, and the progress bar and printing around `terramp::sweep`.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use terramp::sweep::{CSV_FILE, JSON_FILE, Knob, MARKDOWN_FILE, PLOT_FILE, Progress, SweepOptions};

#[derive(Args)]
pub struct SweepArgs {
    #[arg(long)]
    dataset: PathBuf,
    /// Camera path (config/paths/*.toml). Default: as `profile` chooses it.
    #[arg(long)]
    path: Option<PathBuf>,
    /// Folder for trade.csv, trade.json, trade.png and trade.md (created when missing).
    #[arg(long)]
    out: PathBuf,
    #[arg(long, value_delimiter = ',', default_value = "fast,balanced,accurate")]
    presets: Vec<String>,
    /// A settings key and values, each value a point with every preset (repeatable: points are
    /// the product), e.g. `--knob seeds.occlusion_tolerance_m=0.5,1,2`.
    #[arg(long)]
    knob: Vec<Knob>,
    /// Vary one knob at a time from each preset (a series per knob) instead of their product.
    #[arg(long)]
    series: bool,
    /// With --series, vary the knobs from these presets only (default: every preset measured).
    #[arg(long, value_delimiter = ',')]
    series_from: Vec<String>,
    /// Timed frames per point, spread evenly along the path.
    #[arg(long, default_value_t = 60)]
    frames: u32,
    /// Unprofiled frames at the path's start before the timed ones, in every timing round.
    #[arg(long, default_value_t = 10)]
    warmup: u32,
    /// Rounds the timed frames are split into, each round timing every point in turn (a fresh
    /// renderer each), so that the machine's load drifting over the sweep is shared by all points.
    #[arg(long, default_value_t = 3)]
    timing_rounds: u32,
    /// Poses along the path where accuracy is measured.
    #[arg(long, default_value_t = 3)]
    samples: u32,
    /// A TOML file laid over every preset and the reference, before the knobs (e.g. to set
    /// `seeds.impostors` so that frames show trees).
    #[arg(long)]
    settings: Option<PathBuf>,
    #[arg(long)]
    width: Option<u32>,
    #[arg(long)]
    height: Option<u32>,
    /// Frames of the flight popping is measured along (consecutive frames from the middle sample
    /// pose on, against the truth's); 0 does not measure popping.
    #[arg(long, default_value_t = 12)]
    popping_frames: u32,
    /// Metres the camera moves between the popping flight's frames (0.25 m: 15 m/s at 60 fps).
    /// Slow, so that motion alone changes few blocks much and the artefacts stand out.
    #[arg(long, default_value_t = 0.25)]
    popping_step_m: f64,
    /// The ground truths' samples per pixel along each axis.
    #[arg(long, default_value_t = 4)]
    truth_supersample: u32,
    /// The ground truths grow seeds out to this distance, metres.
    #[arg(long, default_value_t = terramp::truth::DEFAULT_REACH_M)]
    truth_reach_m: f64,
    /// Impostors the truths draw their meshes from (default: the settings' `draw_seeds.impostors`;
    /// without any, the truths are the ground alone and selections are not judged against them).
    #[arg(long)]
    truth_impostors: Option<PathBuf>,
}

impl SweepArgs {
    pub fn run(self) -> Result<()> {
        // What the points' frames will not draw, said before the sweep's minutes (the class table
        // and the impostors are the settings file's: no preset sets them).
        if let Some(preset) = self.presets.first() {
            let settings = terramp::config::Settings::load(preset, self.settings.as_deref())?;
            let dataset = terramp::dataset::Dataset::open(&self.dataset)?;
            if let Some(undrawn) = terramp::frame::UndrawnSeeds::of(&dataset, &settings)? {
                eprintln!("terramp: {undrawn}");
            }
        }
        let out = self.out;
        let options = SweepOptions {
            dataset: self.dataset,
            path: self.path,
            presets: self.presets,
            knobs: self.knob,
            series: self.series,
            series_from: self.series_from,
            settings: self.settings,
            frames: self.frames,
            warmup: self.warmup,
            timing_rounds: self.timing_rounds,
            samples: self.samples,
            width: self.width,
            height: self.height,
            popping_frames: self.popping_frames,
            popping_step_m: self.popping_step_m,
            truth: terramp::truth::TruthOptions {
                supersample: self.truth_supersample,
                reach_m: self.truth_reach_m,
                impostors: self.truth_impostors.unwrap_or_default(),
            },
        };
        let bar = indicatif::ProgressBar::new(0);
        bar.set_style(
            indicatif::ProgressStyle::with_template("{elapsed_precise} [{bar:30}] {pos}/{len} {wide_msg}")?
                .progress_chars("=> "),
        );
        let trade = terramp::sweep::run(&options, &mut |event| match event {
            Progress::Total(steps) => bar.set_length(steps),
            Progress::Step(what) => {
                bar.set_message(what.to_owned());
                bar.inc(1);
            }
        });
        bar.finish_and_clear();
        let trade = trade?;
        terramp::sweep::write_outputs(&trade, &out)?;
        print!("{}", terramp::sweep::tables::table(&trade));
        let files = [CSV_FILE, JSON_FILE, PLOT_FILE, MARKDOWN_FILE];
        println!("\nwrote {}", files.map(|f| out.join(f).display().to_string()).join(", "));
        Ok(())
    }
}
