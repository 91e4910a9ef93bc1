//! How it works: Weber & Penn's recursion. A stem is a chain of `curve_res` segments along its
//! local +Y, each turned about local X by the level's curvature (and a random wobble), the deeper
//! levels also pulled towards the sky or the ground (`attraction_up`); its radius tapers from its
//! base to a tenth at its tip (the trunk flares at its foot). Children leave a stem at offsets
//! spread along it, turned around it by the level's rotation and tilted away by its down angle;
//! their length follows the crown's `Shape` on the trunk and the parent's remaining length deeper
//! down. Leaves are quads along the last level's stems.
//!
//! Every stem and every leaf draws its random numbers from its own key, hashed from the tree's
//! seed and its path in the tree (child i of stem k), never from a shared stream: the tree's form
//! is the same at any health, and health only decides which parts are kept, each by comparing a
//! fixed uniform of its own against a keep probability that never grows as health falls. So a
//! sicker tree is exactly a subset of a healthier one (tested), and removing a branch removes its
//! children and leaves with it.

use std::f32::consts::PI;

use glam::{Quat, Vec3};

use super::species::{Level, Species};

/// A cross-section of a stem.
#[derive(Clone, Copy)]
pub struct Ring {
    pub centre: Vec3,
    /// Local +Y along the stem.
    pub frame: Quat,
    pub radius_m: f32,
    /// Where it is along the stem, as a fraction of its length.
    pub along: f32,
}

/// A stem's tube, ready to be meshed.
pub struct Tube {
    /// Depth in the tree: 0 for the trunk.
    pub level: usize,
    /// Base to tip.
    pub rings: Vec<Ring>,
    /// Sides of the tube.
    pub sides: u32,
}

/// A leaf quad: its base, its frame (local +Y from base to tip, local X across), its size.
pub struct Leaf {
    pub base: Vec3,
    pub frame: Quat,
    pub length_m: f32,
    pub width_m: f32,
    /// The uniform its survival was decided by: leaves sorted by it thin uniformly when a
    /// prefix is taken.
    pub rank: f32,
}

/// The kept parts of one tree.
pub struct Grown {
    pub tubes: Vec<Tube>,
    pub leaves: Vec<Leaf>,
    /// Height of the trunk, metres.
    pub height_m: f32,
}

/// Grows `species` from `seed` at `health` (0 dead .. 1 healthy).
pub fn grow(species: &Species, seed: u64, health: f32) -> Grown {
    let root = mix(seed ^ name_hash(species.name));
    let mut rng = Rng(root);
    let height_m = (species.height_m + species.height_v_m * rng.signed()).max(0.1);
    let trunk = &species.levels[0];
    let length_m = height_m * trunk.length;
    let mut grower =
        Grower { species, health, grown: Grown { tubes: Vec::new(), leaves: Vec::new(), height_m } };
    let stem = StemSpec {
        level: 0,
        key: mix(root ^ 0x7472_756e_6b00),
        origin: Vec3::ZERO,
        frame: Quat::IDENTITY,
        length_m,
        radius_m: height_m * species.ratio,
        relative_length: 1.0,
        offset_in_parent: 0.0,
    };
    grower.stem(&stem);
    grower.grown
}

/// Probability that a leaf is kept at `health`: moderate losses omit leaves at random (none left
/// at 0.2).
pub fn leaf_keep(health: f32) -> f32 {
    ((health - 0.2) / 0.8).clamp(0.0, 1.0)
}

/// Probability that a branch of `level` (≥ 1) is kept at `health`: larger losses remove the
/// twigs (from 0.5 down) and then half the limbs (from 0.25 down).
pub fn branch_keep(level: usize, health: f32) -> f32 {
    let threshold = if level == 1 { 0.25 } else { 0.5 };
    (1.0 - (threshold - health) / 0.5).clamp(0.0, 1.0)
}

struct StemSpec {
    level: usize,
    key: u64,
    origin: Vec3,
    frame: Quat,
    length_m: f32,
    radius_m: f32,
    /// Its length over the longest its level could be here, in (0, 1]: shorter stems carry
    /// fewer children.
    relative_length: f32,
    /// Where it leaves its parent, as a fraction of the parent's length.
    offset_in_parent: f32,
}

struct Grower<'a> {
    species: &'a Species,
    health: f32,
    grown: Grown,
}

