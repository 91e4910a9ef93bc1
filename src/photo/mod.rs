//! How it works: the amplified frame against the photograph (issue 43). The forest terramp grows
//! is meant to look, from afar, like the aerial imagery it grows from; this measures how far it
//! does, with no reference but the dataset's own imagery. One camera, two renderers of one
//! dataset and one device:
//! - the **amplified frame**: the settings as given (seeds, texcells, whatever they draw);
//! - the **photograph frame**: the same settings with nothing grown (`photograph_settings`:
//!   `seeds.density_scale` 0, `texcells.reach_m` 0), which is the ground pass alone: the imagery
//!   draped on the terrain, lit by the same sun and clouds and seen through the same air.
//!
//! Both are settled (`Renderer::render_resolved`) and read (`Renderer::read_colour`) through the
//! display's `linear` curve (`measured_settings`): no exposure and no tone curve, the light the
//! passes wrote, balanced for daylight and clipped at white (forest and fields lie far below it),
//! so the sRGB bytes decode to that light and every mean is taken in linear light. The ground's lighting and air are
//! in both frames alike: where the amplified frame shows its ground they cancel, and where it
//! shows a tree the tree is lit by the same sun and seen through the same air as the ground it
//! stands on, so what is left is what the amplification changed.
//! Each pixel is keyed by the terrain point it shows (`keys`: the level-0 imagery texel, and
//! whether its land cover grows trees), and `measure` compares the frames per texel footprint,
//! per 5 × 5 block and per pixel (CIEDE2000 of mean colours, `colour`; the amplified frame's
//! detail within footprints; the share of wooded pixels changed); `edges` tells from the
//! amplified frame's seeds whether the forest's edges follow the land cover's cells.

pub mod colour;
pub mod descent;
pub mod edges;
pub mod keys;
pub mod measure;
pub mod truth;

use std::sync::Arc;

use image::RgbaImage;
use serde::Serialize;
use thiserror::Error;

use crate::camera::{Camera, CameraError};
use crate::config::{Settings, ToneCurve};
use crate::dataset::{Dataset, PackError};
use crate::frame::{RenderError, Renderer};
use crate::gpu::Gpu;
pub use keys::pixel_keys;
pub use measure::{PhotoFigures, PixelKeys, measure};

/// Why a view could not be measured against its photograph.
#[derive(Debug, Error)]
pub enum PhotoError {
    /// A renderer could not be made, or a frame or a readback failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// The camera does not project onto the viewport.
    #[error(transparent)]
    Camera(#[from] CameraError),
    /// A land-cover tile could not be read.
    #[error(transparent)]
    Pack(#[from] PackError),
    /// The frames and the keys are not of one size, pixels.
    #[error(
        "photo: frames of {amplified:?} and {photograph:?} px, keys of {keys:?} px: one camera has one size"
    )]
    Size {
        /// The amplified frame's size.
        amplified: [u32; 2],
        /// The photograph frame's size.
        photograph: [u32; 2],
        /// The keys' size.
        keys: [u32; 2],
    },
    /// A descent that does not go down.
    #[error(
        "photo: a descent from {top_m} m to {bottom_m} m above the ground by {step} a frame: the top must be above the bottom, the bottom above 0 and the step within (0, 1)"
    )]
    Descent {
        /// The first camera's height above the ground below it, metres.
        top_m: f64,
        /// Where the descent ends, metres above that ground.
        bottom_m: f64,
        /// The share of its height the camera sinks each frame.
        step: f64,
    },
    /// A truth image could not be compared (its size differs from the frame's).
    #[error("photo: against the truth: {0}")]
    Truth(crate::reference::image_metrics::ImageMetricError),
    /// A colour difference came out NaN or infinite.
    #[error("photo: a colour difference is {0}")]
    NotFinite(f64),
}

/// The settings of the photograph frame: `settings` with nothing grown (no seeds selected, no
/// texcells drawn), the ground pass over the imagery alone.
pub fn photograph_settings(settings: &Settings) -> Settings {
    let mut s = settings.clone();
    s.seeds.density_scale = 0.0;
    s.texcells.reach_m = 0.0;
    s
}

/// `settings` as the measures render them: the display shows the frame's light itself
/// (`ToneCurve::Linear`), so colours are compared before any exposure or tone curve.
pub fn measured_settings(settings: &Settings) -> Settings {
    let mut s = settings.clone();
    s.display.tone_curve = ToneCurve::Linear;
    s
}

/// One view measured: both frames, what each pixel stands on, the figures.
pub struct PhotoView {
    /// The frame with the settings as given (sRGB).
    pub amplified: RgbaImage,
    /// The frame with `photograph_settings` (sRGB).
    pub photograph: RgbaImage,
    /// Per pixel, its imagery texel and whether it is wooded.
    pub keys: PixelKeys,
    /// The amplified frame against the photograph frame.
    pub figures: PhotoFigures,
}

