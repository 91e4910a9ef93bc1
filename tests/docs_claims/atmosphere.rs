//! What docs/atmosphere.md quotes, and where each number is defined.

use terramp::gpu::layout::{
    FOLIAGE_SKY, FOLIAGE_SUN, FOLIAGE_SUN_WRAP, IRRADIANCE_DIRECTIONS_SIDE, MULTIPLE_DIRECTIONS_SIDE,
    SCENE_LIGHT_MAX, SKY_MARCHED_ABOVE_KM,
};
use terramp::passes::atmosphere::gpu::air::AIR_GROUP;
use terramp::passes::display::{SATURATION_CD_M2, SUN_ILLUMINANCE_LX};

use super::claims::{Claim, Source, grouped, km, percent, plain, sci, test_const};

pub static ATMOSPHERE_CLAIMS: &[Claim] = &[
    Claim {
        doc: "docs/atmosphere.md",
        quote: "it is gathered from {} × {} directions with the true phases at its first scattering",
        values: &[
            (Source::Value(MULTIPLE_DIRECTIONS_SIDE as f64), plain),
            (Source::Value(MULTIPLE_DIRECTIONS_SIDE as f64), plain),
        ],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "whose k₁ is Cornette and Shanks' published mean cosine within {})",
        values: &[(test_const("src/atmosphere/mod.rs", "PUBLISHED_OFF"), sci)],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "the sky's light along that ray (the test allows {} % between the two quadratures) and the transmittance table's share (the test allows {} %)",
        values: &[
            (test_const("tests/atmosphere.rs", "AERIAL_SKY_OFF"), percent),
            (test_const("tests/atmosphere.rs", "AERIAL_THROUGH_OFF"), percent),
        ],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "asserts a mean of at most {} % and a largest error of at most {} %",
        values: &[
            (test_const("tests/atmosphere.rs", "SKY_MEAN_ERROR"), percent),
            (test_const("tests/atmosphere.rs", "SKY_MAX_ERROR"), percent),
        ],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "against at least {} per unit of sun irradiance per steradian",
        values: &[(test_const("tests/atmosphere.rs", "LUMINANCE_FLOOR"), sci)],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "equal it within {} of each transmittance's optical depth, {} of each multiple-scattering texel, {} of each sky-view texel (stored as f16, whose step is 2⁻¹⁰), and {} in the three",
        values: &[
            (test_const("tests/atmosphere.rs", "DEPTH_OFF"), sci),
            (test_const("tests/atmosphere.rs", "MULTIPLE_OFF"), sci),
            (test_const("tests/atmosphere.rs", "SKY_VIEW_OFF"), sci),
            (test_const("tests/atmosphere.rs", "GRAZING_OFF"), sci),
        ],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "the twin's within {} levels of 8 bits",
        values: &[(test_const("tests/atmosphere.rs", "SKY_LEVELS"), plain)],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "`SKY_MARCHED_ABOVE_KM` ({} km)",
        values: &[(Source::Value(SKY_MARCHED_ABOVE_KM as f64), plain)],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "The test allows {} % a channel (`IRRADIANCE_OFF`)",
        values: &[(test_const("tests/air.rs", "IRRADIANCE_OFF"), percent)],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "irradiance texels and the daylight balance within {} (texels under 1 % of the brightest",
        values: &[(test_const("tests/air.rs", "TABLE_OFF"), sci)],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "the test allows {} % of each part beyond {} levels), where the air changes the ground beyond {} km by 14.5 levels on average (the test asks at least {})",
        values: &[
            (test_const("tests/air.rs", "AIR_OUTLIERS"), percent),
            (test_const("tests/air.rs", "AIR_LEVELS"), plain),
            (test_const("tests/air.rs", "FAR_M"), km),
            (test_const("tests/air.rs", "AIR_MIN_CHANGE"), plain),
        ],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "by the shares `FOLIAGE_SUN` ({}), `FOLIAGE_SUN_WRAP` ({}) and `FOLIAGE_SKY` ({})",
        values: &[
            (Source::Value(FOLIAGE_SUN as f64), plain),
            (Source::Value(FOLIAGE_SUN_WRAP as f64), plain),
            (Source::Value(FOLIAGE_SKY as f64), plain),
        ],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "kept under {} (`SCENE_LIGHT_MAX`), within the f16",
        values: &[(Source::Value(SCENE_LIGHT_MAX as f64), plain)],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "illuminance constant of the daylighting literature, {} lux (`SUN_ILLUMINANCE_LX`)",
        values: &[(Source::Value(SUN_ILLUMINANCE_LX), grouped)],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "a factor 1 / ({} × 2^EV100), ISO 12232). The default, {}, is",
        values: &[
            (Source::Value(SATURATION_CD_M2), plain),
            (Source::Setting { preset: None, key: "display.ev100" }, plain),
        ],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "The tests ask the single scattering within {} % on average and {} % at most (`SINGLE_MEAN`, `SINGLE_MAX`) and the tables' sky within {} % and {} % (`BRUNETON_MEAN`, `BRUNETON_MAX`)",
        values: &[
            (test_const("tests/bruneton.rs", "SINGLE_MEAN"), percent),
            (test_const("tests/bruneton.rs", "SINGLE_MAX"), percent),
            (test_const("tests/bruneton.rs", "BRUNETON_MEAN"), percent),
            (test_const("tests/bruneton.rs", "BRUNETON_MAX"), percent),
        ],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "The GPU's display equals the twin's within {} level of 8 bits over {} light steps",
        values: &[
            (test_const("tests/display.rs", "DISPLAY_LEVELS"), plain),
            (test_const("tests/display.rs", "STEPS"), plain),
        ],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "one bind group at `AIR_GROUP` = {}",
        values: &[(Source::Value(AIR_GROUP as f64), plain)],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "gathered over {} × {} directions of the upper half",
        values: &[
            (Source::Value(IRRADIANCE_DIRECTIONS_SIDE as f64), plain),
            (Source::Value(IRRADIANCE_DIRECTIONS_SIDE as f64), plain),
        ],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "| sky irradiance | {} × {} (`atmosphere.irradiance_lut`)",
        values: &[(Source::Setting { preset: None, key: "atmosphere.irradiance_lut" }, plain)],
    },
    Claim {
        doc: "docs/atmosphere.md",
        quote: "the truth 0.941, 0.867, 0.763 (the test allows {} % a channel)",
        values: &[(test_const("tests/air.rs", "CONTRAST_OFF"), percent)],
    },
];
