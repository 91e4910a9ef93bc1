//! What docs/host.md quotes, and where each number is defined.

use super::claims::{Claim, plain, test_const};

pub static HOST_CLAIMS: &[Claim] = &[
    Claim {
        doc: "docs/host.md",
        quote: "0 pixels differing on lavapipe (PSNR ≥ {} dB asked elsewhere)",
        values: &[(test_const("tests/host_device.rs", "SAME_FRAME_PSNR_DB"), plain)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "(the same pixels; the test asks ≥ {} dB PSNR, which half a degree of turn fails",
        values: &[(test_const("tests/resize.rs", "SAME_FRAME_PSNR_DB"), plain)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "the view without the wall (the test asks ≥ {} dB: what streams",
        values: &[(test_const("tests/host_frame.rs", "BESIDE_WALL_PSNR_DB"), plain)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "through every tone curve, within {} level of 8 bits (the test's bound)",
        values: &[(test_const("tests/display.rs", "DISPLAY_LEVELS"), plain)],
    },
];