impl Grower<'_> {
    fn stem(&mut self, stem: &StemSpec) {
        let level = &self.species.levels[stem.level];
        let mut rng = Rng(stem.key);
        let mut rings = self.walk(stem, level, &mut rng);
        if stem.level == 0 && self.species.flare > 0.0 {
            self.flare_rings(stem, &mut rings);
        }
        if stem.level + 1 < self.species.levels.len() {
            self.children(stem, &rings);
        } else {
            self.leaves(stem, &rings);
        }
        self.grown.tubes.push(Tube { level: stem.level, rings, sides: level.sides.max(3) });
    }

    /// The stem's rings, base to tip.
    fn walk(&self, stem: &StemSpec, level: &Level, rng: &mut Rng) -> Vec<Ring> {
        let segments = level.curve_res.max(1);
        let segment_m = stem.length_m / segments as f32;
        let wobble_deg = level.curve_v_deg * rng.signed();
        let mut frame = stem.frame;
        let mut at = stem.origin;
        let mut rings = Vec::with_capacity(segments as usize + 1);
        for s in 0..=segments {
            let along = s as f32 / segments as f32;
            rings.push(Ring { centre: at, frame, radius_m: self.radius(stem, along), along });
            if s == segments {
                break;
            }
            let bend_deg = if level.curve_back_deg == 0.0 {
                level.curve_deg / segments as f32
            } else if 2 * s < segments {
                level.curve_deg / (segments as f32 / 2.0)
            } else {
                level.curve_back_deg / (segments as f32 / 2.0)
            };
            let bend = (bend_deg + (wobble_deg + 0.3 * level.curve_v_deg * rng.signed()) / segments as f32)
                .to_radians();
            frame = (frame * Quat::from_rotation_x(bend)).normalize();
            if stem.level >= 2 {
                frame = attract(frame, self.species.attraction_up / segments as f32);
            }
            at += frame * Vec3::Y * segment_m;
        }
        rings
    }

    /// Rings low in the trunk's first segment, so that its foot flares over a metre or so
    /// instead of over the whole segment.
    fn flare_rings(&self, stem: &StemSpec, rings: &mut Vec<Ring>) {
        let (first, second) = (rings[0], rings[1]);
        let extra = [0.2, 0.5].map(|t| {
            let along = second.along * t * t;
            let at = first.centre.lerp(second.centre, along / second.along);
            Ring { centre: at, frame: first.frame, radius_m: self.radius(stem, along), along }
        });
        rings.splice(1..1, extra);
    }

    fn radius(&self, stem: &StemSpec, along: f32) -> f32 {
        let taper = 1.0 - 0.9 * along;
        let flare = match stem.level {
            0 => 1.0 + self.species.flare * (100f32.powf((1.0 - 8.0 * along).max(0.0)) - 1.0) / 100.0,
            _ => 1.0,
        };
        stem.radius_m * taper * flare
    }

    fn children(&mut self, parent: &StemSpec, rings: &[Ring]) {
        let level_index = parent.level + 1;
        let level = self.species.levels[level_index];
        let mut rng = Rng(mix(parent.key ^ 0x6368_696c_6400));
        let (first, count) = match parent.level {
            0 => (self.species.base_size, level.branches),
            _ => (0.1, level.branches * (0.2 + 0.8 * parent.relative_length)),
        };
        let count = (count + rng.unit()).floor() as u32;
        let mut turn_deg = 360.0 * rng.unit();
        for i in 0..count {
            let key = mix(parent.key ^ (u64::from(i) + 1).wrapping_mul(0x9e37_79b9_7f4a_7c15));
            let mut child_rng = Rng(key);
            let keep = child_rng.unit();
            let offset = first + (1.0 - first) * (i as f32 + 0.5 + 0.4 * child_rng.signed()) / count as f32;
            let offset = offset.clamp(first, 0.98);
            turn_deg += level.rotate_deg + level.rotate_v_deg * child_rng.signed();
            let (length_m, longest_m) = self.child_length(parent, &level, offset, &mut child_rng);
            if keep >= branch_keep(level_index, self.health) || length_m <= 0.0 {
                continue;
            }
            let (at, frame, radius_here) = along(rings, offset);
            let down_deg = match level.down_angle_v_deg {
                v if v < 0.0 => {
                    let r = self.crown_position(parent, offset);
                    level.down_angle_deg + v * (1.0 - 2.0 * super::Shape::Conical.ratio(r))
                }
                v => level.down_angle_deg + v * child_rng.signed(),
            };
            let frame = (frame
                * Quat::from_rotation_y(turn_deg.to_radians())
                * Quat::from_rotation_x(down_deg.to_radians()))
            .normalize();
            let radius_m = (parent.radius_m * (length_m / parent.length_m).powf(self.species.ratio_power))
                .min(0.9 * radius_here);
            self.stem(&StemSpec {
                level: level_index,
                key,
                origin: at,
                frame,
                length_m,
                radius_m,
                relative_length: (length_m / longest_m).clamp(0.0, 1.0),
                offset_in_parent: offset,
            });
        }
    }

    /// A child's length at `offset` along `parent`, and the longest its level could be there.
    fn child_length(&self, parent: &StemSpec, level: &Level, offset: f32, rng: &mut Rng) -> (f32, f32) {
        let factor = level.length + level.length_v * rng.signed();
        match parent.level {
            0 => {
                let longest = parent.length_m * level.length;
                let shape = self.species.shape.ratio(self.crown_position(parent, offset));
                (parent.length_m * factor * shape, longest)
            }
            _ => {
                let room = parent.length_m * (1.0 - 0.6 * offset);
                (factor * room, level.length * parent.length_m)
            }
        }
    }

    /// Weber & Penn's position in the crown for the shape ratio: 1 at the crown's base, 0 at the top.
    fn crown_position(&self, parent: &StemSpec, offset: f32) -> f32 {
        let base = if parent.level == 0 { self.species.base_size } else { 0.0 };
        (1.0 - offset) / (1.0 - base).max(1e-3)
    }

    fn leaves(&mut self, stem: &StemSpec, rings: &[Ring]) {
        let leaves = self.species.leaves;
        let mut rng = Rng(mix(stem.key ^ 0x6c65_6166));
        let wanted = leaves.per_stem * super::Shape::TaperedCylindrical.ratio(stem.offset_in_parent);
        let count = (wanted + rng.unit()).floor() as u32;
        let mut turn_deg = 360.0 * rng.unit();
        for j in 0..count {
            let mut leaf_rng = Rng(mix(stem.key ^ (u64::from(j) + 1).wrapping_mul(0xc2b2_ae3d_27d4_eb4f)));
            let rank = leaf_rng.unit();
            let offset = ((j as f32 + 0.5 + 0.4 * leaf_rng.signed()) / count as f32).clamp(0.05, 1.0);
            turn_deg += 137.5 + 20.0 * leaf_rng.signed();
            if rank >= leaf_keep(self.health) {
                continue;
            }
            let (at, frame, _) = along(rings, offset);
            let down = (leaves.down_angle_deg + 15.0 * leaf_rng.signed()).to_radians();
            let frame = (frame * Quat::from_rotation_y(turn_deg.to_radians()) * Quat::from_rotation_x(down))
                .normalize();
            let size = 1.0 + 0.15 * leaf_rng.signed();
            self.grown.leaves.push(Leaf {
                base: at,
                frame,
                length_m: leaves.length_m * size,
                width_m: leaves.width_m * size,
                rank,
            });
        }
    }
}

