//! `terramp info`: a dataset described (frame, extent, layers).

use std::path::Path;

use anyhow::Result;
use terramp::dataset::Dataset;

/// Prints the dataset's frame, extent and layers.
pub fn run(dataset_dir: &Path) -> Result<()> {
    let dataset = Dataset::open(dataset_dir)?;
    let m = &dataset.manifest;
    let [w, h] = m.extent_m();
    let corner = m.corner_m();
    println!("{} ({})", m.name, dataset_dir.display());
    println!("  CRS: {}", m.crs.note);
    println!(
        "  extent: {:.1} .. {:.1} E, {:.1} .. {:.1} N ({:.1} × {:.1} km)",
        corner[0],
        corner[0] + w,
        corner[1],
        corner[1] + h,
        w / 1000.0,
        h / 1000.0
    );
    match &m.earth {
        Some(earth) => {
            let (lat, lon) = earth.geodetic(corner[0] + 0.5 * w, corner[1] + 0.5 * h);
            let (lat, lon) = (lat.to_degrees(), lon.to_degrees());
            let geoid = earth.geoid.as_ref().map_or_else(
                || "heights above the ellipsoid".to_owned(),
                |g| {
                    format!(
                        "heights above {}, {:.2} m above the ellipsoid there",
                        g.name,
                        g.undulation_at(lat.to_radians(), lon.to_radians())
                    )
                },
            );
            println!(
                "  on the Earth: centre {:.5}° {}, {:.5}° {}; {geoid}; {}",
                lat.abs(),
                if lat >= 0.0 { "N" } else { "S" },
                lon.abs(),
                if lon >= 0.0 { "E" } else { "W" },
                earth.datum_note
            );
        }
        None => {
            println!("  on the Earth: not placed (built before placement, or a CRS the builder cannot map)")
        }
    }
    let p = &m.height.pyramid;
    println!(
        "  heights: {}×{} samples at {} m, {} levels, {:.1} .. {:.1} m, {} filled",
        p.size[0],
        p.size[1],
        m.height.spacing_m,
        p.levels,
        m.height.min_m,
        m.height.max_m,
        m.height.filled_samples
    );
    if let Some(i) = &m.imagery {
        println!(
            "  imagery: {}×{} texels at {} m, {} levels, {}",
            i.pyramid.size[0], i.pyramid.size[1], i.texel_m, i.pyramid.levels, i.format
        );
    }
    if let Some(l) = &m.landcover {
        let source = l.layer.pyramid.size_at(terramp::dataset::lcc::LCC_SOURCE_LEVEL);
        println!(
            "  land cover ({}, {} classes): {}×{} texels at {} m, LCC quadtree of {} levels in {}-bit words, {} codes",
            l.scheme,
            l.classes.len(),
            source[0],
            source[1],
            2.0 * l.layer.texel_m,
            l.layer.pyramid.levels,
            l.coding.word_bits,
            l.coding.palette.len()
        );
    }
    Ok(())
}
