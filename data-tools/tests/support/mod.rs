//! Helpers for the `terramp-data` tests that need GDAL or the binary: running `build`, building the
//! shared samples, writing and reading rasters with GDAL, built layers level by level. Everything
//! else (the shared data, temporary folders, cameras, the audit, image checks) is the workspace's
//! test kit, `terramp_testkit`.

#![allow(dead_code, reason = "each test binary uses a part of these helpers")]

use std::path::{Path, PathBuf};
use std::process::Output;

use gdal::raster::{Buffer, GdalType};
use gdal::spatial_ref::SpatialRef;
use gdal::{DriverManager, GeoTransform};
use terramp::dataset::{Dataset, Pyramid, Sampling, TileId};
use terramp::earth::placing::EarthPlacing;
use terramp_testkit::shared_data;

pub mod texcells;

/// Writes a one-band GeoTIFF of `size` values (row by row from the north) in EPSG `epsg`.
pub fn write_geotiff<T: GdalType + Copy>(
    path: &Path,
    size: [usize; 2],
    values: Vec<T>,
    geo_transform: GeoTransform,
    epsg: u32,
    nodata: Option<f64>,
) -> PathBuf {
    let driver = DriverManager::get_driver_by_name("GTiff").unwrap();
    let mut dataset = driver.create_with_band_type::<T, _>(path, size[0], size[1], 1).unwrap();
    dataset.set_geo_transform(&geo_transform).unwrap();
    dataset.set_spatial_ref(&SpatialRef::from_epsg(epsg).unwrap()).unwrap();
    let mut band = dataset.rasterband(1).unwrap();
    band.set_no_data_value(nodata).unwrap();
    band.write((0, 0), (size[0], size[1]), &mut Buffer::new((size[0], size[1]), values)).unwrap();
    path.to_owned()
}

/// Runs `terramp-data build ARGS`.
pub fn run_build(args: &[&str]) -> Output {
    terramp_testkit::command(env!("CARGO_BIN_EXE_terramp-data")).arg("build").args(args).output().unwrap()
}

