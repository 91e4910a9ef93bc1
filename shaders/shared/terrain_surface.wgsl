// The ground as the terrain mesh draws it (Rust: `dataset::surface`, whose notes say why): each
// cell of a height level split into two triangles along a diagonal alternating like a
// checkerboard, the height that of the triangle holding the point. The shader including this
// defines `mul(a, b)`, a product never fused into the add that follows, so that its CPU twin
// takes the same f32 steps.

// Whether the mesh splits cell `cell` (its south-west sample) along its rising diagonal, south-west
// to north-east, rather than its falling one (Rust: `diagonal_rises`).
fn diagonal_rises(cell: vec2<u32>) -> bool {
    return ((cell.x ^ cell.y) & 1u) == 0u;
}

struct DrawnGround {
    height_m: f32,
    // Height change per cell east and north.
    slope: vec2<f32>,
}

// The drawn ground at position `f` in `cell` whose corners' heights are `corners` (south-west,
// south-east, north-west, north-east): the triangle named by its right-angle corner `c`
// (Rust: `drawn_height`).
fn drawn_ground(cell: vec2<u32>, corners: vec4<f32>, f: vec2<f32>) -> DrawnGround {
    var c = select(vec2<u32>(0u), vec2<u32>(1u), f.x + f.y > 1.0);
    if diagonal_rises(cell) {
        c = select(vec2<u32>(0u, 1u), vec2<u32>(1u, 0u), f.x >= f.y);
    }
    let slope = vec2<f32>(corners[c.y * 2u + 1u] - corners[c.y * 2u], corners[2u + c.x] - corners[c.x]);
    let offset = f - vec2<f32>(c);
    let height_m = corners[c.y * 2u + c.x] + mul(slope.x, offset.x) + mul(slope.y, offset.y);
    return DrawnGround(height_m, slope);
}
