//! How it works: fits a fixed number of planes to a model's triangles, after Décoret et al.'s
//! billboard clouds (2003) as adapted to trees by Fuhrmann et al. (2005).
//!
//! **Plane space.** A plane is a unit normal n (one per ±n pair: about 400 directions spread
//! evenly over the upper hemisphere by a Fibonacci lattice, plus the axes and the vertical
//! diagonals) and an offset d = n·(p − c) from the model's centre c, discretised in bins of
//! max(ε/4, R/1024) over [−R, R] (R the bounding radius).
//!
//! **Density, greedy choice.** A triangle is *valid* for a plane when its three vertices lie
//! within ε of it; over the offsets of one direction that is an interval, so a difference array
//! sums, for every offset bin at once, the projected areas (area × |n·n_tri|: nearly tangent
//! planes win) of the triangles valid there. The densest (n, d) is kept (d at the middle of its
//! plateau), its direction refined on 5 × 5 grids of shrinking steps (3 rounds, down to ~1°), its
//! valid triangles removed, and the next plane chosen among the rest.
//!
//! **An upright skeleton.** Seen from near the horizon (how distant trees are seen), a cloud
//! whose planes all turn edge-on for some azimuth makes the tree vanish there: 2 greedy planes
//! on a pine are a vertical one and a horizontal one (its tiers), invisible from the side of the
//! vertical one. So the first `upright_planes` (3) planes must be upright (normal within
//! `max_tilt_deg`, 30°, of horizontal) and at least `min_azimuth_deg` (60°) apart in azimuth: 2
//! planes give a crossed pair, 3 a star. Later planes are free: horizontal tiers and parallel
//! layers are what makes a crown look deep up close. The rule gives way for a plane when nothing
//! it allows has anything left to cover. The price: from straight above, a 2-plane cloud is a
//! cross (the 8- and 17-plane clouds keep their horizontal planes).
//!
//! **The tolerance.** Décoret fixes ε and gets some number of planes; here the number is fixed
//! (17, 8, 2), so ε is the smallest (bisection over [R/256, R], geometric, 10 steps) for which
//! that many greedy planes cover `coverage` (99 %) of the model's area: coarser LODs get a larger
//! ε from the same full geometry. The few triangles left go to the plane nearest to them.
//!
//! **What each plane shows.** Every triangle valid for it (a triangle near two planes is drawn on
//! both, which avoids cracks, as in Décoret), plus its leftovers. Should the greedy cover
//! everything with fewer planes than asked (a nearly flat model), the plane drawing the most
//! triangles is split in two halves along its longer side until the count is met.

use glam::Vec3;
use rayon::prelude::*;
use thiserror::Error;

/// Why no planes could be fitted.
#[derive(Debug, Error, Clone, Copy, PartialEq, Eq)]
pub enum FitError {
    /// The LOD asks for 0 planes.
    #[error("a billboard cloud needs at least one plane")]
    NoPlanes,
    /// The model's triangles add up to no area: there are none, or all are degenerate.
    #[error("the model has no triangle with an area")]
    NoArea,
}

/// The fit's parameters (see the module doc).
#[derive(Debug, Clone, Copy)]
pub struct FitParams {
    /// Fraction of the model's area the planes must cover at the chosen ε.
    pub coverage: f32,
    /// The first `upright_planes` planes are upright within `max_tilt_deg` and pairwise at least
    /// `min_azimuth_deg` apart in azimuth.
    pub upright_planes: usize,
    pub max_tilt_deg: f32,
    pub min_azimuth_deg: f32,
    /// Fibonacci directions over the hemisphere.
    pub directions: usize,
    pub bisection_steps: u32,
}

impl Default for FitParams {
    fn default() -> Self {
        Self {
            coverage: 0.99,
            upright_planes: 3,
            max_tilt_deg: 30.0,
            min_azimuth_deg: 60.0,
            directions: 400,
            bisection_steps: 10,
        }
    }
}

