//! How it works: the grown tree becomes two triangle lists, arranged for selection by index range
//! (the paper's prearranged buffers): the bark, its tubes sorted by level so that each level's
//! triangles are one contiguous range (trunk first: a prefix is the tree without its finest
//! twigs); and the leaves, one quad each, sorted by the uniform that decided their survival, so
//! that any prefix is a uniform thinning of the crown. Tubes are rings of `sides` + 1 vertices
//! (the seam doubled for its texture coordinate) joined by quads; bark texture coordinates go once
//! around and run along the stem at the texture's aspect. Leaf normals lean away from the trunk,
//! so a crown lights as a volume rather than as a heap of flat cards. Nothing goes below the
//! ground: a low branch that would is laid on it (y = 0).

use std::f32::consts::TAU;
use std::ops::Range;

use glam::Vec3;

use super::grow::{Grown, Leaf, Tube};

/// Bark texture: texels around the stem and along it (along is twice around).
pub const BARK_TEXELS: [u32; 2] = [64, 128];

/// One triangle list: positions (metres, +Y up), normals, texture coordinates, pivots, indices.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Part {
    /// Vertex positions, metres.
    pub positions: Vec<[f32; 3]>,
    /// Unit normals.
    pub normals: Vec<[f32; 3]>,
    /// Texture coordinates (glTF: v down the image).
    pub uvs: Vec<[f32; 2]>,
    /// Where each vertex's leaf hangs from its stem (the wind turns the leaf about it); the vertex
    /// itself for bark (glTF: `_PIVOT`, `bake::model::PIVOT_ATTRIBUTE`).
    pub pivots: Vec<[f32; 3]>,
    /// Triangle indices into the vertices.
    pub indices: Vec<u32>,
}

impl Part {
    /// Triangles in the list.
    pub fn triangles(&self) -> usize {
        self.indices.len() / 3
    }

    /// A vertex whose leaf hangs from `pivot` (`None`: rigid, the vertex itself).
    fn push(&mut self, position: Vec3, normal: Vec3, uv: [f32; 2], pivot: Option<Vec3>) -> u32 {
        let index = self.positions.len() as u32;
        let on_ground = |p: Vec3| [p.x, p.y.max(0.0), p.z];
        self.positions.push(on_ground(position));
        self.pivots.push(on_ground(pivot.unwrap_or(position)));
        self.normals.push(normal.normalize_or(Vec3::Y).to_array());
        self.uvs.push(uv);
        index
    }
}

/// The tree's meshes and what the tests and the LOD read of them.
#[derive(Debug, Clone, PartialEq)]
pub struct TreeMesh {
    /// The stems' tubes.
    pub bark: Part,
    /// The leaf quads, sorted by rank.
    pub leaves: Part,
    /// Per level (trunk first), its bark triangles' index range in `bark.indices`.
    pub bark_levels: Vec<Range<u32>>,
    /// Stems kept per level.
    pub stems_per_level: Vec<u32>,
    /// Leaves kept.
    pub leaf_count: u32,
    /// Height of the trunk, metres (the crown may reach above it).
    pub height_m: f32,
}

/// Meshes `grown`: tubes by level, leaves by rank.
pub fn build(mut grown: Grown, levels: usize) -> TreeMesh {
    grown.tubes.sort_by_key(|t| t.level);
    grown.leaves.sort_by(|a, b| a.rank.total_cmp(&b.rank));
    let mut bark = Part::default();
    let mut bark_levels = vec![0..0; levels];
    let mut stems_per_level = vec![0; levels];
    for tube in &grown.tubes {
        let start = bark.indices.len() as u32;
        tube_mesh(&mut bark, tube);
        if stems_per_level[tube.level] == 0 {
            bark_levels[tube.level].start = start;
        }
        bark_levels[tube.level].end = bark.indices.len() as u32;
        stems_per_level[tube.level] += 1;
    }
    let mut leaves = Part::default();
    for leaf in &grown.leaves {
        leaf_quad(&mut leaves, leaf);
    }
    TreeMesh {
        bark,
        leaves,
        bark_levels,
        stems_per_level,
        leaf_count: grown.leaves.len() as u32,
        height_m: grown.height_m,
    }
}

fn tube_mesh(part: &mut Part, tube: &Tube) {
    let sides = tube.sides;
    let base_circumference_m = (TAU * tube.rings[0].radius_m).max(1e-4);
    let v_per_m = 1.0 / (base_circumference_m * BARK_TEXELS[1] as f32 / BARK_TEXELS[0] as f32);
    let mut along_m = 0.0;
    let mut previous = tube.rings[0].centre;
    let mut first_ring = 0;
    for (k, ring) in tube.rings.iter().enumerate() {
        let (centre, frame, radius) = (ring.centre, ring.frame, ring.radius_m);
        along_m += centre.distance(previous);
        previous = centre;
        let this_ring = part.positions.len() as u32;
        for i in 0..=sides {
            let angle = TAU * i as f32 / sides as f32;
            let outward = frame * Vec3::new(angle.cos(), 0.0, angle.sin());
            let uv = [i as f32 / sides as f32, along_m * v_per_m];
            part.push(centre + outward * radius, outward, uv, None);
        }
        if k > 0 {
            for i in 0..sides {
                let (a, b) = (first_ring + i, first_ring + i + 1);
                let (c, d) = (this_ring + i, this_ring + i + 1);
                // Counter-clockwise seen from outside.
                part.indices.extend_from_slice(&[a, c, b, b, c, d]);
            }
        }
        first_ring = this_ring;
    }
}

fn leaf_quad(part: &mut Part, leaf: &Leaf) {
    let across = leaf.frame * Vec3::X * (0.5 * leaf.width_m);
    let tip = leaf.frame * Vec3::Y * leaf.length_m;
    let centre = leaf.base + 0.5 * tip;
    let radial = Vec3::new(centre.x, 0.0, centre.z).normalize_or(Vec3::ZERO);
    let mut face = leaf.frame * Vec3::Z;
    if face.dot(radial + 0.5 * Vec3::Y) < 0.0 {
        face = -face;
    }
    let normal = face + radial + 0.5 * Vec3::Y;
    let corners = [
        (leaf.base - across, [0.0, 1.0]),
        (leaf.base + across, [1.0, 1.0]),
        (leaf.base + tip + across, [1.0, 0.0]),
        (leaf.base + tip - across, [0.0, 0.0]),
    ];
    let first = part.positions.len() as u32;
    for (position, uv) in corners {
        part.push(position, normal, uv, Some(leaf.base));
    }
    part.indices.extend_from_slice(&[first, first + 1, first + 2, first, first + 2, first + 3]);
}
