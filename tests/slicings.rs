//! Slicings (Jakulin 2000) baked from the shared models (`terramp::bake`, `BakeOptions::slicing`):
//! the trunk and limbs (bark materials) stay the mesh, the crown goes onto 6 slicings of 5 slices;
//! a model without a crown gets none; the slices of a slicing line up (one box, equally spaced);
//! every crown vertex shows (an opaque texel within 2 texels of where it projects) on some slice
//! of some slicing, and in each slicing all but the few on leaves it sees edge-on; all of it read
//! back from the impostor folder. The 17-plane billboard cloud's figure is printed beside it.
#![allow(clippy::unwrap_used, reason = "a test fails by panicking, and says where")]

use glam::Vec3;
use terramp::bake::{BakeOptions, SlicingOptions, bake_models};
use terramp::impostor::slicing::orientation;
use terramp::impostor::{Impostor, MipChain, Plane, load};
use terramp_testkit::{TempDir, shared_data};

const OPTIONS: SlicingOptions = SlicingOptions { orientations: 6, slices: 5 };

/// The model's crown vertices (those of its materials that are not bark), model space.
fn crown_vertices(impostor: &Impostor) -> Vec<Vec3> {
    let mesh = &impostor.mesh;
    mesh.submeshes
        .iter()
        .filter(|s| !mesh.materials[s.material as usize].is_bark())
        .flat_map(|s| &mesh.indices[s.first_index as usize..(s.first_index + s.index_count) as usize])
        .map(|&i| Vec3::from(mesh.vertices[i as usize].position_model_m))
        .collect()
}

/// Whether `plane`'s rectangle of `atlas` has an opaque texel within `reach` texels of where `p`
/// projects.
fn shows(atlas: &MipChain, plane: &Plane, p: Vec3, reach: i64) -> bool {
    let [w, h] = atlas.size;
    let corners = plane.corners_model_m.map(Vec3::from);
    let (right, up) = (corners[1] - corners[0], corners[3] - corners[0]);
    let (s, t) = (
        (p - corners[0]).dot(right) / right.length_squared(),
        (p - corners[0]).dot(up) / up.length_squared(),
    );
    // Corner 0 (bottom left) is at (uv_min.x, uv_max.y); v grows downwards.
    let u = plane.uv_min[0] + s * (plane.uv_max[0] - plane.uv_min[0]);
    let v = plane.uv_max[1] - t * (plane.uv_max[1] - plane.uv_min[1]);
    let (x, y) = ((u * w as f32) as i64, (v * h as f32) as i64);
    (-reach..=reach).any(|dy| {
        (-reach..=reach).any(|dx| {
            let (xx, yy) = (x + dx, y + dy);
            xx >= 0
                && yy >= 0
                && xx < i64::from(w)
                && yy < i64::from(h)
                && atlas.levels[0][4 * (yy as usize * w as usize + xx as usize) + 3] >= 128
        })
    })
}

#[test]
fn crowns_are_sliced_trunks_stay_meshes_and_every_crown_vertex_shows_in_a_slicing() {
    let Some(shared) = shared_data() else { return };
    let models = shared.join("models");
    let out = TempDir::new("slicings");
    let files: Vec<_> = ["Pine_1", "Bush_1", "DeadTree_1"].map(|m| models.join(format!("{m}.glb"))).into();
    let options = BakeOptions { texels: 512, slicing: Some(OPTIONS), ..Default::default() };
    bake_models(None, &files, out.path(), &options, false).unwrap();
    let [pine, bush, dead] = ["Pine_1", "Bush_1", "DeadTree_1"].map(|m| load(out.path(), m).unwrap());

    assert!(dead.slicing.is_none(), "an all-bark model has no crown to slice");
    let triangles = |i: &Impostor| i.mesh.indices.len() as u32 / 3;
    let bush_slicing = bush.slicing.as_ref().unwrap();
    assert_eq!((bush_slicing.crown_triangles, bush_slicing.trunk_triangles), (triangles(&bush), 0));
    let slicing = pine.slicing.as_ref().unwrap();
    println!(
        "Pine_1: crown {} triangles sliced, trunk {} left to the mesh, ε = {:.2} m",
        slicing.crown_triangles, slicing.trunk_triangles, slicing.lod.epsilon_m
    );
    assert_eq!(slicing.crown_triangles + slicing.trunk_triangles, triangles(&pine));
    assert!(slicing.trunk_triangles > 0 && slicing.crown_triangles > slicing.trunk_triangles);
    assert_eq!(slicing.lod.planes.len(), 30);

    let crown = crown_vertices(&pine);
    let slices = OPTIONS.slices as usize;
    for (i, planes) in slicing.lod.planes.chunks(slices).enumerate() {
        let normal = orientation(i as u32, OPTIONS.orientations);
        // One box: each slice is the first moved along the normal by a whole number of spacings.
        let spacing =
            normal.dot(Vec3::from(planes[1].corners_model_m[0]) - Vec3::from(planes[0].corners_model_m[0]));
        for (j, plane) in planes.iter().enumerate() {
            assert!((Vec3::from(plane.normal_model) - normal).length() < 1e-5);
            for (c, corner) in plane.corners_model_m.iter().enumerate() {
                let moved = Vec3::from(planes[0].corners_model_m[c]) + normal * spacing * j as f32;
                assert!((Vec3::from(*corner) - moved).length() < 1e-3, "slicing {i} slice {j} corner {c}");
            }
        }
        let atlas = &slicing.lod.atlas;
        let missing =
            crown.iter().filter(|&&p| !planes.iter().any(|plane| shows(atlas, plane, p, 2))).count();
        println!("slicing {i}: {missing} of {} crown vertices show on none of its slices", crown.len());
        // A leaf seen edge-on from the slicing's side draws nothing there (as in the mesh): the
        // reason two slicings are blended.
        assert!(missing * 10 <= crown.len(), "slicing {i} loses {missing} of {} crown vertices", crown.len());
    }
    let atlas = &slicing.lod.atlas;
    let in_none =
        crown.iter().filter(|&&p| !slicing.lod.planes.iter().any(|plane| shows(atlas, plane, p, 2))).count();
    println!("all slicings: {in_none} of {} crown vertices show on none of their slices", crown.len());
    assert_eq!(in_none, 0, "crown vertices lost by every slicing");
    let cloud = &pine.lods[0];
    let missing =
        crown.iter().filter(|&&p| !cloud.planes.iter().any(|plane| shows(&cloud.atlas, plane, p, 2))).count();
    println!("17-plane cloud: {missing} of {} crown vertices show on none of its planes", crown.len());
}