/// One fitted plane: the points p with `normal · p = offset_m` (model space).
#[derive(Debug, Clone)]
pub struct FittedPlane {
    pub normal: Vec3,
    pub offset_m: f32,
    /// The triangles drawn on it (indices into the fitted list), ascending.
    pub triangles: Vec<u32>,
}

#[derive(Debug, Clone)]
pub struct Fit {
    pub epsilon_m: f32,
    pub planes: Vec<FittedPlane>,
    /// Fraction of the area within ε of some plane.
    pub covered_fraction: f32,
    /// The farthest a leftover triangle's vertex is from the plane it was given to (0 if none).
    pub max_leftover_distance_m: f32,
}

struct Model<'a> {
    triangles: &'a [[Vec3; 3]],
    centre: Vec3,
    radius: f32,
    area: Vec<f32>,
    normal: Vec<Vec3>,
}

impl Model<'_> {
    /// Min and max of n·(p − c) over triangle `t`'s vertices.
    fn range(&self, n: Vec3, t: usize) -> [f32; 2] {
        let d = self.triangles[t].map(|p| n.dot(p - self.centre));
        [d[0].min(d[1]).min(d[2]), d[0].max(d[1]).max(d[2])]
    }

    /// The best offset along `n` for the triangles `alive`, and its density.
    fn best_offset(
        &self,
        n: Vec3,
        ranges: impl Iterator<Item = (usize, [f32; 2])>,
        epsilon: f32,
    ) -> (f32, f32) {
        let r = self.radius;
        let step = (epsilon / 4.0).max(r / 1024.0);
        let bins = (2.0 * r / step).ceil() as usize + 1;
        let mut diff = vec![0.0f64; bins + 1];
        for (t, [lo, hi]) in ranges {
            let (from, to) = (hi - epsilon, lo + epsilon);
            if from > to {
                continue;
            }
            let b0 = ((from + r) / step).ceil().max(0.0) as usize;
            let b1 = ((to + r) / step).floor().min((bins - 1) as f32);
            if b1 < 0.0 || b0 > b1 as usize {
                continue;
            }
            let w = f64::from(self.area[t] * n.dot(self.normal[t]).abs());
            diff[b0] += w;
            diff[b1 as usize + 1] -= w;
        }
        let mut density = Vec::with_capacity(bins);
        let mut sum = 0.0f64;
        for d in &diff[..bins] {
            sum += d;
            density.push(sum);
        }
        let (best, score) =
            density.iter().enumerate().fold((0, 0.0), |acc, (b, &s)| if s > acc.1 { (b, s) } else { acc });
        let (mut first, mut last) = (best, best);
        while first > 0 && density[first - 1] >= score {
            first -= 1;
        }
        while last + 1 < bins && density[last + 1] >= score {
            last += 1;
        }
        (score as f32, -r + step * (first + last) as f32 / 2.0)
    }
}

/// Directions over the upper hemisphere (one per ±n pair).
fn directions(count: usize) -> Vec<Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    let mut dirs: Vec<Vec3> = (0..count)
        .map(|i| {
            let y = 1.0 - (i as f32 + 0.5) / count as f32;
            let ring = (1.0 - y * y).sqrt();
            let phi = golden * i as f32;
            Vec3::new(ring * phi.cos(), y, ring * phi.sin())
        })
        .collect();
    let h = std::f32::consts::FRAC_1_SQRT_2;
    dirs.extend([Vec3::X, Vec3::Y, Vec3::Z, Vec3::new(h, 0.0, h), Vec3::new(h, 0.0, -h)]);
    dirs
}

/// A greedy choice: the planes (normal, offset from the centre), and the area they cover.
struct Greedy {
    planes: Vec<(Vec3, f32)>,
    covered_area: f32,
}

