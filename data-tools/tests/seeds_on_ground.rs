//! Seeds stand on the ground that is drawn. On `zion/`, `rainier/` and `nc/`, from views spread
//! over each dataset, every seed pass 3 keeps is measured against the finest terrain mesh under it,
//! derived here from what the GPU draws rather than from the library's surface: the mesh's own
//! index buffer (`grid_indices`, the two triangles each cell of a node is drawn as, nodes starting
//! every `terrain.node_cells` samples) over the level-0 height tiles, the plane through a
//! triangle's three samples evaluated in f64. Neither a seed's ground (`ground_m`, before sinking)
//! nor its sunk anchor may stand more than 1 cm above it, and its ground may not sit more than
//! 1 cm below it either. As a control, the bilinear patch through the same four samples is
//! measured at the same seeds: on the rugged datasets it stands well above the mesh, so the audit
//! can see what it is there to catch.
//!
//! `rainier/` has no land cover: it is given uniform shrubland (bushes, young pines, boulders) on
//! the DEM's own grid, so seeds grow on its steep relief.
//!
//! The figures: `cargo test -p terramp-data-tools --test seeds_on_ground -- --nocapture`.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

mod support;

use std::collections::HashMap;
use std::path::Path;

use glam::DVec3;
use terramp::config::Settings;
use terramp::dataset::{Dataset, TileId};
use terramp::frame::Renderer;
use terramp::gpu::layout::SpeciesLod;
use terramp::passes::terrain::frame::grid_indices;
use terramp_testkit::camera::posed;
use terramp_testkit::{TempDir, shared_data};

use support::{build, build_nc, build_zion, write_geotiff};

/// The most a seed may stand above the drawn ground (or its ground sit below it), metres.
const LIMIT_M: f64 = 0.01;

/// The finest mesh as the GPU draws it, on the CPU in f64.
struct FinestMesh<'a> {
    dataset: &'a Dataset,
    spacing_m: f64,
    size: [u32; 2],
    /// Cells along a node's side: nodes start at multiples of it.
    cells: u32,
    /// Per cell of a node (row-major), the vertices of its two triangles, node-local samples.
    triangles: Vec<[[[u32; 2]; 3]; 2]>,
    /// Level-0 tiles read so far.
    tiles: HashMap<[u32; 2], Vec<f32>>,
}

impl<'a> FinestMesh<'a> {
    fn new(dataset: &'a Dataset, cells: u32) -> Self {
        let (indices, _) = grid_indices(cells);
        // Vertex k of the (cells + 3)² grid is (k % row, k / row); its outer ring is the skirts.
        let row = cells + 3;
        let mut by_cell = vec![Vec::new(); (cells * cells) as usize];
        for t in indices.chunks_exact(3) {
            let v: Vec<[u32; 2]> = t.iter().map(|&k| [k % row, k / row]).collect();
            let inner = v.iter().all(|p| p.iter().all(|&c| (1..=cells + 1).contains(&c)));
            if !inner {
                continue;
            }
            let local = [v[0], v[1], v[2]].map(|p| [p[0] - 1, p[1] - 1]);
            let cell = [0, 1].map(|a| local.iter().map(|p| p[a]).min().unwrap());
            by_cell[(cell[1] * cells + cell[0]) as usize].push(local);
        }
        let triangles = by_cell
            .into_iter()
            .map(|t| <[_; 2]>::try_from(t).expect("a cell is not drawn as two triangles"))
            .collect();
        let h = &dataset.manifest.height;
        Self {
            dataset,
            spacing_m: h.spacing_m,
            size: dataset.height.pyramid.size,
            cells,
            triangles,
            tiles: HashMap::new(),
        }
    }

    /// Level-0 sample (`i`, `j`), metres, from the tile that owns it.
    fn sample(&mut self, i: u32, j: u32) -> f64 {
        let p = self.dataset.height.pyramid;
        let [nx, ny] = p.tiles_at(0);
        let t = [(i / p.tile).min(nx - 1), (j / p.tile).min(ny - 1)];
        let dataset = self.dataset;
        let tile =
            self.tiles.entry(t).or_insert_with(|| dataset.height_tile(TileId::new(0, t[0], t[1])).unwrap());
        let (x, y) = (i - t[0] * p.tile + p.border, j - t[1] * p.tile + p.border);
        f64::from(tile[(y * p.tile_extent() + x) as usize])
    }

    /// The cell (south-west sample) under grid (x, y) and the position in it, in samples.
    fn cell(&self, x_m: f64, y_m: f64) -> ([u32; 2], [f64; 2]) {
        let g = [x_m / self.spacing_m, y_m / self.spacing_m];
        let cell: [u32; 2] =
            std::array::from_fn(|a| (g[a].floor().max(0.0) as u32).min(self.size[a].saturating_sub(2)));
        (cell, g)
    }

