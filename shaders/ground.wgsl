// Pass 2, the ground: the terrain mesh again (`shared/terrain_mesh.wgsl`), at depth-equal, shaded
// with imagery through the imagery cache's page table. Imagery comes from the finest resident
// level at or above the one the pixel footprint asks for (a missing tile shows its ancestor, never
// a hole), sampled with explicit gradients taken from continuous grid-space coordinates, so tile
// edges cause no derivative spikes. Lit and seen through the air as `shared/air.wgsl` says.

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let normal = normalize(in.normal);
    let height_m = in.height_m;
    // Where the imagery has no data (or no tile is resident yet), the relief tint shows.
    var imagery = vec4<f32>(0.0);
    if u.imagery_texels != IMAGERY_NONE {
        imagery = imagery_albedo(in.grid_m);
    }
    let albedo = ground_albedo(imagery, height_m, normal);
    // Lit by the sun through the air and the clouds, and by the sky from the half of it the
    // normal faces (a slope facing sideways sees half of it).
    let light = light_at(in.rel_m);
    let sun = max(dot(normal, u.sun_dir.xyz), 0.0) * sun_through_clouds(u.cloud_field, u.cloud_shift, in.rel_m);
    let lit = albedo * (light.sun * sun + light.sky * (0.5 + 0.5 * dot(normal, light.up)));
    return vec4<f32>(through_air(lit, in.rel_m), 1.0);
}
