// Pass 2, the ground: the terrain mesh again (`shared/terrain_mesh.wgsl`), at depth-equal, shaded
// with imagery through the imagery cache's page table. Imagery comes from the finest resident
// level at or above the one the pixel footprint asks for (a missing tile shows its ancestor, never
// a hole), sampled with explicit gradients taken from continuous grid-space coordinates, so tile
// edges cause no derivative spikes.

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
    let sun = max(dot(normal, u.sun_dir.xyz), 0.0) * sun_through_clouds(u.cloud_field, u.cloud_shift, in.rel_m);
    let sky = GROUND_SKY * (0.5 + 0.5 * normal.z);
    let lit = albedo * (sun * GROUND_SUN + sky);
    let haze = 1.0 - exp2(-length(in.rel_m) / u.haze.w);
    // The target is sRGB: the hardware encodes on store.
    return vec4<f32>(mix(lit, u.haze.rgb, haze), 1.0);
}
