//! What the docs quote, and where each number is defined. A page that quotes a tolerance, a bound
//! or a default gets a claim here; a test's tolerance a page quotes is a named constant (with its
//! reason beside it), which the claim names rather than retypes.

use terramp::camera::{MAX_COORDINATE_M, MIN_FOV_DEG};
use terramp::classes::{DEFAULT_GROUND_BLEND, MAX_SPECIES};
use terramp::gpu::layout::{
    SEED_DETAIL_FULL_PX, SEED_DETAIL_NONE_PX, TEXCELL_DETAIL_FULL_PX_M, TEXCELL_DETAIL_NONE_PX_M,
};
use terramp::photo::measure::{BLOCK_PX, MIN_PIXELS_PER_TEXEL};
use terramp::seeds::wind::{GUST_WAVELENGTH_M, LEAN_PER_SPEED_SQ, MAX_LEAN};
use terramp::truth::DEFAULT_REACH_M;

/// How a page writes a number.
pub type Format = fn(f64) -> String;

/// Where a quoted number is defined.
pub enum Source {
    /// `const NAME: T = V;` (Rust), `NAME = V` (Python) or `NAME=V` (shell) in a file of the
    /// repository; V a literal or a product of literals.
    Const { file: &'static str, name: &'static str },
    /// A literal in code, where `{}` stands in `pattern`, the first such after `from` (for files
    /// whose owners keep literals).
    Code { file: &'static str, from: &'static str, pattern: &'static str },
    /// A setting of `config/default.toml` under a preset (`None`: the defaults); an array fills as
    /// many `{}` as it holds.
    Setting { preset: Option<&'static str>, key: &'static str },
    /// One item of an array setting.
    SettingItem { preset: Option<&'static str>, key: &'static str, index: usize },
    /// A constant of the library, by its Rust name.
    Value(f64),
}

/// Words of a page, `{}` where each number stands, and the numbers' sources in order.
pub struct Claim {
    pub doc: &'static str,
    pub quote: &'static str,
    pub values: &'static [(Source, Format)],
}

/// A row of `docs/PRESETS.md`'s table: its knob cell's start, its preset cells' words, and the
/// settings that fill them.
pub struct PresetRow {
    pub knob: &'static str,
    pub cell: &'static str,
    pub keys: &'static [(&'static str, Format)],
}

/// A number rounded to 7 significant digits (an f32 constant's, a percentage's product), written
/// as Rust writes the shortest f64 that reads back to it: 60, 0.85, 0.0001.
pub fn plain(v: f64) -> String {
    let rounded: f64 = format!("{v:.6e}").parse().unwrap();
    if rounded == rounded.trunc() && rounded.abs() < 1e15 {
        format!("{}", rounded as i64)
    } else {
        format!("{rounded}")
    }
}

/// A share as a percentage: 0.995 → 99.5.
pub fn percent(v: f64) -> String {
    plain(100.0 * v)
}

/// A number rounded to 7 significant digits, in Rust's exponent form: 1e-6.
pub fn sci(v: f64) -> String {
    let rounded: f64 = format!("{v:.6e}").parse().unwrap();
    format!("{rounded:e}")
}

/// Metres as millimetres.
pub fn mm(v: f64) -> String {
    plain(v * 1000.0)
}

/// Metres as centimetres.
pub fn cm(v: f64) -> String {
    plain(v * 100.0)
}

/// Metres as kilometres.
pub fn km(v: f64) -> String {
    plain(v / 1000.0)
}

/// Bytes as MiB.
pub fn mib(v: f64) -> String {
    plain(v / 1048576.0)
}

/// KiB as MiB.
pub fn mib_of_kib(v: f64) -> String {
    plain(v / 1024.0)
}

