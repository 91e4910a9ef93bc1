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
];
