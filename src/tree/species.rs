//! How it works: a species is a set of Weber & Penn (1995) parameters as Wesslén & Seipel adapt
//! them for nordic trees: the trunk (level 0) and up to three levels of branches, each with its
//! length (relative to its parent's), curvature, the angle children leave at, how they rotate
//! around their parent, and how many there are; the crown's envelope (`Shape`); the leaves on the
//! last level (their number per stem, size, and the procedural texture they wear). Values are
//! per species, in metres and degrees; heights are nominal (the class tables scale each seed).

/// The crown's envelope: how the length of a first-level branch varies with its height on the
/// trunk (Weber & Penn's `ShapeRatio`, `r` = 1 at the crown's base, 0 at the top).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shape {
    /// Longest at the base, shortest at the top (spruce, fir).
    Conical,
    /// Longest half way up.
    Spherical,
    /// Longest low in the crown, rounded top (broadleaves).
    Hemispherical,
    /// Long throughout, narrowing to half at the top.
    TaperedCylindrical,
    /// Longest at 70 % of the way down, reaching half at the ends (pine, birch).
    TendFlame,
}

impl Shape {
    /// Weber & Penn's shape ratio in [0.2, 1] for `r` in [0, 1].
    pub fn ratio(self, r: f32) -> f32 {
        let r = r.clamp(0.0, 1.0);
        match self {
            Shape::Conical => 0.2 + 0.8 * r,
            Shape::Spherical => 0.2 + 0.8 * (std::f32::consts::PI * r).sin(),
            Shape::Hemispherical => 0.2 + 0.8 * (std::f32::consts::FRAC_PI_2 * r).sin(),
            Shape::TaperedCylindrical => 0.5 + 0.5 * r,
            Shape::TendFlame if r <= 0.7 => 0.5 + 0.5 * r / 0.7,
            Shape::TendFlame => 0.5 + 0.5 * (1.0 - r) / 0.3,
        }
    }
}

/// One level of stems: the trunk (level 0) or a level of branches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Level {
    /// Length as a fraction of the parent's (level 0: of the tree's height).
    pub length: f32,
    /// ± variation of `length`.
    pub length_v: f32,
    /// Segments along the stem; curvature is applied per segment.
    pub curve_res: u32,
    /// Bend over the stem's first half (the whole stem when `curve_back_deg` is 0), degrees.
    pub curve_deg: f32,
    /// Bend over the stem's second half, degrees (0: `curve_deg` spans the whole stem).
    pub curve_back_deg: f32,
    /// ± random bend of the whole stem, degrees, spread over its segments.
    pub curve_v_deg: f32,
    /// Angle between a stem and its parent, degrees; a negative `down_angle_v_deg` makes it grow
    /// with the stem's position down its parent instead (Weber & Penn: low branches of conifers
    /// hang lower).
    pub down_angle_deg: f32,
    /// ± variation of `down_angle_deg` (negative: by position down the parent).
    pub down_angle_v_deg: f32,
    /// Turn around the parent from one child to the next, degrees.
    pub rotate_deg: f32,
    /// ± variation of `rotate_deg`.
    pub rotate_v_deg: f32,
    /// Stems of this level on each parent (level 0: ignored, one trunk); deeper levels take fewer
    /// on shorter parents.
    pub branches: f32,
    /// Sides of the stem's tube (at least 3).
    pub sides: u32,
}

/// The procedural texture a species' leaves wear.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LeafKind {
    /// A card of needles along a twig (spruce, fir).
    NeedleSpray,
    /// A tuft of long needles fanning from the twig's end (pine).
    NeedleTuft,
    /// A pointed oval leaf with a midrib (oak, maple; bushes).
    Broad,
    /// A small triangular leaf (birch).
    Birch,
}

/// The leaves on the last level's stems.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Leaves {
    /// Leaves per last-level stem of full length (fewer towards the tree's inside).
    pub per_stem: f32,
    /// Length of a leaf quad, metres.
    pub length_m: f32,
    /// Width of a leaf quad, metres.
    pub width_m: f32,
    /// Angle between a leaf and its stem, degrees.
    pub down_angle_deg: f32,
    /// The texture they wear.
    pub kind: LeafKind,
    /// Base colour (linear RGB) of a healthy leaf.
    pub colour: [f32; 3],
}