fn greedy(
    model: &Model,
    dirs: &[Vec3],
    ranges: &[Vec<[f32; 2]>],
    count: usize,
    epsilon: f32,
    params: &FitParams,
) -> Greedy {
    let mut alive: Vec<bool> = model.area.iter().map(|&a| a > 0.0).collect();
    let mut planes: Vec<(Vec3, f32)> = Vec::new();
    let mut covered_area = 0.0;
    let max_sin_tilt = params.max_tilt_deg.to_radians().sin();
    let min_azimuth_cos = params.min_azimuth_deg.to_radians().cos();
    let azimuth = |n: Vec3| Vec3::new(n.x, 0.0, n.z).normalize_or_zero();
    let spacing = (2.0 * std::f32::consts::PI / params.directions as f32).sqrt();
    for k in 0..count {
        if !alive.iter().any(|&a| a) {
            break;
        }
        let alive_ref = &alive;
        let chosen = &planes;
        let allowed = |n: Vec3, upright: bool| {
            !upright
                || (n.y.abs() <= max_sin_tilt
                    && chosen.iter().all(|(m, _)| azimuth(*m).dot(azimuth(n)).abs() < min_azimuth_cos))
        };
        let densest = |upright: bool| {
            dirs.par_iter()
                .enumerate()
                .filter(|(_, n)| allowed(**n, upright))
                .map(|(j, &n)| {
                    let live =
                        ranges[j].iter().enumerate().filter(|(t, _)| alive_ref[*t]).map(|(t, r)| (t, *r));
                    let (score, d) = model.best_offset(n, live, epsilon);
                    (score, n, d)
                })
                .reduce(|| (0.0, Vec3::Y, 0.0), |a, b| if b.0 > a.0 { b } else { a })
        };
        // The upright rule gives way when no direction it allows finds anything left to cover.
        let mut upright = k < params.upright_planes;
        let mut best = densest(upright);
        if best.0 <= 0.0 && upright {
            upright = false;
            best = densest(false);
        }
        let (mut score, mut n, mut d) = best;
        if score <= 0.0 {
            break;
        }
        let mut step = spacing / 2.0;
        for _ in 0..3 {
            let (t1, t2) = n.any_orthonormal_pair();
            let centre = n;
            for (a, b) in (-2..=2).flat_map(|a| (-2..=2).map(move |b| (a as f32, b as f32))) {
                let candidate = (centre + step * (a * t1 + b * t2)).normalize();
                if (a, b) == (0.0, 0.0) || !allowed(candidate, upright) {
                    continue;
                }
                let live =
                    (0..model.area.len()).filter(|&t| alive[t]).map(|t| (t, model.range(candidate, t)));
                let (s, offset) = model.best_offset(candidate, live, epsilon);
                if s > score {
                    (score, n, d) = (s, candidate, offset);
                }
            }
            step /= 2.0;
        }
        for (t, live) in alive.iter_mut().enumerate() {
            let [lo, hi] = model.range(n, t);
            if *live && hi - d <= epsilon && d - lo <= epsilon {
                *live = false;
                covered_area += model.area[t];
            }
        }
        planes.push((n, d));
    }
    Greedy { planes, covered_area }
}

