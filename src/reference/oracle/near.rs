//! How it works: the seeds standing within a radius of a grid point, judged as the oracle judges
//! a view's (the same cells, patterns, classes, rules and reach from the camera), under any
//! culls: with `Culls::GROWN`, every plant the view grows there, seen or not (what a host
//! collides with); with `Culls::SELECTION`, those pass 3 keeps. Only the ring-0 cells the disc
//! overlaps are judged, over the ground from them to the eye.

use glam::DVec2;
use rayon::prelude::*;

use super::frame::ViewFrame;
use super::{Culls, OracleError, OracleInputs, OracleSeed, cell_span, span_region};

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
    let [(x0, x1), (y0, y1)] = cell_span(extent_m, cell_m, centre_m, radius_m);
    if x0 > x1 || y0 > y1 || radius_m < 0.0 {
        return Ok(Vec::new());
    }
    let cells: Vec<[i64; 2]> = (y0..=y1).flat_map(|gy| (x0..=x1).map(move |gx| [gx, gy])).collect();
    // The region holds the eye too: the occlusion test walks the ground from the eye to a seed.
    let eye = frame.eye.truncate();
    let (region_min, region_max) = span_region(extent_m, cell_m, [(x0, x1), (y0, y1)]);
    let (region_min, region_max) = (region_min.min(eye), region_max.max(eye));
    let view = frame.view(inputs, culls, region_min.to_array(), region_max.to_array())?;
    let judged: Vec<Vec<OracleSeed>> =
        cells.par_iter().map(|&address| Ok(view.cell(address)?.0)).collect::<Result<_, OracleError>>()?;
    let near = |s: &OracleSeed| DVec2::from(s.position_grid_m).distance(centre_m) <= radius_m;
    let mut seeds: Vec<OracleSeed> = judged.into_iter().flatten().filter(near).collect();
    seeds.sort_by_key(|s| (s.address, s.rank));
    Ok(seeds)
}
