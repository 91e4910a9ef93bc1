//! How it works: the seeds standing within a radius of a grid point, judged as the oracle judges
//! a view's (the same cells, patterns, classes, rules and reach from the camera), under any
//! culls: with `Culls::GROWN`, every plant the view grows there, seen or not (what a host
//! collides with); with `Culls::SELECTION`, those pass 3 keeps. Only the ring-0 cells the disc
//! overlaps are judged, over the ground from them to the eye.

use glam::DVec2;
use rayon::prelude::*;

use super::frame::ViewFrame;
use super::{Culls, OracleError, OracleInputs, OracleSeed};

/// The seeds of the view of `inputs` standing within `radius_m` of grid point `centre_m` that
/// survive `culls`, sorted by (address, rank).
pub fn seeds_within(
    inputs: &OracleInputs,
    culls: Culls,
    centre_m: DVec2,
    radius_m: f64,
) -> Result<Vec<OracleSeed>, OracleError> {
    let frame = ViewFrame::new(inputs)?;
    let (cell_m, extent_m) = (inputs.settings.tlm.cell_m, frame.extent_m);
    let range = |a: usize| {
        let last = (extent_m[a] / cell_m).floor();
        let lo = ((centre_m[a] - radius_m) / cell_m).floor().max(0.0);
        let hi = ((centre_m[a] + radius_m) / cell_m).floor().min(last);
        (lo as i64, hi as i64)
    };
    let ((x0, x1), (y0, y1)) = (range(0), range(1));
    if x0 > x1 || y0 > y1 || radius_m < 0.0 {
        return Ok(Vec::new());
    }
    let cells: Vec<[i64; 2]> = (y0..=y1).flat_map(|gy| (x0..=x1).map(move |gx| [gx, gy])).collect();
    // The region holds the eye too: the occlusion test walks the ground from the eye to a seed.
    let eye = frame.eye.truncate();
    let region_min = DVec2::new(x0 as f64 * cell_m, y0 as f64 * cell_m).min(eye);
    let region_max =
        DVec2::new(((x1 + 1) as f64 * cell_m).min(extent_m[0]), ((y1 + 1) as f64 * cell_m).min(extent_m[1]))
            .max(eye);
    let view = frame.view(inputs, culls, region_min.to_array(), region_max.to_array())?;
    let judged: Vec<Vec<OracleSeed>> =
        cells.par_iter().map(|&address| Ok(view.cell(address)?.0)).collect::<Result<_, OracleError>>()?;
    let near = |s: &OracleSeed| DVec2::from(s.position_grid_m).distance(centre_m) <= radius_m;
    let mut seeds: Vec<OracleSeed> = judged.into_iter().flatten().filter(near).collect();
    seeds.sort_by_key(|s| (s.address, s.rank));
    Ok(seeds)
}