/// Runs `terramp-data build ARGS --out OUT`, asserts success, returns the opened dataset and stdout.
pub fn build(out: &Path, args: &[&str]) -> (Dataset, String) {
    let output = run_build(&[args, &["--out", out.to_str().unwrap()]].concat());
    let (stdout, stderr) = (String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
    assert!(output.status.success(), "build failed:\n{stdout}\n{stderr}");
    (Dataset::open(out).unwrap(), stdout.into_owned())
}

/// Builds, in `dir`, a geographic sea-level raster (EPSG:4326, heights 0 above EGM96) of
/// `samples` × `samples` every `step_deg` degrees, centred on 0° N 0° E: the builder moves it to
/// its local azimuthal equidistant frame, centred there.
pub fn sea_level(dir: &Path, step_deg: f64, samples: usize) -> Dataset {
    let half = 0.5 * samples as f64 * step_deg;
    let transform = [-half, step_deg, 0.0, half, 0.0, -step_deg];
    let heights = vec![0.0f32; samples * samples];
    let dem = write_geotiff(&dir.join("sea.tif"), [samples, samples], heights, transform, 4326, None);
    build(&dir.join("sea"), &["--dem", dem.to_str().unwrap()]).0
}

/// Builds `nc/`'s co-registered trio (DEM, Landsat true colour, land use) into `out`.
pub fn build_nc(out: &Path) -> Dataset {
    build_nc_with(out, &[])
}

/// Builds `nc/` as `build_nc` does, with the imagery's NDVI (Landsat band 4 against band 3) in
/// its alpha (`--nir-band 4`).
pub fn build_nc_ndvi(out: &Path) -> Dataset {
    build_nc_with(out, &["--nir-band", "4"])
}

/// `nc/`'s DEM, Landsat bands 3, 2, 1 and land use, built into `out` with `extra` arguments.
fn build_nc_with(out: &Path, extra: &[&str]) -> Dataset {
    let nc = shared_data().expect("../shared/data").join("nc");
    let arg = |f: &str| nc.join(f).to_str().unwrap().to_owned();
    let args = [
        ["--dem", &arg("elev_ned_30m.tif")],
        ["--imagery", &arg("landsat_multiband.tif")],
        ["--bands", "3,2,1"],
        ["--landcover", &arg("landuse_r.tif")],
        ["--classes", "nc"],
    ];
    let mut all = args.concat();
    all.extend_from_slice(extra);
    build(out, &all).0
}

/// Builds `zion/`'s reprojected DEM and NLCD land cover (no imagery) into `out`.
pub fn build_zion(out: &Path) -> Dataset {
    let zion = shared_data().expect("../shared/data").join("zion");
    let arg = |f: &str| zion.join(f).to_str().unwrap().to_owned();
    let args = [
        ["--dem", &arg("dem_utm12n_30m.tif")],
        ["--landcover", &arg("nlcd_utm12n_30m.tif")],
        ["--classes", "nlcd"],
    ];
    build(out, &args.concat()).0
}

/// Band 1 of a raster, row by row from the north, with its size.
pub fn gdal_band(path: &Path) -> (Vec<f64>, [usize; 2]) {
    let dataset = gdal::Dataset::open(path).unwrap();
    let band = dataset.rasterband(1).unwrap();
    let (width, height) = band.size();
    (band.read_band_as::<f64>().unwrap().into_shape_and_vec().1, [width, height])
}

/// The source value under grid texel (`x`, `y`) of a grid that is the raster's own grid.
pub fn north_first(values: &[f64], size: [usize; 2], x: u32, y: u32) -> f64 {
    values[(size[1] - 1 - y as usize) * size[0] + x as usize]
}

/// One level of a layer as a whole image (south row first), each texel taken from the tile that
/// owns it, with every stored texel of every tile checked against it: shared edges and borders
/// must repeat their neighbour's values exactly (or the edge, replicated, beyond the layer).
pub fn level_image<T: Copy + PartialEq + std::fmt::Debug>(
    pyramid: &Pyramid,
    level: u32,
    tile: impl Fn(TileId) -> Vec<T>,
) -> Vec<T> {
    let size = pyramid.size_at(level);
    let [nx, ny] = pyramid.tiles_at(level);
    let extent = pyramid.tile_extent() as i64;
    let border = i64::from(pyramid.border);
    let step = i64::from(pyramid.tile);
    let tiles: Vec<Vec<T>> = (0..ny)
        .flat_map(|y| (0..nx).map(move |x| (x, y)))
        .map(|(x, y)| tile(TileId::new(level, x, y)))
        .collect();
    let owner = |v: u32, n: u32| (i64::from(v) / step).min(i64::from(n) - 1);
    let image: Vec<T> = (0..size[1])
        .flat_map(|y| (0..size[0]).map(move |x| (x, y)))
        .map(|(x, y)| {
            let (tx, ty) = (owner(x, nx), owner(y, ny));
            let (lx, ly) = (i64::from(x) - tx * step + border, i64::from(y) - ty * step + border);
            tiles[(ty * i64::from(nx) + tx) as usize][(ly * extent + lx) as usize]
        })
        .collect();
    let clamp = |v: i64, n: u32| v.clamp(0, i64::from(n) - 1) as usize;
    for (index, texels) in tiles.iter().enumerate() {
        let id = TileId::new(level, index as u32 % nx, index as u32 / nx);
        let [x0, y0] = pyramid.tile_origin(id);
        for j in 0..extent {
            for i in 0..extent {
                let expected = image[clamp(y0 + j, size[1]) * size[0] as usize + clamp(x0 + i, size[0])];
                assert_eq!(texels[(j * extent + i) as usize], expected, "{id:?} texel ({i}, {j})");
            }
        }
    }
    image
}

/// Level `level` of the heights, checked across tile borders.
pub fn height_image(dataset: &Dataset, level: u32) -> Vec<f32> {
    level_image(&dataset.height.pyramid, level, |id| dataset.height_tile(id).unwrap())
}

/// Level 0 of the validity mask pack, checked across tile borders.
pub fn mask_image(dataset: &Dataset) -> Vec<u8> {
    let mask = dataset.valid_mask.as_ref().expect("a validity mask pack");
    assert_eq!(mask.pyramid.sampling, Sampling::Vertex);
    level_image(&mask.pyramid, 0, |id| mask.tile_bytes(id).unwrap().to_vec())
}

/// The number after `label` in `text` ("filled 12 samples" → `number_before(text, " samples")`).
pub fn number_before(text: &str, label: &str) -> u64 {
    let end = text.find(label).unwrap_or_else(|| panic!("no {label:?} in {text}"));
    let start = text[..end].rfind(|c: char| !c.is_ascii_digit()).map_or(0, |i| i + 1);
    text[start..end].parse().unwrap()
}

/// This crate's `tests/` folder, where the reference images live.
pub fn tests_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests")
}

/// The ground under one pixel: its land-cover code, the level-1 land-cover texel it lies in, and
/// its distance from the camera.
#[derive(Debug, Clone, Copy)]
pub struct PixelGround {
    pub code: u8,
    pub texel: [u32; 2],
    pub distance_m: f64,
}

/// The land-cover code of level-1 texel `q` (`None` off the map or where the source had none).
pub fn code_at(dataset: &Dataset, q: [u32; 2]) -> Option<u8> {
    let meta = dataset.manifest.landcover.as_ref()?;
    let index = dataset.landcover_index(1, q).ok()?;
    meta.coding.code_of(index)
}

