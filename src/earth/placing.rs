//! How it works: where a renderer draws its dataset's grid points, frame by frame. A dataset whose
//! manifest records where it lies on the Earth (`EarthFrame`) is drawn on WGS 84's ellipsoid, seen
//! from the camera's frame (`LocalFrame::grid_aligned`: up along the ellipsoid's normal, the
//! grid's x direction turned into the horizontal); one without (a synthetic world, a local CRS),
//! or a renderer told `render.curved_earth = false`, is drawn as the flat sheet of its grid. Both
//! hand the GPU the same thing, a node's `EarthNode`: on the flat sheet the mapping is the
//! identity (first derivatives the axes, no second ones), which the shader's polynomial turns into
//! exactly the sum the flat sheet formed (the origin plus the offset; the zero terms add nothing).
//!
//! A node's mapping in Earth-centred axes (`EcefNode`) depends on the node alone, so it is formed
//! once (13 exact mappings) and kept, keyed by the node's origin; each frame only turns it into
//! the camera's frame. The CPU's culling asks `box_rel_m` for a camera-relative box that holds
//! what the GPU draws of a grid box: its lattice of corners and mid-points placed by the node's
//! polynomial, widened by what a quadratic can bulge between them and by the polynomial's third
//! order.

use std::collections::HashMap;
use std::sync::Arc;

use glam::DVec3;

use super::EarthFrame;
use super::horizon::{HorizonCone, SMALLEST_RADIUS_M};
use super::local::{EcefNode, LocalFrame};
use crate::gpu::gpu_types::EarthNode;

/// Nodes whose mappings are kept; past this the keep is emptied and refilled as frames ask.
pub const MAX_KEPT_NODES: usize = 1 << 16;

/// How a renderer places its dataset: on the ellipsoid, or flat.
#[derive(Debug, Clone)]
pub struct EarthPlacing {
    round: Option<Round>,
    /// Mappings formed so far, by their origin's grid position's bits.
    kept: HashMap<[u64; 3], EcefNode>,
}

#[derive(Debug, Clone)]
struct Round {
    earth: Arc<EarthFrame>,
    /// The grid's origin, CRS metres (`Manifest::origin_m`).
    origin_m: [f64; 2],
    /// The geoid's lowest undulation over the dataset (0 without one), metres.
    lowest_undulation_m: f64,
}

/// How far below the datum's lowest point the horizon's ellipsoid is lowered beyond the geoid's
/// lowest undulation, metres: a datum step's metres, and the parallel surface's departure from
/// a scaled ellipsoid (h e², centimetres).
const HORIZON_MARGIN_M: f64 = 10.0;

impl EarthPlacing {
    /// Placing on `earth` (when given and `curved`) for a grid whose origin is CRS point
    /// `origin_m`; flat otherwise.
    pub fn new(earth: Option<&EarthFrame>, origin_m: [f64; 2], curved: bool) -> Self {
        let round = earth.filter(|_| curved).map(|earth| {
            let lowest =
                earth.geoid.as_ref().map_or(0.0, |g| g.undulation_m.iter().copied().fold(0.0f32, f32::min));
            Round { earth: Arc::new(earth.clone()), origin_m, lowest_undulation_m: f64::from(lowest) }
        });
        Self { round, kept: HashMap::new() }
    }

    /// Whether the grid is drawn on the ellipsoid.
    pub fn is_round(&self) -> bool {
        self.round.is_some()
    }

    /// The exact placing (f64) seen from a camera at grid point `camera_grid_m`.
    pub fn exact(&self, camera_grid_m: DVec3) -> ExactPlacing {
        let round = self.round.as_ref().map(|round| {
            let [x, y] = [camera_grid_m.x + round.origin_m[0], camera_grid_m.y + round.origin_m[1]];
            RoundView {
                frame: LocalFrame::grid_aligned(&round.earth, x, y, camera_grid_m.z),
                earth: Arc::clone(&round.earth),
                origin_m: round.origin_m,
                lowest_undulation_m: round.lowest_undulation_m,
            }
        });
        ExactPlacing { camera_grid_m, round }
    }

    /// The placing `exact` (this placing's, from the frame's camera) with the node mappings kept,
    /// for a frame's GPU work: one frame's passes share one camera frame.
    pub fn view<'a>(&'a mut self, exact: &'a ExactPlacing) -> PlacedView<'a> {
        PlacedView { exact, kept: &mut self.kept }
    }
}

