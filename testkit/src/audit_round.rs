//! The ray oracle on the Earth: what a pixel's ray must show when the renderer places the grid
//! on the ellipsoid (`terramp::earth::placing`). The ray is straight in the camera's frame; its
//! path over the grid (x, y and the height above the datum) is found at knots by the exact
//! placing's inverse (`ExactPlacing::grid_m`), 250 m apart where the finest LOD is drawn and a
//! hundredth of the distance beyond (the path bends by the chord's sagitta between knots, L² / 8R:
//! 1.2 mm and, at 100 km, 2 cm), and taken as straight between them. The rules are the flat
//! oracle's (`super::expect`): the ray must enter over the dataset from above the ground to be
//! judged; dipping below the finest mesh by more than the slack where the dataset covers is
//! ground; staying above it by more than the slack everywhere is sky; anything else is not judged.

use glam::DVec3;
use terramp::earth::horizon::SMALLEST_RADIUS_M;
use terramp::earth::placing::ExactPlacing;

use super::{Dem, Expect, Tolerance, slack_m};

/// What the ray from the camera along `dir` (camera-relative) must show over `dem`, from `t_near`
/// on, with the finest LOD out to `fine_within_m`.
pub fn expect(
    dem: &Dem,
    exact: &ExactPlacing,
    dir: DVec3,
    t_near: f64,
    tol: Tolerance,
    fine_within_m: f64,
) -> Expect {
    let slack = |t: f64| slack_m(&tol, fine_within_m, t);
    let widest = tol.height_m.max(tol.coarse_height_m);
    let band = [dem.min_m - widest - 1.0, dem.max_m + widest + 1.0];
    let span = dem.span_m();
    let t_far = [[0.0, 0.0], [span[0], 0.0], [0.0, span[1]], [span[0], span[1]]]
        .iter()
        .map(|c| exact.position_rel_m(DVec3::new(c[0], c[1], band[1])).length())
        .fold(0.0, f64::max)
        + 1_000.0;
    let knot_m = |t: f64| if t < fine_within_m { 250.0 } else { (0.01 * t).max(250.0) };
    let horizontal = dir.truncate().length();
    let finest = tol.height_m.min(widest);
    let (mut entered, mut near_miss) = (false, false);
    let (mut t0, mut g0) = (t_near, exact.grid_m(dir * t_near));
    while t0 < t_far {
        let t1 = (t0 + knot_m(t0)).min(t_far);
        let g1 = exact.grid_m(dir * t1);
        // Between knots, steps a quarter of a cell across and half the slack up or down (the
        // ray's height turns by t / R per metre on top of its own slope).
        let climb = dir.z.abs() + t1 / SMALLEST_RADIUS_M;
        let step = (0.25 * dem.spacing_m / horizontal.max(1e-300)).min(0.5 * finest / climb.max(1e-300));
        let steps = ((t1 - t0) / step).ceil().clamp(1.0, 1e6) as u64;
        for k in 1..=steps {
            let f = k as f64 / steps as f64;
            let (t, g) = (t0 + (t1 - t0) * f, g0 + (g1 - g0) * f);
            let inside = (0.0..=span[0]).contains(&g.x) && (0.0..=span[1]).contains(&g.y);
            if !inside {
                if entered {
                    return if near_miss { Expect::Unknown } else { Expect::Sky };
                }
                // A ray may cross a corner between two samples: passing within a step of the
                // dataset (where the flat oracle finds its entry exactly), it is not judged sky.
                let reach = step * horizontal;
                let near =
                    (-reach..=span[0] + reach).contains(&g.x) && (-reach..=span[1] + reach).contains(&g.y);
                near_miss |= near && g.z <= band[1];
                continue;
            }
            let clearance = || g.z - dem.mesh_height_m(g.x, g.y);
            if !entered {
                entered = true;
                if g.z < band[0] || (g.z <= band[1] && clearance() <= slack(t)) {
                    return Expect::Unknown;
                }
            }
            if g.z > band[1] {
                continue;
            }
            let c = clearance();
            if c < -slack(t) {
                return if dem.covers(g.x, g.y, tol.margin_m) { Expect::Ground } else { Expect::Unknown };
            }
            near_miss |= c <= slack(t);
        }
        // A straight ray's height above the Earth only falls and then rises: once above the band
        // and rising, it never comes back.
        if g1.z > band[1] && g1.z > g0.z {
            break;
        }
        (t0, g0) = (t1, g1);
    }
    if near_miss { Expect::Unknown } else { Expect::Sky }
}