/// The point, frame and radius at `fraction` of a stem's length.
fn along(rings: &[Ring], fraction: f32) -> (Vec3, Quat, f32) {
    let fraction = fraction.clamp(0.0, 1.0);
    let i = rings[1..].iter().position(|r| r.along >= fraction).unwrap_or(rings.len() - 2);
    let (a, b) = (rings[i], rings[i + 1]);
    let t = ((fraction - a.along) / (b.along - a.along).max(1e-6)).clamp(0.0, 1.0);
    (a.centre.lerp(b.centre, t), a.frame.slerp(b.frame, t), a.radius_m + (b.radius_m - a.radius_m) * t)
}

/// Turns `frame`'s stem direction towards the sky by `strength` × its declination (towards the
/// ground when negative), never past vertical.
fn attract(frame: Quat, strength: f32) -> Quat {
    let direction = frame * Vec3::Y;
    let declination = direction.y.clamp(-1.0, 1.0).acos();
    let axis = direction.cross(Vec3::Y);
    if axis.length_squared() < 1e-8 {
        return frame;
    }
    let angle = match strength >= 0.0 {
        true => (strength * declination).min(declination),
        false => (strength * declination).max(declination - PI),
    };
    (Quat::from_axis_angle(axis.normalize(), angle) * frame).normalize()
}

/// SplitMix64's finaliser: a well-mixed 64-bit hash of `x`.
fn mix(mut x: u64) -> u64 {
    x = x.wrapping_add(0x9e37_79b9_7f4a_7c15);
    x = (x ^ (x >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// FNV-1a of a species name, so that two species grown from one seed differ.
fn name_hash(name: &str) -> u64 {
    name.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3))
}

/// A SplitMix64 stream: each stem and leaf has its own.
pub(super) struct Rng(pub u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        mix(self.0)
    }

    /// Uniform in [0, 1).
    pub(super) fn unit(&mut self) -> f32 {
        (self.next() >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Uniform in [−1, 1).
    pub(super) fn signed(&mut self) -> f32 {
        2.0 * self.unit() - 1.0
    }
}