/// The placing from one camera, exact (f64): for the CPU, and for tests that judge the GPU.
#[derive(Debug, Clone)]
pub struct ExactPlacing {
    camera_grid_m: DVec3,
    /// `None` flat.
    round: Option<RoundView>,
}

/// The Earth seen from one camera.
#[derive(Debug, Clone)]
struct RoundView {
    /// The camera's frame (`LocalFrame::grid_aligned`).
    frame: LocalFrame,
    earth: Arc<EarthFrame>,
    /// The grid's origin, CRS metres.
    origin_m: [f64; 2],
    /// The geoid's lowest undulation over the dataset, metres.
    lowest_undulation_m: f64,
}

impl ExactPlacing {
    /// Whether the grid is placed on the ellipsoid.
    pub fn is_round(&self) -> bool {
        self.round.is_some()
    }

    /// The camera's grid position.
    pub fn camera_grid_m(&self) -> DVec3 {
        self.camera_grid_m
    }

    /// The mapping of the grid point under the camera, at height 0 (as `PlacedView::node` forms
    /// a node's, not kept: it moves with the camera): what places the seeds, none of which
    /// stands farther than their reach (kilometres) from it.
    pub fn nadir_node(&self) -> EarthNode {
        let nadir_grid_m = DVec3::new(self.camera_grid_m.x, self.camera_grid_m.y, 0.0);
        match &self.round {
            Some(RoundView { frame, earth, origin_m, .. }) => {
                let origin = nadir_grid_m + DVec3::new(origin_m[0], origin_m[1], 0.0);
                EarthNode::from(&frame.place(&EcefNode::at(earth, origin)))
            }
            None => flat_node(nadir_grid_m - self.camera_grid_m),
        }
    }

    /// The horizon this camera sees over ground no lower than `lowest_height_m` (the dataset's
    /// lowest): the ellipsoid lowered below it by the geoid's lowest undulation and
    /// `HORIZON_MARGIN_M`. `None` flat, or with the eye below that ellipsoid.
    pub fn horizon(&self, lowest_height_m: f64) -> Option<HorizonCone> {
        let RoundView { frame, lowest_undulation_m, .. } = self.round.as_ref()?;
        let height_m = lowest_height_m + lowest_undulation_m - HORIZON_MARGIN_M;
        HorizonCone::new(frame.eye_ecef_m, frame.local_from_ecef, height_m)
    }

    /// The camera-relative position of grid point `grid_m` (x, y and a height).
    pub fn position_rel_m(&self, grid_m: DVec3) -> DVec3 {
        match &self.round {
            Some(RoundView { frame, earth, origin_m, .. }) => {
                frame.position_m(earth, grid_m.x + origin_m[0], grid_m.y + origin_m[1], grid_m.z)
            }
            None => grid_m - self.camera_grid_m,
        }
    }

    /// The grid point (x, y and a height) placed at camera-relative `rel_m`: `position_rel_m`'s
    /// inverse (`EarthFrame::crs_m`), exact at any distance.
    pub fn grid_m(&self, rel_m: DVec3) -> DVec3 {
        match &self.round {
            Some(RoundView { frame, earth, origin_m, .. }) => {
                let ecef_m = frame.eye_ecef_m + frame.local_from_ecef.transpose() * rel_m;
                earth.crs_m(ecef_m) - DVec3::new(origin_m[0], origin_m[1], 0.0)
            }
            None => self.camera_grid_m + rel_m,
        }
    }
}

/// The flat sheet's mapping of a node whose origin lies `origin_rel_m` from the camera.
fn flat_node(origin_rel_m: DVec3) -> EarthNode {
    EarthNode { origin_m: origin_rel_m.as_vec3().extend(0.0).to_array(), ..EarthNode::FLAT }
}

/// One frame's placing: the camera's frame, and the dataset's mappings.
pub struct PlacedView<'a> {
    exact: &'a ExactPlacing,
    kept: &'a mut HashMap<[u64; 3], EcefNode>,
}