    /// Height of the drawn finest mesh at grid (x, y): the plane of the triangle holding it.
    fn height_m(&mut self, x_m: f64, y_m: f64) -> f64 {
        let (cell, g) = self.cell(x_m, y_m);
        let node = cell.map(|c| c - c % self.cells);
        let local = cell.map(|c| c % self.cells);
        let mut best = (f64::NEG_INFINITY, 0.0);
        for tri in self.triangles[(local[1] * self.cells + local[0]) as usize] {
            let v = tri.map(|p| [node[0] + p[0], node[1] + p[1]]);
            let [a, b, c] = v.map(|p| [f64::from(p[0]), f64::from(p[1])]);
            let det = (b[1] - c[1]) * (a[0] - c[0]) + (c[0] - b[0]) * (a[1] - c[1]);
            let wa = ((b[1] - c[1]) * (g[0] - c[0]) + (c[0] - b[0]) * (g[1] - c[1])) / det;
            let wb = ((c[1] - a[1]) * (g[0] - c[0]) + (a[0] - c[0]) * (g[1] - c[1])) / det;
            let w = [wa, wb, 1.0 - wa - wb];
            let h = v.map(|p| self.sample(p[0], p[1]));
            let height = w[0] * h[0] + w[1] * h[1] + w[2] * h[2];
            // The triangle that holds the point: its least weight is the largest (0 on an edge).
            let least = w.iter().copied().fold(f64::INFINITY, f64::min);
            if least > best.0 {
                best = (least, height);
            }
        }
        best.1
    }

    /// The bilinear patch through the same cell's samples at (x, y): the control.
    fn bilinear_m(&mut self, x_m: f64, y_m: f64) -> f64 {
        let ([i, j], g) = self.cell(x_m, y_m);
        let (u, v) = (g[0] - f64::from(i), g[1] - f64::from(j));
        let (h00, h10) = (self.sample(i, j), self.sample(i + 1, j));
        let (h01, h11) = (self.sample(i, j + 1), self.sample(i + 1, j + 1));
        (h00 * (1.0 - u) + h10 * u) * (1.0 - v) + (h01 * (1.0 - u) + h11 * u) * v
    }
}

/// What the views of one dataset found, metres.
#[derive(Debug, Default)]
struct Standing {
    views: usize,
    seeds: usize,
    /// Seeds placed on a coarser height level than 0 (none once a view is resolved).
    coarse: usize,
    /// Largest height of a seed's ground (before sinking) above the mesh, and below it (signed).
    ground_above_m: f64,
    ground_below_m: f64,
    /// Seeds whose ground (before sinking) stands more than `LIMIT_M` above the mesh.
    floating: usize,
    /// Largest height of a seed's sunk anchor above the mesh (negative: every anchor is below it).
    anchor_above_m: f64,
    /// Largest height of the bilinear patch above the mesh at the same seeds.
    bilinear_above_m: f64,
}

/// Poses spread over the dataset: a 4 × 3 grid of places, each at its own height, heading and pitch.
fn spread_poses(dataset: &Dataset) -> Vec<[f64; 5]> {
    let [w, h] = dataset.manifest.extent_m();
    (0..12)
        .map(|k| {
            let (fx, fy) = (0.2 + 0.2 * f64::from(k % 4), 0.25 + 0.25 * f64::from(k / 4));
            let above_m = [3.0, 12.0, 40.0][k as usize % 3];
            let pitch_deg = [-6.0, -14.0, -25.0][k as usize % 3];
            [fx * w, fy * h, above_m, f64::from(k * 97 % 360), pitch_deg]
        })
        .collect()
}