/// The ground under each pixel of a `size` frame seen from `camera`, read back from its
/// reversed-Z `depth` (`None`: sky, or off the map), drawn on the Earth where the manifest says
/// where (`curved`: `render.curved_earth`) or flat.
pub fn ground_under_pixels(
    dataset: &Dataset,
    camera: &terramp::camera::Camera,
    size: [u32; 2],
    depth: &[f32],
    curved: bool,
) -> Vec<Option<PixelGround>> {
    let [w, h] = size;
    let clip_from_world = camera.clip_from_view(w, h).unwrap() * camera.view_from_world();
    let world_from_clip = clip_from_world.inverse();
    let meta = dataset.manifest.landcover.clone().unwrap();
    let texel_m = 2.0 * meta.layer.texel_m;
    let origin = dataset.manifest.origin_m;
    let half = 0.5 * dataset.manifest.height.spacing_m;
    let eye_grid_m = camera.position_m - glam::DVec3::new(origin[0], origin[1], 0.0);
    let exact = EarthPlacing::new(dataset.manifest.earth.as_ref(), origin, curved).exact(eye_grid_m);
    let mut codes = std::collections::HashMap::new();
    (0..w * h)
        .map(|i| {
            let d = f64::from(depth[i as usize]);
            if d <= 0.0 {
                return None;
            }
            let ndc = [
                (f64::from(i % w) + 0.5) / f64::from(w) * 2.0 - 1.0,
                1.0 - (f64::from(i / w) + 0.5) / f64::from(h) * 2.0,
            ];
            let p = world_from_clip * glam::DVec4::new(ndc[0], ndc[1], d, 1.0);
            let rel = p.truncate() / p.w;
            let grid = exact.grid_m(rel);
            // Cell layers tile the extent from half a height spacing south-west of the grid.
            let q = [((grid[0] + half) / texel_m).floor(), ((grid[1] + half) / texel_m).floor()];
            if q[0] < 0.0 || q[1] < 0.0 {
                return None;
            }
            let texel = [q[0] as u32, q[1] as u32];
            let code = *codes.entry(texel).or_insert_with(|| code_at(dataset, texel));
            code.map(|code| PixelGround { code, texel, distance_m: rel.length() })
        })
        .collect()
}

/// nc's forest and water codes.
pub const FOREST: u8 = 5;
pub const WATER: u8 = 6;

/// A pose over forest with water ahead: grid (x, y) of a level-1 land-cover texel whose
/// neighbourhood is mostly forest, the closest such to a lake, and the heading to that lake.
pub fn forest_near_water(dataset: &Dataset) -> ([f64; 2], f64) {
    let meta = dataset.manifest.landcover.clone().unwrap();
    let texel_m = 2.0 * meta.layer.texel_m;
    let [w, h] = dataset.manifest.extent_m();
    let n = [(w / texel_m) as i64, (h / texel_m) as i64];
    let code = |q: [i64; 2]| {
        if q[0] < 0 || q[1] < 0 || q[0] >= n[0] || q[1] >= n[1] {
            return meta.nodata_code;
        }
        let index = dataset.landcover_index(1, [q[0] as u32, q[1] as u32]).unwrap();
        meta.coding.code_of(index).unwrap_or(meta.nodata_code)
    };
    // Codes on a coarse grid (each lookup reads a tile): enough to find a forest and a lake.
    let step = 8;
    let g = [n[0] / step, n[1] / step];
    let grid: Vec<u8> = (0..g[1])
        .flat_map(|y| (0..g[0]).map(move |x| [x, y]))
        .map(|[x, y]| code([x * step, y * step]))
        .collect();
    let at = |x: i64, y: i64| grid[(y * g[0] + x) as usize];
    let water: Vec<[i64; 2]> =
        (0..g[1]).flat_map(|y| (0..g[0]).map(move |x| [x, y])).filter(|&[x, y]| at(x, y) == WATER).collect();
    assert!(!water.is_empty(), "no water in nc");
    let mut best: Option<(i64, [i64; 2], [i64; 2])> = None;
    for y in 2..g[1] - 2 {
        for x in 2..g[0] - 2 {
            let forest = (-2..=2)
                .flat_map(|j| (-2..=2).map(move |i| (x + i, y + j)))
                .filter(|&(i, j)| at(i, j) == FOREST)
                .count();
            if forest < 20 {
                continue;
            }
            let nearest = water.iter().min_by_key(|w| (w[0] - x).pow(2) + (w[1] - y).pow(2)).unwrap();
            let d = (nearest[0] - x).pow(2) + (nearest[1] - y).pow(2);
            // Water a little way off: a view across the forest to the lake.
            if d >= 4 && best.is_none_or(|b| d < b.0) {
                best = Some((d, [x * step, y * step], [nearest[0] * step, nearest[1] * step]));
            }
        }
    }
    let (_, at, lake) = best.expect("forest near water in nc");
    let grid = at.map(|v| (v as f64 + 0.5) * texel_m);
    let yaw = ((lake[0] - at[0]) as f64).atan2((lake[1] - at[1]) as f64).to_degrees();
    (grid, yaw)
}