/// A species: everything that makes the tree, given a seed and a health.
#[derive(Debug, Clone, PartialEq)]
pub struct Species {
    /// As `species` knows it.
    pub name: &'static str,
    /// The crown's envelope.
    pub shape: Shape,
    /// Fraction of the trunk bare of branches at its base.
    pub base_size: f32,
    /// Nominal height, metres.
    pub height_m: f32,
    /// ± variation of `height_m`.
    pub height_v_m: f32,
    /// Trunk radius at its base per metre of height.
    pub ratio: f32,
    /// Exponent of a child's radius against its length.
    pub ratio_power: f32,
    /// Widening of the trunk's foot (0: none).
    pub flare: f32,
    /// Bend of the deeper branches towards the sky (negative: towards the ground, birch).
    pub attraction_up: f32,
    /// The trunk, then up to three levels of branches.
    pub levels: Vec<Level>,
    /// The leaves on the last level.
    pub leaves: Leaves,
    /// Bark base colour (linear RGB).
    pub bark_colour: [f32; 3],
    /// Pale bark with dark bands (birch).
    pub birch_bark: bool,
}

/// The names `species` knows, for messages.
pub const NAMES: [&str; 5] = ["spruce", "pine", "birch", "broadleaf", "bush"];

/// A built-in species by name (`NAMES`).
pub fn species(name: &str) -> Option<Species> {
    match name {
        "spruce" => Some(spruce()),
        "pine" => Some(pine()),
        "birch" => Some(birch()),
        "broadleaf" => Some(broadleaf()),
        "bush" => Some(bush()),
        _ => None,
    }
}

const TRUNK: Level = Level {
    length: 1.0,
    length_v: 0.0,
    curve_res: 6,
    curve_deg: 0.0,
    curve_back_deg: 0.0,
    curve_v_deg: 12.0,
    down_angle_deg: 0.0,
    down_angle_v_deg: 0.0,
    rotate_deg: 0.0,
    rotate_v_deg: 0.0,
    branches: 1.0,
    sides: 8,
};

/// The defaults of a branch level; each species' levels say where they differ.
const BRANCH: Level = Level {
    length: 0.5,
    length_v: 0.1,
    curve_res: 3,
    curve_deg: 0.0,
    curve_back_deg: 0.0,
    curve_v_deg: 30.0,
    down_angle_deg: 45.0,
    down_angle_v_deg: 15.0,
    rotate_deg: 140.0,
    rotate_v_deg: 30.0,
    branches: 8.0,
    sides: 3,
};

/// Norway spruce: a narrow cone of drooping branches to the ground, needles along the twigs.
fn spruce() -> Species {
    Species {
        name: "spruce",
        shape: Shape::Conical,
        base_size: 0.08,
        height_m: 18.0,
        height_v_m: 3.0,
        ratio: 0.018,
        ratio_power: 1.4,
        flare: 0.6,
        attraction_up: -0.4,
        levels: vec![
            Level { curve_v_deg: 6.0, ..TRUNK },
            Level {
                length: 0.34,
                length_v: 0.05,
                curve_res: 4,
                curve_deg: 25.0,
                curve_v_deg: 20.0,
                down_angle_deg: 85.0,
                down_angle_v_deg: -35.0,
                rotate_deg: 137.5,
                rotate_v_deg: 15.0,
                branches: 70.0,
                sides: 5,
                ..BRANCH
            },
            Level {
                length: 0.45,
                curve_res: 2,
                curve_v_deg: 20.0,
                down_angle_deg: 55.0,
                down_angle_v_deg: 10.0,
                rotate_deg: 180.0,
                rotate_v_deg: 25.0,
                branches: 9.0,
                ..BRANCH
            },
        ],
        leaves: Leaves {
            per_stem: 12.0,
            length_m: 0.8,
            width_m: 0.5,
            down_angle_deg: 25.0,
            kind: LeafKind::NeedleSpray,
            colour: [0.045, 0.11, 0.05],
        },
        bark_colour: [0.16, 0.10, 0.07],
        birch_bark: false,
    }
}

/// Scots pine: a long bare trunk under a flat, open crown of needle tufts.
fn pine() -> Species {
    Species {
        name: "pine",
        shape: Shape::TendFlame,
        base_size: 0.55,
        height_m: 20.0,
        height_v_m: 4.0,
        ratio: 0.016,
        ratio_power: 1.3,
        flare: 0.4,
        attraction_up: 0.3,
        levels: vec![
            Level { curve_v_deg: 10.0, ..TRUNK },
            Level {
                length: 0.3,
                length_v: 0.08,
                curve_res: 4,
                curve_deg: -20.0,
                curve_v_deg: 40.0,
                down_angle_deg: 65.0,
                rotate_deg: 137.5,
                branches: 26.0,
                sides: 5,
                ..BRANCH
            },
            Level { length: 0.4, curve_deg: -20.0, ..BRANCH },
        ],
        leaves: Leaves {
            per_stem: 9.0,
            length_m: 0.8,
            width_m: 0.8,
            down_angle_deg: 30.0,
            kind: LeafKind::NeedleTuft,
            colour: [0.05, 0.10, 0.06],
        },
        bark_colour: [0.33, 0.16, 0.08],
        birch_bark: false,
    }
}

