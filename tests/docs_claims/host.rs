//! What docs/host.md quotes, and where each number is defined.

use super::claims::{Claim, cm, grouped, mm, percent, plain, pow10, test_const};

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
    Claim {
        doc: "docs/host.md",
        quote: "Each picks {} pixels of a settled 320 × 180 view",
        values: &[(test_const("testkit/src/query.rs", "PICKS"), grouped)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "depth buffer gives for that pixel: within {} cm, or within the",
        values: &[(test_const("testkit/src/query.rs", "PICK_FLOOR_M"), cm)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "up to 2^-{} pixel ({} subpixel bits, the fewest Vulkan allows;",
        values: &[
            (test_const("testkit/src/query.rs", "SUBPIXEL_BITS"), plain),
            (test_const("testkit/src/query.rs", "SUBPIXEL_BITS"), plain),
        ],
    },
    Claim {
        doc: "docs/host.md",
        quote: "point is the pick's within {} mm (the test's bound), and of the pixels showing sky at most {} %",
        values: &[
            (test_const("testkit/src/query.rs", "HEIGHT_M"), mm),
            (test_const("testkit/src/query.rs", "SKY_PICKED"), percent),
        ],
    },
    Claim {
        doc: "docs/host.md",
        quote: "ask for the plants within {} m of {} picked points of a low view",
        values: &[
            (test_const("testkit/src/query.rs", "PLANTS_RADIUS_M"), plain),
            (test_const("testkit/src/query.rs", "PLANT_POINTS"), plain),
        ],
    },
    Claim {
        doc: "docs/host.md",
        quote: "{} % of the seeds near the points kept by the oracle and dropped by pass 3",
        values: &[(test_const("testkit/src/query.rs", "PLANTS_DROPPED"), percent)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "at most {} % kept by pass 3 and dropped by the oracle",
        values: &[(test_const("testkit/src/query.rs", "PLANTS_KEPT"), percent)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "a rotation that is not orthonormal within {})",
        values: &[(test_const("src/camera/from_host.rs", "HOST_MATRIX_TOLERANCE"), pow10)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "back from the camera within {} per element;",
        values: &[(test_const("src/camera/from_host_tests.rs", "ROUND_TRIP_OFF"), pow10)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "`tests/host_camera.rs` draws, on a {} × {} view",
        values: &[
            (test_const("tests/host_camera.rs", "SIDE"), plain),
            (test_const("tests/host_camera.rs", "SIDE"), plain),
        ],
    },
    Claim {
        doc: "docs/host.md",
        quote: "the test allows {} % apart, for seeds on the frustum's edge",
        values: &[(test_const("tests/host_camera.rs", "SELECTION_DIFFERENCE"), percent)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "at 81.7 dB PSNR on lavapipe (the test asks ≥ {} dB)",
        values: &[(test_const("tests/host_camera.rs", "TURNED_PSNR_DB"), plain)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "13.5 dB (the test asks it to stay ≤ {} dB)",
        values: &[(test_const("tests/host_camera.rs", "CONTROL_PSNR_DB"), plain)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "relative steps of 2^-11; the test allows {}),",
        values: &[(test_const("tests/display.rs", "HDR_STEPS"), plain)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "one of its 36,864 pixels (the test allows {});",
        values: &[(test_const("tests/host_hdr.rs", "TONED_LEVELS"), plain)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "each run drawing {} frames at 320 × 180",
        values: &[(test_const("tests/winit_host.rs", "FRAMES"), plain)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "frame is terramp's own (the test asks ≥ {} dB;",
        values: &[(test_const("tests/winit_host.rs", "OWN_VIEW_PSNR_DB"), plain)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "a {} m cube floating 2.6 km away",
        values: &[(test_const("tests/winit_host.rs", "CUBE_M"), plain)],
    },
    Claim {
        doc: "docs/host.md",
        quote: "changes 70 (the test asks at least {});",
        values: &[(test_const("tests/winit_host.rs", "SHOWN_PIXELS"), plain)],
    },
];
