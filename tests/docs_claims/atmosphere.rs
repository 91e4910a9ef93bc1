//! What docs/atmosphere.md quotes, and where each number is defined.

use terramp::gpu::layout::SKY_MARCHED_ABOVE_KM;

use super::claims::{Claim, Source, percent, plain, sci, test_const};

pub static ATMOSPHERE_CLAIMS: &[Claim] = &[
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
            (test_const("tests/atmosphere.rs", "TABLE_OFF"), sci),
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
];