/// An integer with thousands separated by commas: 1,024.
pub fn grouped(v: f64) -> String {
    let digits = plain(v);
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// A power of ten in superscript: 1e-4 → 10⁻⁴.
pub fn pow10(v: f64) -> String {
    let exponent = v.log10().round() as i32;
    let sup = |c: char| "⁰¹²³⁴⁵⁶⁷⁸⁹".chars().nth(c.to_digit(10).unwrap() as usize).unwrap();
    let digits: String = exponent.unsigned_abs().to_string().chars().map(sup).collect();
    format!("10{}{digits}", if exponent < 0 { "⁻" } else { "" })
}

/// A power of ten as `4e9`.
pub fn exp(v: f64) -> String {
    format!("{v:e}")
}

/// With its sign, a true minus: +1, 0, −0.5.
pub fn signed(v: f64) -> String {
    match v {
        v if v > 0.0 => format!("+{}", plain(v)),
        v if v < 0.0 => format!("−{}", plain(-v)),
        _ => "0".to_owned(),
    }
}

/// 0 as `auto` (the settings' automatic choice).
pub fn auto_zero(v: f64) -> String {
    if v == 0.0 { "auto".to_owned() } else { plain(v) }
}

/// A flag as `on` / `off`.
pub fn on_off(v: f64) -> String {
    if v != 0.0 { "on".to_owned() } else { "off".to_owned() }
}

/// Where `tests/streaming_faults.rs` sets its flight's faults (after its control flight, which
/// sets none).
const FAULTS: &str = "let control = fly(";

pub const fn test_const(file: &'static str, name: &'static str) -> Source {
    Source::Const { file, name }
}

const fn default(key: &'static str) -> Source {
    Source::Setting { preset: None, key }
}

pub static CLAIMS: &[Claim] = &[
    // The ground truth and its test.
    Claim {
        doc: "docs/truth.md",
        quote: "which seed; tolerance {} %)",
        values: &[(test_const("tests/truth.rs", "MIN_SAMPLES_AGREEING"), percent)],
    },
    Claim {
        doc: "docs/truth.md",
        quote: "union 0.93–1.00; tolerance {})",
        values: &[(test_const("tests/truth.rs", "MIN_SEED_IOU"), plain)],
    },
    Claim {
        doc: "docs/truth.md",
        quote: "depth within {} (relative; tolerance: {} % of them)",
        values: &[
            (test_const("tests/truth.rs", "DEPTH_TOLERANCE_REL"), pow10),
            (test_const("tests/truth.rs", "MIN_DEPTHS_AGREEING"), percent),
        ],
    },
    Claim {
        doc: "docs/truth.md",
        quote: "`--reach-m` (default {} km:",
        values: &[(Source::Value(DEFAULT_REACH_M), km)],
    },
    Claim {
        doc: "docs/photo.md",
        quote: "counted when there are at least {} of them",
        values: &[(Source::Value(MIN_PIXELS_PER_TEXEL as f64), plain)],
    },
    Claim {
        doc: "docs/photo.md",
        quote: "(`seeds.vegetation_bare` {}: none, `vegetation_full` {}: the class table's density)",
        values: &[(default("seeds.vegetation_bare"), plain), (default("seeds.vegetation_full"), plain)],
    },
    Claim {
        doc: "docs/texcells.md",
        quote: "(from {} to {} m a pixel, `TEXCELL_DETAIL_*_PX_M`)",
        values: &[
            (Source::Value(TEXCELL_DETAIL_FULL_PX_M as f64), plain),
            (Source::Value(TEXCELL_DETAIL_NONE_PX_M as f64), plain),
        ],
    },
    Claim {
        doc: "docs/photo.md",
        quote: "(`TEXCELL_DETAIL_FULL_PX_M` {} m to `TEXCELL_DETAIL_NONE_PX_M` {} m a pixel,",
        values: &[
            (Source::Value(TEXCELL_DETAIL_FULL_PX_M as f64), plain),
            (Source::Value(TEXCELL_DETAIL_NONE_PX_M as f64), plain),
        ],
    },
    Claim {
        doc: "docs/earth.md",
        quote: "the test allows {} roundings of the largest term",
        values: &[(test_const("tests/earth.rs", "ROUNDINGS"), plain)],
    },
    Claim {
        doc: "docs/earth.md",
        quote: "allows {} mm and {} mm); the truth",
        values: &[
            (test_const("src/reference/oracle/tests.rs", "MAX_SAG_HEIGHT_MISS_M"), mm),
            (test_const("src/reference/oracle/tests.rs", "MAX_SAG_TRACK_MISS_M"), mm),
        ],
    },
    Claim {
        doc: "docs/earth.md",
        quote: "(the test allows {} of it)",
        values: &[(test_const("tests/earth.rs", "STAND_MISS"), sci)],
    },
    Claim {
        doc: "docs/earth.md",
        quote: "sunk height (the test allows {} mm)",
        values: &[(test_const("tests/earth_seeds.rs", "MAX_ANCHOR_MISS_M"), mm)],
    },
    Claim {
        doc: "docs/earth.md",
        quote: "finest LOD is drawn (the test allows {} mm)",
        values: &[(test_const("data-tools/tests/earth_extremes.rs", "FINE_HEIGHT_M"), mm)],
    },
    Claim {
        doc: "docs/earth.md",
        quote: "(the test allows {} pixel)",
        values: &[(test_const("data-tools/tests/earth_horizon.rs", "MISS_PX"), plain)],
    },
    Claim {
        doc: "docs/light.md",
        quote: "`SEED_DETAIL_FULL_PX` ({}) pixels tall or less",
        values: &[(Source::Value(SEED_DETAIL_FULL_PX as f64), plain)],
    },
    Claim {
        doc: "docs/light.md",
        quote: "all of it at `SEED_DETAIL_NONE_PX` ({}) pixels and below",
        values: &[(Source::Value(SEED_DETAIL_NONE_PX as f64), plain)],
    },
    Claim {
        doc: "config/default.toml",
        quote: "(SEED_DETAIL_FULL_PX {} down to SEED_DETAIL_NONE_PX {})",
        values: &[
            (Source::Value(SEED_DETAIL_FULL_PX as f64), plain),
            (Source::Value(SEED_DETAIL_NONE_PX as f64), plain),
        ],
    },
    Claim {
        doc: "docs/photo.md",
        quote: "**per {} × {} pixel block**",
        values: &[(Source::Value(BLOCK_PX as f64), plain), (Source::Value(BLOCK_PX as f64), plain)],
    },
    // The README's trees.
    Claim {
        doc: "docs/README.md",
        quote: "`draw_seeds.reach_m` ({} m), then billboard clouds of 17, 8 and 2 planes out to the others ({}, {}, {} m)",
        values: &[(default("draw_seeds.reach_m"), plain)],
    },
    Claim {
        doc: "docs/README.md",
        quote: "(`draw_seeds.fade_fraction`, {})",
        values: &[(default("draw_seeds.fade_fraction"), plain)],
    },
    Claim {
        doc: "docs/README.md",
        quote: "`data-tools/tests/draw_seeds.rs`, which allows at most {}, and at most {} × the switch's",
        values: &[
            (test_const("data-tools/tests/draw_seeds.rs", "MAX_FADE_BLOCK_CHANGE"), plain),
            (test_const("data-tools/tests/draw_seeds.rs", "MAX_FADE_OF_POP"), plain),
        ],
    },
    Claim {
        doc: "docs/README.md",
        quote: "(it allows at most {} there)",
        values: &[(test_const("data-tools/tests/draw_seeds.rs", "MAX_CLASS_FADE_BLOCK_CHANGE"), plain)],
    },
    Claim {
        doc: "docs/README.md",
        quote: "`data-tools/tests/reference/nc_trees_320x180.png`, ≥ {} dB PSNR",
        values: &[(test_const("data-tools/tests/draw_seeds.rs", "MIN_PSNR_DB"), plain)],
    },
    Claim {
        doc: "docs/README.md",
        quote: "`imagery.anisotropy = {}` (automatic)",
        values: &[(default("imagery.anisotropy"), plain)],
    },
    Claim {
        doc: "docs/README.md",
        quote: "below `MIN_FOV_DEG` ({}°)",
        values: &[(Source::Value(MIN_FOV_DEG), plain)],
    },
    Claim {
        doc: "docs/README.md", quote: "beyond ±{} m", values: &[(Source::Value(MAX_COORDINATE_M), exp)]
    },
    // The viewer.
    Claim {
        doc: "docs/viewer.md",
        quote: "the image to ≥ {} dB PSNR (on lavapipe both views come out bit for bit",
        values: &[(test_const("tests/knobs.rs", "SAME_FRAME_PSNR_DB"), plain)],
    },
    Claim {
        doc: "docs/viewer.md",
        quote: "(the test asks ≥ {} dB: the line gives",
        values: &[(test_const("tests/viewer.rs", "WINDOW_PSNR_DB"), plain)],
    },
    // Seeds.
    Claim {
        doc: "docs/seeds.md",
        quote: "ground colours within {}/255",
        values: &[(test_const("tests/seed_select.rs", "MAX_COLOUR_ERROR"), plain)],
    },
    Claim {
        doc: "docs/seeds.md",
        quote: "The test asserts ≥ {} for every preset",
        values: &[(test_const("data-tools/tests/seed_spacing.rs", "MIN_BORDER_RATIO"), plain)],
    },
    Claim {
        doc: "docs/seeds.md",
        quote: "(the test asks ≥ {}), leave no point",
        values: &[(test_const("src/seeds/patterns/tests.rs", "MIN_CLOSEST_PAIR"), plain)],
    },
    Claim {
        doc: "docs/seeds.md",
        quote: "from a seed (≤ {}), and have",
        values: &[(test_const("src/seeds/patterns/tests.rs", "MAX_COVERAGE"), plain)],
    },
    Claim {
        doc: "docs/seeds.md",
        quote: "1st-percentile ratios of 1.02–2.1 (≥ {}).",
        values: &[(test_const("src/seeds/patterns/tests.rs", "MIN_BORDER_RATIO"), plain)],
    },
    Claim {
        doc: "docs/seeds.md",
        quote: "Over the outer `draw_seeds.fade_fraction` ({}) of its LOD's reach",
        values: &[(default("draw_seeds.fade_fraction"), plain)],
    },
    Claim {
        doc: "docs/seeds.md",
        quote: "(`tlm.patterns` {}: C = 2 corner colours)",
        values: &[(default("tlm.patterns"), plain)],
    },
    Claim {
        doc: "docs/seeds.md",
        quote: "spheres within its frustum margin ({} of the half-screen)",
        values: &[(Source::Setting { preset: Some("balanced"), key: "seeds.frustum_epsilon" }, plain)],
    },
    Claim {
        doc: "docs/seeds.md",
        quote: "a march of up to {} bilinear fetches",
        values: &[(default("seeds.occlusion_refine_steps"), grouped)],
    },
    // Trees and the wind.
    Claim {
        doc: "docs/trees.md",
        quote: "each variant's share within {} of an even split",
        values: &[(test_const("tests/seed_select.rs", "VARIANT_SHARE_TOLERANCE"), plain)],
    },
    Claim {
        doc: "docs/trees.md",
        quote: "holds at most {} models in all (`MAX_SPECIES`",
        values: &[(Source::Value(MAX_SPECIES as f64), plain)],
    },
    Claim {
        doc: "docs/trees.md",
        quote: "({} % of the height at 10 m/s, at most {} %)",
        values: &[(Source::Value(LEAN_PER_SPEED_SQ * 100.0), percent), (Source::Value(MAX_LEAN), percent)],
    },
    Claim {
        doc: "docs/trees.md",
        quote: "downwind at the wind's speed ({} m apart",
        values: &[(Source::Value(GUST_WAVELENGTH_M), plain)],
    },
    Claim {
        doc: "docs/trees.md",
        quote: "frame n / `wind.frame_rate_hz` ({})",
        values: &[(default("wind.frame_rate_hz"), plain)],
    },
    // Reliability.
    Claim {
        doc: "docs/RELIABILITY.md",
        quote: "A guard over 3 orbits of {} frames",
        values: &[(test_const("tests/seed_flight_memory.rs", "ORBIT"), plain)],
    },
    Claim {
        doc: "docs/RELIABILITY.md",
        quote: "may rise by at most {} MiB",
        values: &[(test_const("tests/seed_flight_memory.rs", "MAX_ANON_GROWTH_KIB"), mib_of_kib)],
    },
    Claim {
        doc: "docs/RELIABILITY.md",
        quote: "against a {} MiB bound",
        values: &[(test_const("scripts/soak_plot.py", "BOUND_MIB"), plain)],
    },
    Claim {
        doc: "docs/RELIABILITY.md",
        quote: "the test allows {} a frame)",
        values: &[(
            Source::Code { file: "tests/streaming_faults.rs", from: "", pattern: "|&px| px <= {})" },
            plain,
        )],
    },
    Claim {
        doc: "docs/RELIABILITY.md",
        quote: "(`[faults]`: {} % of tiles fail, {} % of the rest arrive corrupt, {} % of the rest damaged, every read waits up to {} ms",
        values: &[
            (Source::Code { file: "tests/streaming_faults.rs", from: FAULTS, pattern: "fail: {}," }, percent),
            (
                Source::Code { file: "tests/streaming_faults.rs", from: FAULTS, pattern: "corrupt: {}," },
                percent,
            ),
            (
                Source::Code { file: "tests/streaming_faults.rs", from: FAULTS, pattern: "damage: {}," },
                percent,
            ),
            (
                Source::Code { file: "tests/streaming_faults.rs", from: FAULTS, pattern: "delay_ms: {}," },
                plain,
            ),
        ],
    },
    Claim {
        doc: "docs/RELIABILITY.md",
        quote: "BC7 keeps alpha (within {} levels)",
        values: &[(test_const("data-tools/tests/build.rs", "BC7_MAX_ALPHA_ERROR"), plain)],
    },
    // Texcells, light, slicings, streaming: defaults.
    Claim {
        doc: "docs/texcells.md",
        quote: "`texcells.reach_m` ({} km by default)",
        values: &[(default("texcells.reach_m"), km)],
    },
    Claim {
        doc: "docs/texcells.md",
        quote: "by `texcells.ground_blend` ({} by default, the photograph's",
        values: &[(default("texcells.ground_blend"), plain)],
    },
    Claim {
        doc: "docs/light.md",
        quote: "(`clouds.scale_m`, {} m by default)",
        values: &[(default("clouds.scale_m"), plain)],
    },
    Claim {
        doc: "docs/light.md",
        quote: "`clouds.shadow_depth` ({})",
        values: &[(default("clouds.shadow_depth"), plain)],
    },
    Claim {
        doc: "docs/light.md",
        quote: "`ground_blend` (0 to 1, {} by default",
        values: &[(Source::Value(DEFAULT_GROUND_BLEND as f64), plain)],
    },
    Claim {
        doc: "docs/slicings.md",
        quote: "(m_s {}, the paper's)",
        values: &[(default("draw_seeds.slicing_brightness"), plain)],
    },
    Claim {
        doc: "docs/slicings.md",
        quote: "LOD 1 starts at {} m in `balanced`",
        values: &[(
            Source::SettingItem { preset: Some("balanced"), key: "draw_seeds.reach_m", index: 0 },
            plain,
        )],
    },
    Claim {
        doc: "docs/streaming.md",
        quote: "`upload_tiles_per_frame` = {} tiles to one cache, or more than {} MiB",
        values: &[
            (default("cache.upload_tiles_per_frame"), plain),
            (default("cache.upload_bytes_per_frame"), mib),
        ],
    },
    Claim {
        doc: "docs/streaming.md",
        quote: "the imagery cache fills its {} slots",
        values: &[(default("cache.imagery_slots"), plain)],
    },
    // The slicings.
    Claim {
        doc: "docs/slicings.md",
        quote: "The test asks at least {}.",
        values: &[(test_const("tests/slicings_views.rs", "MIN_AGREEMENT"), plain)],
    },
    Claim {
        doc: "docs/slicings.md",
        quote: "The test asserts that the slicings cover {} to {} of the clouds' pixels (0.929) and share at least {} of either's",
        values: &[
            (test_const("tests/slicings.rs", "MIN_COVERAGE_OF_CLOUDS"), plain),
            (test_const("tests/slicings.rs", "MAX_COVERAGE_OF_CLOUDS"), plain),
            (test_const("tests/slicings.rs", "MIN_SHARED_WITH_CLOUDS"), plain),
        ],
    },
];