/// Fits `count` planes to `triangles` (model space).
pub fn fit_planes(triangles: &[[Vec3; 3]], count: usize, params: &FitParams) -> Result<Fit, FitError> {
    if count == 0 {
        return Err(FitError::NoPlanes);
    }
    let area: Vec<f32> = triangles.iter().map(|[a, b, c]| 0.5 * (*b - *a).cross(*c - *a).length()).collect();
    let total_area: f32 = area.iter().sum();
    if total_area <= 0.0 {
        return Err(FitError::NoArea);
    }
    let (lo, hi) = triangles
        .iter()
        .flatten()
        .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let centre = 0.5 * (lo + hi);
    let radius = triangles.iter().flatten().map(|p| p.distance(centre)).fold(0.0, f32::max).max(1e-6);
    let normal = triangles.iter().map(|[a, b, c]| (*b - *a).cross(*c - *a).normalize_or_zero()).collect();
    let model = Model { triangles, centre, radius, area, normal };
    let dirs = directions(params.directions);
    let ranges: Vec<Vec<[f32; 2]>> =
        dirs.par_iter().map(|&n| (0..triangles.len()).map(|t| model.range(n, t)).collect()).collect();
    let covers = |epsilon: f32| {
        let g = greedy(&model, &dirs, &ranges, count, epsilon, params);
        let ok = g.covered_area >= params.coverage * total_area;
        (ok, g)
    };
    let (mut lo_eps, mut hi_eps) = (radius / 256.0, radius);
    let (ok, mut chosen) = covers(lo_eps);
    let mut epsilon = lo_eps;
    if !ok {
        chosen = covers(hi_eps).1;
        epsilon = hi_eps;
        for _ in 0..params.bisection_steps {
            let mid = (lo_eps * hi_eps).sqrt();
            let (ok, g) = covers(mid);
            if ok {
                (hi_eps, chosen, epsilon) = (mid, g, mid);
            } else {
                lo_eps = mid;
            }
        }
    }
    Ok(assemble(&model, chosen, epsilon, count, total_area))
}

/// The drawn triangles of each chosen plane, leftovers given out, split up to `count` planes.
fn assemble(model: &Model, chosen: Greedy, epsilon: f32, count: usize, total_area: f32) -> Fit {
    let distance = |(n, d): (Vec3, f32), t: usize| {
        let [lo, hi] = model.range(n, t);
        (hi - d).max(d - lo)
    };
    let mut planes: Vec<(Vec3, f32, Vec<u32>)> = chosen
        .planes
        .iter()
        .map(|&(n, d)| {
            let drawn =
                (0..model.triangles.len()).filter(|&t| distance((n, d), t) <= epsilon).map(|t| t as u32);
            (n, d, drawn.collect())
        })
        .collect();
    let mut max_leftover = 0.0f32;
    for t in 0..model.triangles.len() {
        if planes.iter().any(|p| p.2.binary_search(&(t as u32)).is_ok()) {
            continue;
        }
        let (k, far) = planes
            .iter()
            .enumerate()
            .map(|(k, p)| (k, distance((p.0, p.1), t)))
            .fold((0, f32::INFINITY), |a, b| if b.1 < a.1 { b } else { a });
        max_leftover = max_leftover.max(far);
        let list = &mut planes[k].2;
        let at = list.partition_point(|&x| x < t as u32);
        list.insert(at, t as u32);
    }
    while planes.len() < count {
        let Some(k) =
            (0..planes.len()).filter(|&k| planes[k].2.len() >= 2).max_by_key(|&k| planes[k].2.len())
        else {
            break;
        };
        let (n, d, list) = planes[k].clone();
        let (u, v) = n.any_orthonormal_pair();
        let centroid = |t: u32| model.triangles[t as usize].iter().copied().sum::<Vec3>() / 3.0;
        let spread = |axis: Vec3| {
            let values = list.iter().map(|&t| axis.dot(centroid(t)));
            values.clone().fold(f32::NEG_INFINITY, f32::max) - values.fold(f32::INFINITY, f32::min)
        };
        let axis = if spread(u) >= spread(v) { u } else { v };
        let mut sorted = list.clone();
        sorted.sort_by(|&a, &b| axis.dot(centroid(a)).total_cmp(&axis.dot(centroid(b))));
        let (left, right) = sorted.split_at(sorted.len() / 2);
        let (mut left, mut right) = (left.to_vec(), right.to_vec());
        left.sort_unstable();
        right.sort_unstable();
        planes[k].2 = left;
        planes.push((n, d, right));
    }
    let covered_fraction = chosen.covered_area / total_area;
    Fit {
        epsilon_m: epsilon,
        planes: planes
            .into_iter()
            .map(|(n, d, triangles)| FittedPlane { normal: n, offset_m: d + n.dot(model.centre), triangles })
            .collect(),
        covered_fraction,
        max_leftover_distance_m: max_leftover,
    }
}

#[cfg(test)]
mod tests;