/// Every view of the dataset built in `dir`, measured.
fn stand(what: &str, dir: &Path) -> Standing {
    let mut settings = Settings::default();
    settings.render.width = 320;
    settings.render.height = 180;
    let cells = settings.terrain.node_cells;
    let gpu = terramp_testkit::gpu();
    let mut r = Renderer::new(gpu, Dataset::open(dir).unwrap(), settings).unwrap();
    let poses = spread_poses(&r.dataset);
    // The mesh reads its own copy of the tiles.
    let dataset = Dataset::open(dir).unwrap();
    let mut mesh = FinestMesh::new(&dataset, cells);
    let sink = r.settings.seeds.sink_fraction;
    // Signed: a seed sunk everywhere shows as a negative height above.
    let lowest = f64::NEG_INFINITY;
    let mut s = Standing {
        views: poses.len(),
        ground_above_m: lowest,
        ground_below_m: lowest,
        anchor_above_m: lowest,
        bilinear_above_m: lowest,
        ..Default::default()
    };
    for pose in poses {
        let camera = posed(&r, pose);
        r.render_resolved(&camera).unwrap();
        let (records, _) = r.read_seeds().unwrap().unwrap();
        let placing = r.exact_placing(&camera);
        let mut view_above = f64::NEG_INFINITY;
        for record in &records {
            let p = placing.grid_m(DVec3::from(record.position_rel_m.map(f64::from)));
            let ground_mesh_m = mesh.height_m(p.x, p.y);
            let ground_m = f64::from(record.ground_m);
            assert!(ground_m.is_finite() && p.is_finite(), "{what}: {record:?}");
            // The anchor is where the record puts it: its ground sunk by its share of its height.
            let sunk_m = ground_m - sink * f64::from(record.height_m);
            assert!(
                (p.z - sunk_m).abs() <= 0.01f64.max(placing.camera_grid_m().z.abs() * 2e-7),
                "{what}: {record:?}: anchor {} m off",
                p.z - sunk_m
            );
            s.coarse += usize::from(SpeciesLod::unpack(record.species_lod).height_level != 0);
            s.ground_above_m = s.ground_above_m.max(ground_m - ground_mesh_m);
            s.ground_below_m = s.ground_below_m.max(ground_mesh_m - ground_m);
            s.anchor_above_m = s.anchor_above_m.max(p.z - ground_mesh_m);
            s.bilinear_above_m = s.bilinear_above_m.max(mesh.bilinear_m(p.x, p.y) - ground_mesh_m);
            view_above = view_above.max(ground_m - ground_mesh_m);
            s.floating += usize::from(ground_m - ground_mesh_m > LIMIT_M);
        }
        println!("{what} {pose:?}: {} seeds, ground up to {view_above:.4} m above the mesh", records.len());
        s.seeds += records.len();
    }
    println!("{what}: {s:?}");
    s
}

fn assert_on_the_ground(what: &str, s: &Standing, min_seeds: usize) {
    assert!(
        s.seeds >= min_seeds,
        "{what}: only {} seeds in {} views: the audit saw too little",
        s.seeds,
        s.views
    );
    assert_eq!(s.coarse, 0, "{what}: seeds placed on a coarse height level in resolved views");
    assert!(
        s.ground_above_m <= LIMIT_M,
        "{what}: a seed's ground is {} m above the drawn mesh",
        s.ground_above_m
    );
    assert!(
        s.anchor_above_m <= LIMIT_M,
        "{what}: a seed's anchor is {} m above the drawn mesh",
        s.anchor_above_m
    );
    assert!(
        s.ground_below_m <= LIMIT_M,
        "{what}: a seed's ground is {} m below the drawn mesh",
        s.ground_below_m
    );
}

/// `rainier/`'s DEM with uniform shrubland (nc class 4) on its own grid.
fn build_rainier(out: &Path, tmp: &Path) -> Dataset {
    let dem = shared_data().expect("../shared/data").join("rainier/mt_rainier_90m.tif");
    let source = gdal::Dataset::open(&dem).unwrap();
    let (width, height) = source.raster_size();
    let shrubs = write_geotiff(
        &tmp.join("shrubland.tif"),
        [width, height],
        vec![4u8; width * height],
        source.geo_transform().unwrap(),
        4326,
        Some(255.0),
    );
    let args = ["--dem", dem.to_str().unwrap(), "--landcover", shrubs.to_str().unwrap(), "--classes", "nc"];
    build(out, &args).0
}

#[test]
fn seeds_stand_on_the_drawn_ground_of_zion_rainier_and_nc() {
    if shared_data().is_none() {
        return;
    }
    let tmp = TempDir::new("seeds-on-ground");
    let dir = |name: &str| tmp.path().join(name);
    build_zion(&dir("zion"));
    build_rainier(&dir("rainier"), tmp.path());
    build_nc(&dir("nc"));
    let zion = stand("zion", &dir("zion"));
    let rainier = stand("rainier", &dir("rainier"));
    let nc = stand("nc", &dir("nc"));
    // The control: on rugged 30 m and 90 m cells the bilinear patch floats well above the mesh.
    for (what, s) in [("zion", &zion), ("rainier", &rainier)] {
        assert!(
            s.bilinear_above_m > 0.05,
            "{what}: the bilinear control is only {} m above the mesh",
            s.bilinear_above_m
        );
    }
    for (what, s) in [("zion", &zion), ("rainier", &rainier), ("nc", &nc)] {
        assert_on_the_ground(what, s, 2000);
    }
}
