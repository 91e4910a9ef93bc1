//! How it works: the grown tree becomes two triangle lists, arranged for selection by index range
//! (the paper's prearranged buffers): the bark, its tubes sorted by level so that each level's
//! triangles are one contiguous range (trunk first: a prefix is the tree without its finest
//! twigs); and the leaves, one quad each, sorted by the uniform that decided their survival, so
//! that any run of them is a uniform thinning of the crown. The mean diameter of each level's
//! stems and the leaves' mean size go with them: the continuous LOD's sizes
//! (`impostor::detail`). Tubes are rings of `sides` + 1 vertices
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
    /// Where each vertex's leaf hangs from its stem (the wind turns the leaf about it); for bark,
    /// its stem's base, which names the stem for the continuous LOD (the wind does not turn
    /// stems) (glTF: `_PIVOT`, `bake::model::PIVOT_ATTRIBUTE`).
    pub pivots: Vec<[f32; 3]>,
    /// Triangle indices into the vertices.
    pub indices: Vec<u32>,
}

impl Part {
    /// Triangles in the list.
    pub fn triangles(&self) -> usize {
        self.indices.len() / 3
    }

    /// A vertex whose leaf or stem hangs from `pivot` (`None`: the vertex itself).
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
    /// Per level, its stems' mean diameter, metres (the continuous LOD's size of a level).
    pub level_diameters_m: Vec<f32>,
    /// The leaves' mean size, metres: the side of a square of a leaf's area.
    pub leaf_size_m: f32,
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
    let mut diameter_sums = vec![(0.0, 0); levels];
    for tube in &grown.tubes {
        let start = bark.indices.len() as u32;
        tube_mesh(&mut bark, tube);
        if stems_per_level[tube.level] == 0 {
            bark_levels[tube.level].start = start;
        }
        bark_levels[tube.level].end = bark.indices.len() as u32;
        stems_per_level[tube.level] += 1;
        let (sum, rings) = &mut diameter_sums[tube.level];
        *sum += tube.rings.iter().map(|r| 2.0 * r.radius_m).sum::<f32>();
        *rings += tube.rings.len();
    }
    let level_diameters_m = diameter_sums.iter().map(|&(sum, rings)| sum / rings.max(1) as f32).collect();
    let mut leaves = Part::default();
    for leaf in &grown.leaves {
        leaf_quad(&mut leaves, leaf);
    }
    let leaf_sizes_m = grown.leaves.iter().map(|l| (l.length_m * l.width_m).sqrt()).sum::<f32>();
    TreeMesh {
        bark,
        leaves,
        bark_levels,
        level_diameters_m,
        leaf_size_m: leaf_sizes_m / grown.leaves.len().max(1) as f32,
        stems_per_level,
        leaf_count: grown.leaves.len() as u32,
        height_m: grown.height_m,
    }
}

impl TreeMesh {
    /// The bark of each level (trunk first) as a triangle list of its own: what the glTF writes
    /// as one primitive per level, so that a level's stems are one index range of the mesh.
    pub fn bark_by_level(&self) -> Vec<Part> {
        self.bark_levels.iter().map(|range| self.bark.sub_part(range.clone())).collect()
    }
}

impl Part {
    /// The triangles of `indices` (a range of `self.indices`) with the vertices they use, in
    /// order.
    fn sub_part(&self, indices: Range<u32>) -> Part {
        let indices = &self.indices[indices.start as usize..indices.end as usize];
        let (Some(&first), Some(&last)) = (indices.iter().min(), indices.iter().max()) else {
            return Part::default();
        };
        let vertices = first as usize..=last as usize;
        Part {
            positions: self.positions[vertices.clone()].to_vec(),
            normals: self.normals[vertices.clone()].to_vec(),
            uvs: self.uvs[vertices.clone()].to_vec(),
            pivots: self.pivots[vertices].to_vec(),
            indices: indices.iter().map(|i| i - first).collect(),
        }
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
            part.push(centre + outward * radius, outward, uv, Some(tube.rings[0].centre));
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
