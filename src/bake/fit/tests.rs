use glam::Vec3;

use super::*;

/// A square of side 2 m centred on `centre`, spanned by `a` and `b`, cut into `cuts`² cells of
/// two triangles each.
fn quad(centre: Vec3, a: Vec3, b: Vec3, cuts: u32) -> Vec<[Vec3; 3]> {
    let at = |i: u32, j: u32| {
        centre + a * (2.0 * i as f32 / cuts as f32 - 1.0) + b * (2.0 * j as f32 / cuts as f32 - 1.0)
    };
    (0..cuts)
        .flat_map(|i| (0..cuts).map(move |j| (i, j)))
        .flat_map(|(i, j)| {
            [[at(i, j), at(i + 1, j), at(i + 1, j + 1)], [at(i, j), at(i + 1, j + 1), at(i, j + 1)]]
        })
        .collect()
}

fn parallel(a: Vec3, b: Vec3) -> bool {
    a.dot(b).abs() > 1.0f32.to_radians().cos()
}

#[test]
fn two_crossed_quads_give_those_two_planes() {
    let centre = Vec3::new(0.0, 1.0, 0.0);
    let mut triangles = quad(centre, Vec3::Z, Vec3::Y, 4); // the plane x = 0
    let first = triangles.len() as u32;
    triangles.extend(quad(centre, Vec3::X, Vec3::Y, 4)); // the plane z = 0
    let fit = fit_planes(&triangles, 2, &FitParams::default()).unwrap();
    assert_eq!(fit.planes.len(), 2);
    assert!(fit.covered_fraction >= 0.99, "{fit:?}");
    assert!(fit.epsilon_m < 0.05, "ε = {}", fit.epsilon_m);
    for (normal, owned) in [(Vec3::X, 0..first), (Vec3::Z, first..triangles.len() as u32)] {
        let plane =
            fit.planes.iter().find(|p| parallel(p.normal, normal)).unwrap_or_else(|| panic!("{fit:?}"));
        assert!(plane.offset_m.abs() < 0.02, "{plane:?}");
        // Each plane draws its own quad whole, and of the other only the cells on the crossing.
        assert!(owned.clone().all(|t| plane.triangles.contains(&t)), "{plane:?}");
        let foreign = plane.triangles.iter().filter(|t| !owned.contains(t)).count();
        assert!(foreign <= 8, "{plane:?}");
    }
}

#[test]
fn a_three_layer_slab_gives_its_layers_at_lod_0_like_counts() {
    // Three parallel horizontal quads 1 m apart (a tiered pine, schematically) and one vertical.
    let mut triangles = Vec::new();
    for y in [1.0, 2.0, 3.0] {
        triangles.extend(quad(Vec3::new(0.0, y, 0.0), Vec3::X, Vec3::Z, 2));
    }
    triangles.extend(quad(Vec3::new(0.0, 2.0, 0.0), Vec3::X, Vec3::Y, 2));
    let fit = fit_planes(&triangles, 4, &FitParams::default()).unwrap();
    assert_eq!(fit.planes.len(), 4);
    let horizontal = fit.planes.iter().filter(|p| parallel(p.normal, Vec3::Y)).count();
    assert_eq!(horizontal, 3, "{fit:?}");
    assert!(fit.epsilon_m < 0.05, "ε = {}", fit.epsilon_m);
}

#[test]
fn more_planes_than_the_model_needs_still_gives_that_many_non_empty_planes() {
    let triangles = quad(Vec3::ZERO, Vec3::X, Vec3::Y, 2);
    let fit = fit_planes(&triangles, 3, &FitParams::default()).unwrap();
    assert_eq!(fit.planes.len(), 3);
    assert!(fit.planes.iter().all(|p| !p.triangles.is_empty() && parallel(p.normal, Vec3::Z)), "{fit:?}");
    let drawn: usize = fit.planes.iter().map(|p| p.triangles.len()).sum();
    assert_eq!(drawn, triangles.len(), "split, not duplicated");
}

#[test]
fn models_without_area_are_refused() {
    let flat = vec![[Vec3::ZERO, Vec3::X, Vec3::X * 2.0]];
    assert!(fit_planes(&flat, 2, &FitParams::default()).is_err());
    assert!(fit_planes(&quad(Vec3::ZERO, Vec3::X, Vec3::Y, 1), 0, &FitParams::default()).is_err());
}