/// What `photo.json` holds: the view and its figures.
#[derive(Debug, Clone, Serialize)]
pub struct PhotoReport {
    /// The dataset's folder.
    pub dataset: String,
    /// The camera: x, y, z (CRS metres), yaw, pitch (degrees).
    pub camera: [f64; 5],
    /// Vertical field of view, degrees.
    pub fov_deg: f64,
    /// The scene's time, seconds (wind, clouds).
    pub time_s: f64,
    /// The adapter the frames were rendered on.
    pub adapter: String,
    /// The figures.
    pub figures: PhotoFigures,
    /// Against a truth image of the same view, when one was given.
    pub truth: Option<truth::TruthFlip>,
}

/// Renders the view from `camera` (at `settings.render`'s size) with `settings` and with
/// `photograph_settings`, both settled at scene time `time_s` and displayed by
/// `measured_settings`, and measures one against the other; `amplified`, when given, stands for
/// the first (a frame of the same view and size rendered elsewhere, e.g. by another build, with
/// `display.tone_curve = "linear"`), and only the photograph frame is rendered.
pub fn measure_view(
    gpu: &Gpu,
    dataset: Arc<Dataset>,
    settings: &Settings,
    camera: &Camera,
    time_s: f64,
    amplified: Option<RgbaImage>,
) -> Result<PhotoView, PhotoError> {
    let settings = &measured_settings(settings);
    let settle = |settings: Settings| -> Result<(Renderer, RgbaImage), PhotoError> {
        let mut renderer = Renderer::new(gpu.clone(), Arc::clone(&dataset), settings)?;
        renderer.set_time_s(time_s);
        renderer.render_resolved(camera)?;
        let image = renderer.read_colour()?;
        Ok((renderer, image))
    };
    let (amplified, trees) = match amplified {
        Some(image) => (image, None),
        None => {
            let (renderer, image) = settle(settings.clone())?;
            (image, edges::tree_shares(&renderer, camera)?)
        }
    };
    let (photo_renderer, photograph) = settle(photograph_settings(settings))?;
    let keys = pixel_keys(&photo_renderer, camera)?;
    let mut figures = measure(&amplified, &photograph, &keys)?;
    figures.edges = trees.map(|trees| edges::edges(&keys, &trees));
    Ok(PhotoView { amplified, photograph, keys, figures })
}

/// The two frames side by side: the photograph on the left, the amplified frame on the right.
pub fn side_by_side(photograph: &RgbaImage, amplified: &RgbaImage) -> RgbaImage {
    let (w, h) = (photograph.width(), photograph.height().max(amplified.height()));
    let mut out = RgbaImage::new(w + amplified.width(), h);
    image::imageops::overlay(&mut out, photograph, 0, 0);
    image::imageops::overlay(&mut out, amplified, i64::from(w), 0);
    out
}

/// The figures as a table for a terminal, one line each.
pub fn table(figures: &PhotoFigures) -> String {
    let num = |v: Option<f64>, digits: usize| v.map_or("-".to_string(), |v| format!("{v:.digits$}"));
    let de = |d: Option<measure::DeltaE>| match d {
        Some(d) => format!("{:>7.2} {:>7.2} {:>7.2}", d.mean, d.p95, d.max),
        None => format!("{:>7} {:>7} {:>7}", "-", "-", "-"),
    };
    let (t, b) = (&figures.texels, &figures.blocks);
    let mut out = String::new();
    out.push_str(&format!(
        "{:<34} {:>7} {:>7} {:>7} {:>7}\n",
        "CIEDE2000, amplified vs photograph", "counted", "mean", "p95", "max"
    ));
    out.push_str(&format!("{:<34} {:>7} {}\n", "  imagery texel footprints", t.counted, de(t.delta_e)));
    out.push_str(&format!(
        "{:<34} {:>7} {}\n",
        format!("  {0} x {0} pixel blocks", measure::BLOCK_PX),
        b.counted,
        de(b.delta_e)
    ));
    out.push_str(&format!(
        "mean L* over footprints            amplified {}, photograph {}\n",
        num(t.amplified_mean_l, 2),
        num(t.photograph_mean_l, 2)
    ));
    out.push_str(&format!(
        "detail (std of linear Y in a footprint)  amplified {}, photograph {}\n",
        num(t.amplified_detail_y, 4),
        num(t.photograph_detail_y, 4)
    ));
    out.push_str(&format!(
        "contrast (that std over the mean)  amplified {}, photograph {}\n",
        num(t.amplified_contrast, 3),
        num(t.photograph_contrast, 3)
    ));
    out.push_str(&format!(
        "changed share of wooded pixels  {} ({} of {})\n",
        num(figures.changed_share, 4),
        figures.changed_px,
        figures.wooded_px
    ));
    if let Some(e) = &figures.edges {
        let stair = |s: &edges::Staircase| {
            format!("{} ({} trees, {} px near an edge)", num(s.step_share, 3), s.trees, s.pixels)
        };
        out.push_str(&format!(
            "trees' edges, step share (0 filtered, 1 on the cells): between seeded classes {}; all {}\n",
            stair(&e.between_seeded),
            stair(&e.all)
        ));
    }
    out
}
