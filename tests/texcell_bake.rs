//! Baking the forest samples of texcells (`terramp::bake::forest`) from the shared models, small:
//! every dense class of the nc and nlcd tables gets a sample of the pyramid's shape that reads back
//! as written; the sample is a forest seen from above (covered, trunks low, crowns high); its
//! coarsest slice holds all the others composited; and it wraps: across the square's edge the
//! top view changes no more than between neighbouring texels inside it.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use terramp::bake::forest::{ForestOptions, bake_forests};
use terramp::classes::ClassTable;
use terramp::texcell::{self, ForestSample, pyramid};
use terramp_testkit::data::target_tmp_dir;
use terramp_testkit::{gpu, shared_data};

const OPTIONS: ForestOptions = ForestOptions { cell_m: 32.0, texels: 64, slices: 8, supersample: 2, seed: 1 };

fn mean_alpha(bytes: &[u8]) -> f64 {
    bytes.chunks_exact(4).map(|t| f64::from(t[3]) / 255.0).sum::<f64>() / (bytes.len() / 4) as f64
}

#[test]
fn dense_classes_bake_forest_samples_that_wrap_and_read_back() {
    let Some(shared) = shared_data() else { return };
    let out = target_tmp_dir().join("texcell-bake");
    let _ = std::fs::remove_dir_all(&out);
    let gpu = gpu();
    for scheme in ["nc", "nlcd"] {
        let table = ClassTable::load(scheme).unwrap();
        let dense: Vec<u8> = table.classes.iter().filter(|c| c.texcells).map(|c| c.code).collect();
        let reports =
            bake_forests(Some(&gpu), &table, &shared.join("models"), &out, &OPTIONS, &mut |_| {}).unwrap();
        assert_eq!(reports.iter().map(|r| r.class_code).collect::<Vec<_>>(), dense);
        for code in dense {
            let sample = texcell::load(&out, code).unwrap().unwrap();
            check(scheme, &sample);
        }
    }
    let _ = std::fs::remove_dir_all(&out);
}

fn check(scheme: &str, s: &ForestSample) {
    let what = format!("{scheme} class {} ({})", s.class_code, s.class_name);
    // The pyramid's shape: 8, 4, 2, 1 slices of 64, 32, 16, 8 texels; the volume 64² × 8 down.
    assert_eq!((s.slice_count(), s.texels()), (8, 64), "{what}");
    let shape: Vec<(usize, u32)> = s.slices.iter().map(|l| (l.len(), l[0].side)).collect();
    assert_eq!(shape, [(8, 64), (4, 32), (2, 16), (1, 8)], "{what}");
    assert_eq!((s.volume[0].side, s.volume[0].depth), (64, 8), "{what}");
    // As dense as the class: 64 m × 64 m of forest at 15,000 trees per km² is about 60 trees.
    assert!((30..=80).contains(&s.trees.len()), "{what}: {} trees", s.trees.len());
    // A forest from above: covered (how much depends on the class's species: nc's pines and oaks
    // close the canopy, nlcd's aspens leave gaps), the top slice only by the tallest crowns.
    let top = s.top_view();
    let covered = mean_alpha(&top);
    let finest = &s.slices[0];
    let per_slice: Vec<f64> = finest.iter().map(|c| mean_alpha(&c.levels[0])).collect();
    let densest = per_slice.iter().copied().fold(0.0, f64::max);
    println!(
        "{what}: {} trees, {:.1} m tall slab, covered {covered:.2}, per slice {per_slice:.3?}",
        s.trees.len(),
        s.height_m
    );
    assert!(covered > 0.15, "{what}: {covered}");
    assert!(per_slice[7] < 0.5 * densest, "{what}: the top slice is as full as the densest");
    // The coarsest slice is every slice composited (then halved three times: the mean stays).
    let coarsest = mean_alpha(&s.slices[3][0].levels[0]);
    assert!((coarsest - covered).abs() < 0.01, "{what}: {coarsest} against {covered}");
    // It wraps: across the square's edge the top view changes as much as between neighbouring
    // columns and rows inside it, no more. (Control: baked without the trees' copies across the
    // wrap, nc's forest changed by 0.78 across the edge against 0.22 inside.)
    let texels = pyramid::decode(&top);
    let side = s.texels() as usize;
    let at = |x: usize, y: usize| texels[(y % side) * side + (x % side)];
    let step = |a: [f32; 4], b: [f32; 4]| (0..4).map(|c| f64::from((a[c] - b[c]).abs())).sum::<f64>();
    let mean_step = |from: usize, horizontal: bool| {
        (0..side)
            .map(|i| {
                if horizontal {
                    step(at(from, i), at(from + 1, i))
                } else {
                    step(at(i, from), at(i, from + 1))
                }
            })
            .sum::<f64>()
            / side as f64
    };
    let inside: f64 = (0..side - 1).map(|k| mean_step(k, true) + mean_step(k, false)).sum::<f64>()
        / (2 * (side - 1)) as f64;
    let seam = 0.5 * (mean_step(side - 1, true) + mean_step(side - 1, false));
    println!("{what}: change across the wrap {seam:.3}, between neighbours inside {inside:.3}");
    assert!(seam < 1.5 * inside, "{what}: the sample does not wrap ({seam} across, {inside} inside)");
}

#[test]
fn the_generated_table_bakes_its_forest_with_no_model_folder_at_all() {
    // The embedded default's table names generated trees only: the baker grows them.
    let out = target_tmp_dir().join("texcell-bake-generated");
    let _ = std::fs::remove_dir_all(&out);
    let table = ClassTable::load("nc-generated").unwrap();
    let nowhere = out.join("no-models-here");
    let reports = bake_forests(Some(&gpu()), &table, &nowhere, &out, &OPTIONS, &mut |_| {}).unwrap();
    assert_eq!(reports.iter().map(|r| r.class_code).collect::<Vec<_>>(), [5]);
    check("nc-generated", &texcell::load(&out, 5).unwrap().unwrap());
    let _ = std::fs::remove_dir_all(&out);
}