/// The mapping of a node whose origin is grid point `origin_grid_m`, formed once.
fn kept_node<'k>(
    kept: &'k mut HashMap<[u64; 3], EcefNode>,
    earth: &EarthFrame,
    origin_m: [f64; 2],
    origin_grid_m: DVec3,
) -> &'k EcefNode {
    if kept.len() >= MAX_KEPT_NODES {
        kept.clear();
    }
    let key = origin_grid_m.to_array().map(f64::to_bits);
    kept.entry(key)
        .or_insert_with(|| EcefNode::at(earth, origin_grid_m + DVec3::new(origin_m[0], origin_m[1], 0.0)))
}

impl PlacedView<'_> {
    /// The camera's grid position.
    pub fn camera_grid_m(&self) -> DVec3 {
        self.exact.camera_grid_m
    }

    /// The mapping of a node whose origin is grid point `origin_grid_m` (x, y and a height), for
    /// the GPU: offsets from that point go in, camera-relative positions come out.
    pub fn node(&mut self, origin_grid_m: DVec3) -> EarthNode {
        match &self.exact.round {
            Some(RoundView { frame, earth, origin_m, .. }) => {
                EarthNode::from(&frame.place(kept_node(self.kept, earth, *origin_m, origin_grid_m)))
            }
            None => flat_node(origin_grid_m - self.exact.camera_grid_m),
        }
    }

    /// Whether the Earth hides every point of the camera-relative box `lo`..`hi` from the camera
    /// (horizon culling, `ExactPlacing::horizon`, over ground no lower than `lowest_height_m`).
    /// Flat, or with the eye below that ground, nothing is hidden.
    pub fn hidden_by_earth(&self, lo: DVec3, hi: DVec3, lowest_height_m: f64) -> bool {
        self.exact.horizon(lowest_height_m).is_some_and(|cone| cone.hides_box(lo, hi))
    }

    /// A camera-relative box holding everything the GPU draws of the grid box `min_m`..`max_m`
    /// when its mapping's origin is the box's centre at height 0 (`node`).
    pub fn box_rel_m(&mut self, min_m: DVec3, max_m: DVec3) -> (DVec3, DVec3) {
        let camera_grid_m = self.exact.camera_grid_m;
        let Some(RoundView { frame, earth, origin_m, .. }) = &self.exact.round else {
            return (min_m - camera_grid_m, max_m - camera_grid_m);
        };
        let centre = DVec3::new(0.5 * (min_m.x + max_m.x), 0.5 * (min_m.y + max_m.y), 0.0);
        let node = *kept_node(self.kept, earth, *origin_m, centre);
        let half = 0.5 * (max_m - min_m);
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for j in -1..=1 {
            for i in -1..=1 {
                for h in [min_m.z, max_m.z] {
                    let offset = DVec3::new(f64::from(i) * half.x, f64::from(j) * half.y, h);
                    let p = frame.turn(node.position_m(offset) - frame.eye_ecef_m);
                    (lo, hi) = (lo.min(p), hi.max(p));
                }
            }
        }
        // Between lattice points half a side apart a quadratic strays from the chord by a quarter
        // of its second-order term there; the polynomial itself misses by its third order.
        let (a, b) = (half.x, half.y);
        let quadratic =
            0.25 * (node.d_xx.length() * a * a + node.d_xy.length() * a * b + node.d_yy.length() * b * b);
        let margin = DVec3::splat(quadratic + third_order_m(a, b));
        (lo - margin, hi + margin)
    }

    /// How far the GPU may draw a point of the grid box `min_m`..`max_m` from where the exact
    /// mapping puts it, when the box's mapping's origin is its centre at height 0 (`node`): the
    /// polynomial's third order. 0 flat.
    pub fn miss_bound_m(&self, min_m: DVec3, max_m: DVec3) -> f64 {
        if self.exact.round.is_none() {
            return 0.0;
        }
        third_order_m(0.5 * (max_m.x - min_m.x), 0.5 * (max_m.y - min_m.y))
    }
}

/// What a node's second-order polynomial misses the ellipsoid by at the corners of a box of
/// half-sides `a` and `b` about its origin: its third order, about r³ / 6R² at half-diagonal r,
/// doubled (the projection's own third order, on the frames the builder writes, is of the same
/// size: `the_miss_bound_holds_a_continent_wide`).
fn third_order_m(a: f64, b: f64) -> f64 {
    f64::hypot(a, b).powi(3) / (3.0 * SMALLEST_RADIUS_M * SMALLEST_RADIUS_M)
}

#[cfg(test)]
#[path = "placing_tests.rs"]
mod tests;