/// Silver birch: a slim white trunk, ascending branches with hanging twigs, small leaves.
fn birch() -> Species {
    Species {
        name: "birch",
        shape: Shape::TendFlame,
        base_size: 0.3,
        height_m: 16.0,
        height_v_m: 3.0,
        ratio: 0.014,
        ratio_power: 1.2,
        flare: 0.3,
        attraction_up: -0.8,
        levels: vec![
            Level { curve_v_deg: 14.0, ..TRUNK },
            Level {
                length: 0.38,
                length_v: 0.08,
                curve_res: 4,
                curve_deg: 20.0,
                down_angle_deg: 40.0,
                down_angle_v_deg: 12.0,
                rotate_deg: 137.5,
                rotate_v_deg: 20.0,
                branches: 28.0,
                sides: 5,
                ..BRANCH
            },
            Level { curve_deg: 40.0, down_angle_deg: 50.0, branches: 9.0, ..BRANCH },
        ],
        leaves: Leaves {
            per_stem: 14.0,
            length_m: 0.32,
            width_m: 0.32,
            down_angle_deg: 50.0,
            kind: LeafKind::Birch,
            colour: [0.14, 0.26, 0.05],
        },
        bark_colour: [0.75, 0.74, 0.70],
        birch_bark: true,
    }
}

/// A broadleaf (oak, maple): a short trunk under a wide, round crown of large leaves.
fn broadleaf() -> Species {
    Species {
        name: "broadleaf",
        shape: Shape::Hemispherical,
        base_size: 0.25,
        height_m: 14.0,
        height_v_m: 3.0,
        ratio: 0.028,
        ratio_power: 1.3,
        flare: 0.5,
        attraction_up: 0.4,
        levels: vec![
            Level { curve_v_deg: 20.0, ..TRUNK },
            Level {
                length: 0.55,
                curve_res: 4,
                curve_deg: -30.0,
                curve_v_deg: 40.0,
                down_angle_deg: 55.0,
                rotate_deg: 137.5,
                rotate_v_deg: 25.0,
                branches: 18.0,
                sides: 6,
                ..BRANCH
            },
            Level { length: 0.45, curve_deg: -10.0, curve_v_deg: 40.0, branches: 10.0, sides: 4, ..BRANCH },
            Level { curve_res: 2, branches: 5.0, ..BRANCH },
        ],
        leaves: Leaves {
            per_stem: 7.0,
            length_m: 0.45,
            width_m: 0.32,
            down_angle_deg: 45.0,
            kind: LeafKind::Broad,
            colour: [0.09, 0.2, 0.04],
        },
        bark_colour: [0.2, 0.16, 0.12],
        birch_bark: false,
    }
}

/// A bush: many thin stems from a short base, small dense leaves.
fn bush() -> Species {
    Species {
        name: "bush",
        shape: Shape::Spherical,
        base_size: 0.05,
        height_m: 1.4,
        height_v_m: 0.3,
        ratio: 0.02,
        ratio_power: 1.0,
        flare: 0.0,
        attraction_up: 0.5,
        levels: vec![
            Level { length: 0.5, curve_v_deg: 20.0, sides: 5, ..TRUNK },
            Level {
                length: 1.3,
                length_v: 0.2,
                curve_deg: -30.0,
                curve_v_deg: 40.0,
                down_angle_deg: 50.0,
                down_angle_v_deg: 20.0,
                rotate_deg: 137.5,
                branches: 12.0,
                ..BRANCH
            },
            Level { curve_res: 2, branches: 6.0, ..BRANCH },
        ],
        leaves: Leaves {
            per_stem: 8.0,
            length_m: 0.12,
            width_m: 0.09,
            down_angle_deg: 45.0,
            kind: LeafKind::Broad,
            colour: [0.07, 0.16, 0.04],
        },
        bark_colour: [0.18, 0.13, 0.09],
        birch_bark: false,
    }
}
