//! Continuous LOD (`draw_seeds.continuous_lod`) drawn on the GPU, over the synthetic dataset with
//! one generated pine standing for every species of the embedded default's table (one bake):
//! - it shows the same forest: near and far, the pixels the trees cover stay within 15 % of what
//!   the whole meshes and the 17-plane clouds cover (leaves thin out and the kept ones grow, so a
//!   crown keeps its area), and it does change the frame (it is on);
//! - the frame's LOD 1 draw is narrowed to a part of the mesh, and a frame drawn twice is the
//!   same, bit for bit.
//!
//! The rule itself (primitives by distance, none below a pixel) is `tests/trees.rs`.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use std::path::PathBuf;

use terramp::bake::{BakeOptions, bake_missing};
use terramp::config::Settings;
use terramp::frame::Renderer;
use terramp_testkit::data::target_tmp_dir;
use terramp_testkit::{camera, ground_settings, renderer, small_settings, synth_dataset};

const IMAGE_PX: [u32; 2] = [480, 270];
const MODEL: &str = "tree-pine-s1-h100";
/// How far the thinned trees' pixels may part from the whole meshes' and 17-plane clouds': the
/// thinning grows each kept leaf back so the crown keeps its projected area (1.05× near, 1.03×
/// far measured, docs/trees.md); a crown that lost the thinned leaves' area, or drew them twice,
/// leaves the range.
const COVER_RATIO: std::ops::RangeInclusive<f64> = 0.85..=1.15;

/// The embedded default's generated table with every species grown as `MODEL`, and its impostor
/// baked (small atlases), in the target's scratch folder.
fn table_and_impostors() -> (PathBuf, PathBuf) {
    let dir = target_tmp_dir().join("continuous-lod");
    std::fs::create_dir_all(&dir).unwrap();
    let text = include_str!("../config/classes/nc_generated.toml");
    let one_model: String = text
        .lines()
        .map(|line| if line.starts_with("model") { format!("model = \"{MODEL}\"") } else { line.to_owned() })
        .collect::<Vec<_>>()
        .join("\n");
    let table = dir.join("pines.toml");
    std::fs::write(&table, one_model).unwrap();
    let impostors = dir.join("impostors");
    let options = BakeOptions { texels: 256, ..Default::default() };
    let baked =
        bake_missing(Some(&terramp_testkit::gpu()), &dir, &[MODEL], &impostors, &options, false).unwrap();
    assert!(baked.absent.is_empty());
    (table, impostors)
}

fn settings(table: &str, impostors: &str, continuous: bool) -> Settings {
    let mut s = small_settings(IMAGE_PX[0], IMAGE_PX[1]);
    s.seeds.class_table = table.to_owned();
    s.draw_seeds.impostors = impostors.to_owned();
    s.draw_seeds.continuous_lod = continuous;
    s
}

fn frame(r: &mut Renderer) -> image::RgbaImage {
    let camera = camera::over_fraction(r, [0.45, 0.35], 40.0, 20.0, -6.0);
    r.render_resolved(&camera).unwrap();
    r.read_colour().unwrap()
}

/// Pixels of `image` that are not `ground`'s, in the lower (near) and upper (far) half of the
/// view's lower two thirds (the sky above holds no tree).
fn covered(image: &image::RgbaImage, ground: &image::RgbaImage) -> [usize; 2] {
    let mut halves = [0; 2];
    for (x, y, p) in image.enumerate_pixels() {
        let row = y * 3 / IMAGE_PX[1];
        if row > 0 && p != ground.get_pixel(x, y) {
            halves[usize::from(row == 1)] += 1;
        }
    }
    halves
}

#[test]
fn thinned_trees_cover_what_whole_ones_do_and_the_frame_is_deterministic() {
    let (table, impostors) = table_and_impostors();
    let (table, impostors) = (table.to_str().unwrap(), impostors.to_str().unwrap());
    let dir = synth_dataset(1024, 7);
    // The ground alone: no seeds grown (selecting them without drawing costs the software adapter
    // seconds a frame here, and draws nothing).
    let ground = frame(&mut renderer(&dir, ground_settings(IMAGE_PX[0], IMAGE_PX[1])));
    let whole = frame(&mut renderer(&dir, settings(table, impostors, false)));
    let mut on = renderer(&dir, settings(table, impostors, true));
    let thinned = frame(&mut on);
    let (whole_px, thinned_px) = (covered(&whole, &ground), covered(&thinned, &ground));
    let changed = whole.pixels().zip(thinned.pixels()).filter(|(a, b)| a != b).count();
    println!(
        "trees cover {whole_px:?} pixels (near, far) whole, {thinned_px:?} thinned; {changed} pixels differ"
    );
    for (half, (w, t)) in ["near", "far"].iter().zip(whole_px.iter().zip(&thinned_px)) {
        assert!(*w > 500, "{half}: only {w} tree pixels: a weak test");
        let ratio = *t as f64 / *w as f64;
        assert!(COVER_RATIO.contains(&ratio), "{half}: thinned trees cover {ratio:.3} × the whole ones'");
    }
    assert!(changed > 100, "continuous LOD changed only {changed} pixels: is it on?");

    // LOD 1's draw of some species is a part of its mesh this frame.
    let templates = on.seed_draw_templates().unwrap();
    let narrowed = (0..terramp::gpu::layout::MAX_SPECIES as usize)
        .filter(|s| {
            let lods = terramp::gpu::layout::SEED_LODS as usize;
            let (mesh, lod1) = (templates[s * lods], templates[s * lods + 1]);
            mesh.index_count > 0 && lod1.index_count < mesh.index_count
        })
        .count();
    assert!(narrowed > 0, "no LOD 1 draw was narrowed");
    assert_eq!(frame(&mut on), thinned, "the same frame drawn again differs");
}
