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

// The mapping's derivatives at `offset_m` from `node`'s origin: how the point there moves per
// metre of x, of y and of height (the polynomial's Jacobian, its columns).
fn earth_jacobian(node: EarthNode, offset_m: vec3<f32>) -> mat3x3<f32> {
    let dx = offset_m.x;
    let dy = offset_m.y;
    let dh = offset_m.z;
    let along_x = node.d_x.xyz + (2.0 * dx) * node.d_xx.xyz + dy * node.d_xy.xyz + dh * node.d_xh.xyz;
    let along_y = node.d_y.xyz + dx * node.d_xy.xyz + (2.0 * dy) * node.d_yy.xyz + dh * node.d_yh.xyz;
    let up = node.d_h.xyz + dx * node.d_xh.xyz + dy * node.d_yh.xyz;
    return mat3x3<f32>(along_x, along_y, up);
}

// The normal, not unit, of a surface whose normal on the flat sheet is `normal`, where it passes
// `offset_m` from `node`'s origin: tangents move by the Jacobian J, so normals by its cofactor
// matrix det(J) J⁻ᵀ. The identity's is the identity, term by term.
fn earth_normal(node: EarthNode, offset_m: vec3<f32>, normal: vec3<f32>) -> vec3<f32> {
    let j = earth_jacobian(node, offset_m);
    return normal.x * cross(j[1], j[2]) + normal.y * cross(j[2], j[0]) + normal.z * cross(j[0], j[1]);
}

// The flat sheet's direction, not unit, of camera-frame direction `direction` at `node`'s origin
// (J⁻¹ times det J: the rows of the cofactor matrix).
fn earth_flat_direction(node: EarthNode, direction: vec3<f32>) -> vec3<f32> {
    let j = earth_jacobian(node, vec3<f32>(0.0));
    return vec3<f32>(
        dot(cross(j[1], j[2]), direction),
        dot(cross(j[2], j[0]), direction),
        dot(cross(j[0], j[1]), direction),
    );
}

// `v`, given in a frame whose z is straight up, stood on a place whose local vertical is `up`
// (unit, or within 1e-6 of it): turned by the least rotation that takes z to `up` (about
// z × up). Straight up, every vector comes back as it went in, to the bit (its products are by
// 1 and 0).
fn earth_stand(v: vec3<f32>, up: vec3<f32>) -> vec3<f32> {
    let c = 1.0 / (1.0 + up.z);
    let x = vec3<f32>(1.0 - up.x * up.x * c, -up.x * up.y * c, -up.x);
    let y = vec3<f32>(-up.x * up.y * c, 1.0 - up.y * up.y * c, -up.y);
    return x * v.x + y * v.y + up * v.z;
}

// `earth_stand`'s inverse: camera-frame `v` in the frame of a place whose vertical is `up`.
fn earth_unstand(v: vec3<f32>, up: vec3<f32>) -> vec3<f32> {
    let c = 1.0 / (1.0 + up.z);
    let x = vec3<f32>(1.0 - up.x * up.x * c, -up.x * up.y * c, -up.x);
    let y = vec3<f32>(-up.x * up.y * c, 1.0 - up.y * up.y * c, -up.y);
    return vec3<f32>(dot(x, v), dot(y, v), dot(up, v));
}
