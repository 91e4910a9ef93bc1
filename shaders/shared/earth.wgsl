// The one mapping from a dataset's points into the camera's local frame, a node at a time (Rust:
// `earth::local`): the CPU forms each node's origin relative to the camera in f64 and rounds it
// once, with the mapping's first and second derivatives there (`EarthNode`); a point at CRS
// offset (dx, dy) from the origin and dh above it is placed by the second-order polynomial, the
// small terms summed first and the origin added last, in the order `NodeMapping::position_m` sums
// them.

struct EarthNode {
    origin_m: vec4<f32>,
    d_x: vec4<f32>,
    d_y: vec4<f32>,
    d_h: vec4<f32>,
    d_xx: vec4<f32>,
    d_xy: vec4<f32>,
    d_yy: vec4<f32>,
    d_xh: vec4<f32>,
    d_yh: vec4<f32>,
}

// The camera-relative position, metres (east, north, up at the camera), of the point at CRS
// offset `offset_m.xy` from `node`'s origin and `offset_m.z` above it.
fn earth_position_m(node: EarthNode, offset_m: vec3<f32>) -> vec3<f32> {
    let dx = offset_m.x;
    let dy = offset_m.y;
    let dh = offset_m.z;
    let curved = node.d_xx.xyz * (dx * dx) + node.d_xy.xyz * (dx * dy) + node.d_yy.xyz * (dy * dy);
    let turned = (node.d_xh.xyz * dx + node.d_yh.xyz * dy) * dh;
    let linear = node.d_x.xyz * dx + node.d_y.xyz * dy + node.d_h.xyz * dh;
    return node.origin_m.xyz + (linear + (curved + turned));
}
