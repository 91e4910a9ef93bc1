// Pass 4, drawing the seeds: two indexed indirect draws per (species, LOD) group, whose
// instances are the draw slots compaction gave the group: the group's own geometry (LOD 0 the
// real mesh, 1 to 3 the billboard clouds; model space: metres, +Y up, base at y = 0), then the
// next LOD's, for the cross-fade. An instance reads its record through `order`, places the model
// at the record's camera-relative anchor, scaled to its height and turned about the vertical by
// its jitter, bent by the wind (`shared/wind.wgsl`: the same field for every LOD, so a cross-fade
// shows one plant swaying), and projects it like the terrain. Fragments take their material's
// colour (times a layer of the texture array), are alpha-tested, follow the photograph's colour
// under the seed (foliage, by its species' `ground_blend`; bark keeps its own: the colour
// follow-up, a ratio transfer, `photo_scale`), are varied by the seed's colour variation and by
// the luminosity of their place in the plant (`crown_luminosity`), lit (the sun through the air
// and the clouds, the sky: `shared/air.wgsl`, `shared/clouds.wgsl`) and seen through the air
// like the ground. A seed a few pixels tall seen from
// above shows its mean colour instead of one sample of its detail a pixel (`small_seed_mean`).
//
// Continuous LOD (`draw_seeds.continuous_lod`, `u.continuous_lod`): a mesh whose materials say how
// they shed detail thins its leaves and its thin stems as they shrink on screen, per seed
// (`detail_position`), and serves LOD 1 too: its materials' `last_lod`.
//
// Cross-fade: over the outer `fade_fraction` of its LOD's reach a seed's fade f falls from 1 to
// 0. Its own geometry keeps the pixels whose ordered-dither threshold t (Bayer 4×4, shifted per
// seed so neighbours do not share a pattern) is below f, the next LOD's geometry those at or above
// it: each pixel shows one of the two, and the mix moves smoothly with distance. Outside the band
// the cross-fade draw collapses its vertices; the last LOD has none and fades out to nothing, as
// does the last LOD a seed's class draws (`SpeciesLod::last`, `classes::Class::seed_lods`).

struct DrawSeedsUniforms {
    clip_from_view_world: mat4x4<f32>,
    sun_dir: vec4<f32>,
    draw_reach_m: vec4<f32>,
    inv_reference_height_m: f32,
    sink_fraction: f32,
    fade_fraction: f32,
    focal_px: f32,
    wind: vec4<f32>,
    wind_wave: vec4<f32>,
    cloud_field: vec4<f32>,
    cloud_shift: vec4<f32>,
    seed_up: vec4<f32>,
    seed_up_per_x_m: vec4<f32>,
    seed_up_per_y_m: vec4<f32>,
    continuous_lod: u32,
    prefilter_small: u32,
    _pad0: u32,
    _pad1: u32,
    from_above: array<vec4<f32>, SEED_GROUPS>,
}

struct SeedShape {
    inv_model_height_m: f32,
    wind_bend: f32,
    ground_blend: f32,
    crown_shading: f32,
}

struct SeedMaterial {
    base_colour: vec4<f32>,
    layer: u32,
    alpha_cutoff: f32,
    lod: u32,
    flags: u32,
    last_lod: u32,
    detail_m: f32,
    first_leaf_vertex: u32,
    leaf_count: u32,
    slicings: u32,
    slicing_brightness: f32,
    _pad0: u32,
    _pad1: u32,
}

// A storage binding, not a uniform one: Mesa lavapipe specialises a shader on the values of
// uniforms that steer loops and branches and keeps every variant, and these change every frame
// (a leak of about 0.35 MiB a frame with seeds drawn, caught by tests/seed_flight_memory.rs).
@group(0) @binding(0) var<storage, read> u: DrawSeedsUniforms;
@group(0) @binding(1) var<storage, read> records: array<SeedRecord>;
@group(0) @binding(2) var<storage, read> order: array<u32>;
@group(0) @binding(3) var<storage, read> shapes: array<SeedShape>;
@group(0) @binding(4) var<storage, read> materials: array<SeedMaterial>;
@group(0) @binding(5) var textures: texture_2d_array<f32>;
@group(0) @binding(6) var clamp_sampler: sampler;
@group(0) @binding(7) var repeat_sampler: sampler;

struct VertexIn {
    @location(0) position_model_m: vec3<f32>,
    @location(1) normal_model: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) material: u32,
    @location(4) pivot_model_m: vec3<f32>,
}

struct VertexOut {
    // Invariant: the depth prepass and the shading draw after it (`fs_depth`, then a draw whose
    // depth must equal it) compile this shader with different fragment stages, and each must place
    // every vertex bit for bit where the other did.
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) rel_m: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    // Albedo tint (rgb).
    @location(3) @interpolate(flat) tint: vec3<f32>,
    @location(4) @interpolate(flat) material: u32,
    // The colour follow-up's factor on the albedo, per channel (`photo_scale`).
    @location(5) @interpolate(flat) follow: vec3<f32>,
    // Dither thresholds this draw keeps, [x, y), and the seed's shift of the dither pattern (z).
    @location(6) @interpolate(flat) keep: vec3<f32>,
    // The seed's record: what the ground truth's id buffer names.
    @location(7) @interpolate(flat) record: u32,
    // Luminosity by position inside the plant (`crown_luminosity`).
    @location(8) luminosity: f32,
    // The dither range a slice keeps of the slicings' blend (`slice_blend`); [0, 2) elsewhere.
    @location(9) @interpolate(flat) blend: vec2<f32>,
    // The seed's mean albedo seen from above, in units of flat ground's light (rgb), and how much
    // of it the foliage shows in place of its own detail (w, `small_seed_mean`).
    @location(10) @interpolate(flat) far: vec4<f32>,
    // The light at the seed's anchor (`light_at`): a plant is small beside the distances over
    // which the sun's and the sky's light change, so every fragment of it takes its anchor's.
    @location(11) @interpolate(flat) sun_light: vec3<f32>,
    @location(12) @interpolate(flat) sky_light: vec3<f32>,
    @location(13) @interpolate(flat) air_up: vec3<f32>,
}

// The local vertical at camera-relative `rel_m` (pass 3's `up_at`, from the camera's mapping):
// straight up on the flat sheet.
fn seed_up(rel_m: vec3<f32>) -> vec3<f32> {
    return u.seed_up.xyz + u.seed_up_per_x_m.xyz * rel_m.x + u.seed_up_per_y_m.xyz * rel_m.y;
}

// Model space (x, y up, z) to world (x east, y north, z up), turned by `angle` about the vertical:
// the seed's own frame, which `earth_stand` stands on its place.
fn model_to_world(v: vec3<f32>, angle: f32) -> vec3<f32> {
    let w = vec3<f32>(v.x, -v.z, v.y);
    let c = cos(angle);
    let s = sin(angle);
    return vec3<f32>(c * w.x - s * w.y, s * w.x + c * w.y, w.z);
}

// Luminosity by position inside the plant (Amara et al. § 5): darker low in its crown and on its
// side away from the sun, by the species' `crown_shading`, from the vertex's height over the
// model's and its offset from the axis towards the sun over the crown's half width; exactly 1
// without crown shading.
fn crown_luminosity(shape: SeedShape, position_model_m: vec3<f32>, angle: f32) -> f32 {
    if shape.crown_shading <= 0.0 {
        return 1.0;
    }
    let height = clamp(position_model_m.y * shape.inv_model_height_m, 0.0, 1.0);
    let offset = model_to_world(position_model_m, angle).xy * shape.inv_model_height_m;
    let sun_across = length(u.sun_dir.xy);
    var side = 0.0;
    if sun_across > 1e-3 {
        side = clamp(dot(offset, u.sun_dir.xy / sun_across) / CROWN_HALF_WIDTH_PER_HEIGHT, -1.0, 1.0);
    }
    return 1.0 - shape.crown_shading * (0.5 * (1.0 - height) + 0.25 * (1.0 - side));
}

// Slicings (Jakulin 2000, Rust twin `impostor::slicing::view_blend`): the dither range a slice
// of `material` keeps, by the blend of the two slicings whose orientations are nearest the eye as
// seen from the crown's middle (the seed's mid-height), in model space. [0, α̅) in the one at the
// lower azimuth, [1 − α̅, 1] in the other: complementary, so where the corrected opacities sum
// past 1 a pixel shows both, and no sort is needed; and by azimuth rather than by role, so each
// slicing keeps its pixels when the two trade roles half-way. Empty (x ≥ y) in the other
// slicings. The slice's own slicing is its normal's.
fn slice_blend(material: SeedMaterial, normal_model: vec3<f32>, record: SeedRecord, angle: f32, up: vec3<f32>) -> vec2<f32> {
    let tau = 6.2831853;
    let n = max(material.slicings, 1u);
    let step = tau / f32(n);
    let centre_rel = record.position_rel_m + up * (record.height_m * (u.sink_fraction + 0.5));
    // World to model space: into the seed's own frame, undo the turn about the vertical, then
    // model_to_world's axes.
    let eye = earth_unstand(-centre_rel, up);
    let c = cos(angle);
    let s = sin(angle);
    let w = vec2<f32>(c * eye.x + s * eye.y, c * eye.y - s * eye.x);
    let azimuth = atan2(-w.y, w.x);
    let wrapped = azimuth - floor(azimuth / tau) * tau;
    let nearest = round(wrapped / step);
    let primary = u32(nearest) % n;
    let discrepancy = wrapped - nearest * step;
    var secondary = (primary + n - 1u) % n;
    if discrepancy >= 0.0 {
        secondary = (primary + 1u) % n;
    }
    var alpha_primary = 1.0;
    if n > 1u {
        alpha_primary = 1.0 - abs(discrepancy) / step;
    }
    let alpha_secondary = 1.0 - alpha_primary;
    let brightness = 1.0 + material.slicing_brightness * alpha_secondary;
    let own_azimuth = atan2(normal_model.z, normal_model.x);
    let own = u32(round((own_azimuth - floor(own_azimuth / tau) * tau) / step)) % n;
    var alpha = 0.0;
    if own == primary {
        alpha = brightness * alpha_primary;
    } else if own == secondary {
        alpha = brightness * alpha_secondary;
    } else {
        return vec2<f32>(1.0, 0.0);
    }
    // The lower of the two (the primary when the eye is past it) keeps the low thresholds.
    if (own == primary) == (discrepancy >= 0.0) {
        return vec2<f32>(0.0, alpha);
    }
    return vec2<f32>(1.0 - alpha, 2.0);
}

// How far the seed's foot is from the eye (its anchor was sunk by pass 3), metres.
fn seed_distance_m(record: SeedRecord, up: vec3<f32>) -> f32 {
    let ground_rel = record.position_rel_m + up * (record.height_m * u.sink_fraction);
    return length(ground_rel);
}

// 1 inside the seed's LOD reach, falling to 0 over the last `fade_fraction` of it.
fn band_fade(record: SeedRecord, lod: u32, distance_m: f32) -> f32 {
    let size_scale = min(1.0, record.height_m * u.inv_reference_height_m);
    let reach = u.draw_reach_m[min(lod, SEED_LODS - 1u)] * size_scale;
    // Without a band (fade_fraction 0) a seed is whole up to its reach, then the next LOD's.
    let width = max(reach * u.fade_fraction, 1e-6);
    return clamp((reach - distance_m) / width, 0.0, 1.0);
}

// Continuous LOD (`impostor::detail`, same steps as its Rust): where vertex `vertex` of material
// `material_index` lies (model space, w = 1) on seed `seed_bits` drawn `scale` times its model's
// size `distance_m` away, or w = 0 when its primitive is left out. Leaves below DETAIL_FULL_PX
// keep the last (ratio to it)² share of them in buffer order, each grown about its pivot back to
// DETAIL_FULL_PX; stems narrower than DETAIL_MIN_PX are widened along their normals to it where
// the hash of the stem (its base, which its pivot holds) and the seed falls below the ratio.
fn detail_position(in: VertexIn, vertex: u32, scale: f32, distance_m: f32, seed_bits: u32) -> vec4<f32> {
    let material = materials[in.material];
    if (material.flags & (MATERIAL_LEAVES | MATERIAL_STEMS)) == 0u {
        return vec4<f32>(in.position_model_m, 1.0);
    }
    let size_px = material.detail_m * scale * u.focal_px / max(distance_m, 1e-3);
    if (material.flags & MATERIAL_STEMS) != 0u {
        if size_px >= DETAIL_MIN_PX {
            return vec4<f32>(in.position_model_m, 1.0);
        }
        var share = 0.0;
        if size_px > 0.0 {
            share = size_px / DETAIL_MIN_PX;
        }
        // Each stem its own draw, hashed from its base (its pivot) and the seed.
        let base = bitcast<vec3<u32>>(in.pivot_model_m);
        let unit = f32(pcg(seed_bits ^ pcg(base.x ^ pcg(base.y ^ pcg(base.z)))) >> 8u) / 16777216.0;
        if unit >= share {
            return vec4<f32>(0.0);
        }
        let widen_m = 0.5 * material.detail_m * (DETAIL_MIN_PX / max(size_px, 1e-6) - 1.0);
        return vec4<f32>(in.position_model_m + in.normal_model * widen_m, 1.0);
    }
    var ratio = 0.0;
    if size_px > 0.0 {
        ratio = min(size_px / DETAIL_FULL_PX, 1.0);
    }
    if ratio >= 1.0 {
        return vec4<f32>(in.position_model_m, 1.0);
    }
    let leaf = (vertex - material.first_leaf_vertex) / 4u;
    let share = ratio * ratio;
    if f32(material.leaf_count - min(leaf, material.leaf_count)) - 0.5 >= share * f32(material.leaf_count) {
        return vec4<f32>(0.0);
    }
    let growth = 1.0 / max(ratio, 1e-6);
    return vec4<f32>(in.pivot_model_m + (in.position_model_m - in.pivot_model_m) * growth, 1.0);
}

@vertex
fn vs_main(
    in: VertexIn,
    @builtin(instance_index) instance: u32,
    @builtin(vertex_index) vertex: u32,
) -> VertexOut {
    let record = records[order[instance]];
    let seed = unpack_species_lod(record.species_lod);
    let species = seed.species;
    let lod = seed.lod;
    let material = materials[in.material];
    let up = seed_up(record.position_rel_m);
    let distance_m = seed_distance_m(record, up);
    var fade = band_fade(record, lod, distance_m);
    // In its class's last LOD a seed fades out to nothing, as in the last band: no next LOD.
    let last = seed.last != 0u;
    if material.lod <= lod && lod < material.last_lod && !last {
        // Its own geometry goes on as the next LOD (continuous LOD): nothing to cross-fade.
        fade = 1.0;
    }
    var out: VertexOut;
    out.record = order[instance];
    // The group's own geometry keeps thresholds below the fade, the next LOD's the rest.
    out.keep = vec3<f32>(0.0, fade, f32(record.rank & 15u));
    if lod < material.lod || lod > material.last_lod {
        out.keep = vec3<f32>(fade, 2.0, f32(record.rank & 15u));
        if fade >= 1.0 || (last && lod < material.lod) {
            // Not in the band, or no next LOD: nothing to cross-fade. Every vertex at one point
            // outside the view.
            out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
            return out;
        }
    }
    let jitter = unpack_seed_jitter(record.jitter);
    let angle = f32(jitter.angle) * (6.2831853 / 65536.0);
    let shape = shapes[min(species, arrayLength(&shapes) - 1u)];
    let scale = record.height_m * shape.inv_model_height_m;
    out.blend = vec2<f32>(0.0, 2.0);
    if (material.flags & MATERIAL_SLICE) != 0u {
        out.blend = slice_blend(material, in.normal_model, record, angle, up);
        if out.blend.x >= out.blend.y {
            // A slicing the view does not blend: every vertex at one point outside the view.
            out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
            return out;
        }
    }
    var position_model_m = in.position_model_m;
    if u.continuous_lod != 0u {
        let detailed = detail_position(in, vertex, scale, distance_m, record.jitter);
        if detailed.w == 0.0 {
            out.clip = vec4<f32>(2.0, 2.0, 2.0, 1.0);
            return out;
        }
        position_model_m = detailed.xyz;
    }
    // Still air (or a rock) leaves every vertex where it was, bit for bit: this expression is
    // the one the pass had before the wind, and nothing else uses its products (a compiler may
    // fuse a product into the add only where the product has no other use).
    var rel_m = record.position_rel_m + earth_stand(model_to_world(position_model_m * scale, angle), up);
    // In wind, a leaf turns about where it hangs, then the whole plant bends.
    if u.wind.z > 0.0 && shape.wind_bend > 0.0 {
        // (A stem's pivot names it for the continuous LOD: stems do not flutter.)
        var pivot_model_m = in.pivot_model_m;
        if (material.flags & MATERIAL_STEMS) != 0u {
            pivot_model_m = position_model_m;
        }
        let pivot_m = model_to_world(pivot_model_m * scale, angle);
        let leaf_m = model_to_world((position_model_m - pivot_model_m) * scale, angle);
        let fluttered = wind_flutter(u.wind, u.wind_wave, leaf_m, pivot_model_m, record.height_m);
        let top_m = wind_top_m(u.wind, u.wind_wave, record.position_rel_m, record.height_m, record.jitter);
        let bent = wind_bend(pivot_m + fluttered, top_m * shape.wind_bend, record.height_m);
        rel_m = record.position_rel_m + earth_stand(bent, up);
    }
    out.clip = u.clip_from_view_world * vec4<f32>(rel_m, 1.0);
    out.rel_m = rel_m;
    out.normal = earth_stand(model_to_world(in.normal_model, angle), up);
    out.uv = in.uv;
    // Colour variation: brightness ±15 % and a slight shift between yellow-green and blue-green.
    let variation = f32(jitter.colour) / 65535.0 - 0.5;
    let shift = vec3<f32>(1.0 + 0.3 * variation, 1.0, 1.0 - 0.3 * variation);
    out.tint = shift * (1.0 + 0.3 * variation);
    out.material = in.material;
    // The colour follow-up: foliage is scaled so that, seen from above, its geometry's mean lit
    // colour is the photograph's under the seed, lit as the ground lights it (a ratio transfer:
    // the model keeps its texture, shading and gaps). Bark keeps its own colour, as does
    // geometry with no foliage to measure (a scale of 0).
    let ground = unpack4x8unorm(record.ground_colour);
    let light = light_at(record.position_rel_m);
    out.sun_light = light.sun;
    out.sky_light = light.sky;
    out.air_up = light.up;
    let photo_scale = photo_scale_at(u.from_above[seed_group(species, material.lod)], light);
    var follow = shape.ground_blend * ground.a;
    if (material.flags & MATERIAL_BARK) != 0u || photo_scale.g <= 0.0 {
        follow = 0.0;
    }
    out.follow = mix(vec3<f32>(1.0), ground.rgb * photo_scale, follow);
    out.far = vec4<f32>(0.0);
    if u.prefilter_small != 0u && (material.flags & MATERIAL_BARK) == 0u && photo_scale.g > 0.0 {
        // The model's own mean is the photograph's yardstick over its factor.
        let mean = mix(1.0 / max(photo_scale, vec3<f32>(1e-4)), ground.rgb, follow) * out.tint;
        out.far = vec4<f32>(mean, small_seed_mean(record, distance_m, up));
    }
    out.luminosity = crown_luminosity(shape, position_model_m, angle);
    return out;
}

// The colour follow-up's factor per channel for a group seen from above as `from_above` says
// (mean albedo, xyz; mean facing towards the sun, w: `draw_seeds::from_above`) under a seed's
// `light`: level ground's light over the group's mean lit colour, clouds aside; 0 where nothing is
// measured or lit (the seed keeps its own colours). Twin: `FromAbove::photo_scale`.
fn photo_scale_at(from_above: vec4<f32>, light: SunAndSky) -> vec3<f32> {
    let sun_up = max(dot(light.up, u.sun_dir.xyz), 0.0);
    let foliage = light.sun * (FOLIAGE_SUN * from_above.w + FOLIAGE_SUN_WRAP * sun_up) + light.sky * FOLIAGE_SKY;
    let lit = from_above.rgb * foliage;
    if from_above.g <= 0.0 || any(lit <= vec3<f32>(1e-6)) {
        return vec3<f32>(0.0);
    }
    return level_ground_light(light, u.sun_dir.xyz, 1.0) / lit;
}

// How much of a seed's foliage shows its mean colour seen from above rather than its own detail
// (`draw_seeds.prefilter_small`): all of it where the seed stands `SEED_DETAIL_NONE_PX` tall on
// screen or less, none from `SEED_DETAIL_FULL_PX`, and only for views from above (the follow-up's
// `PHOTO_DETAIL_*`), whose mean the photograph shows. A crown of a pixel or two shows one sample
// of its shading and gaps a pixel, which changes as the view moves by a fraction of a pixel; its
// mean is what a pixel over it would average (the truth supersamples to it).
fn small_seed_mean(record: SeedRecord, distance_m: f32, up: vec3<f32>) -> f32 {
    let tall_px = record.height_m * u.focal_px / max(distance_m, 1e-3);
    let down = -dot(record.position_rel_m, up) / max(length(record.position_rel_m), 1e-3);
    let from_above = smoothstep(PHOTO_DETAIL_GRAZING_SIN, PHOTO_DETAIL_STEEP_SIN, down);
    return (1.0 - smoothstep(SEED_DETAIL_NONE_PX, SEED_DETAIL_FULL_PX, tall_px)) * from_above;
}

// A fragment of a seed, before the alpha test: its colour lit and seen through the air, its alpha and how fast that
// alpha changes across the pixel.
struct Surface {
    colour: vec4<f32>,
    alpha: f32,
    alpha_per_px: f32,
}

// The fragment's material colour and alpha: its texel (if textured) times the base colour.
fn texel_of(in: VertexOut, material: SeedMaterial) -> vec4<f32> {
    // Derivatives in uniform control flow; the samplers differ only in wrapping (the mesh's
    // textures repeat, the atlases must not bleed across their edge).
    let dx = dpdx(in.uv);
    let dy = dpdy(in.uv);
    var texel = vec4<f32>(1.0);
    if (material.flags & MATERIAL_TEXTURED) != 0u {
        let layer = i32(material.layer);
        if (material.flags & MATERIAL_REPEAT) != 0u {
            texel = textureSampleGrad(textures, repeat_sampler, in.uv, layer, dx, dy);
        } else {
            texel = textureSampleGrad(textures, clamp_sampler, in.uv, layer, dx, dy);
        }
    }
    return texel * material.base_colour;
}

fn surface(in: VertexOut) -> Surface {
    let material = materials[in.material];
    let texel = texel_of(in, material);
    let albedo = texel.rgb * in.follow * in.tint * in.luminosity;
    // Seen from the side facing the eye (billboards, leaves); foliage lets light wrap around.
    var normal = normalize(in.normal);
    if dot(normal, in.rel_m) > 0.0 {
        normal = -normal;
    }
    let clouds = sun_through_clouds(u.cloud_field, u.cloud_shift, in.rel_m);
    let light = SunAndSky(in.sun_light, in.sky_light, in.air_up);
    let sun = u.sun_dir.xyz;
    let facing = FOLIAGE_SUN * max(dot(normal, sun), 0.0) + FOLIAGE_SUN_WRAP * max(dot(light.up, sun), 0.0);
    var lit = albedo * (light.sun * facing * clouds + light.sky * FOLIAGE_SKY);
    if in.far.w > 0.0 {
        // Its mean seen from above, lit as level ground (`photo_scale`'s yardstick).
        lit = mix(lit, in.far.rgb * level_ground_light(light, sun, clouds), in.far.w);
    }
    return Surface(vec4<f32>(through_air(lit, in.rel_m), 1.0), texel.a, fwidth(texel.a));
}

// Whether the cross-fade gives this pixel to the other of the seed's two draws, or the slicings'
// blend to the other slicing (a dither of its own: the pattern transposed, not to correlate
// with the cross-fade's).
fn faded_out(in: VertexOut) -> bool {
    let pixel = vec2<u32>(in.clip.xy);
    let t = bayer4(pixel, u32(in.keep.z));
    let b = bayer4(pixel.yx, u32(in.keep.z) ^ SLICE_DITHER_SALT);
    return t < in.keep.x || t >= in.keep.y || b < in.blend.x || b >= in.blend.y;
}

// The fragment's colour lit and seen through the air, or discarded (alpha test, dither).
fn shade(in: VertexOut) -> vec4<f32> {
    let s = surface(in);
    if cut_out(in, s.alpha) {
        discard;
    }
    return s.colour;
}

// Whether a fragment of alpha `alpha` is cut away: the alpha test, or a dither giving its pixel to
// another draw. One test for the draw and its depth prepass, which must keep the same fragments.
fn cut_out(in: VertexOut, alpha: f32) -> bool {
    return alpha < materials[in.material].alpha_cutoff || faded_out(in);
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    return shade(in);
}

// The depth prepass (`draw_seeds.depth_prepass`): every draw first writes only the depth of what
// it keeps (the alpha test and the dithers: one texture fetch, no lighting), with colour writes
// off; the draws are then repeated with the depth test `Equal` and no depth write, so only the
// fragment each pixel finally shows reaches the lighting, whatever the order the seeds come in.
// The colour returned is never written.
@fragment
fn fs_depth(in: VertexOut) -> @location(0) vec4<f32> {
    if cut_out(in, texel_of(in, materials[in.material]).a) {
        discard;
    }
    return vec4<f32>(0.0);
}

struct TruthOut {
    @location(0) colour: vec4<f32>,
    @location(1) seed: u32,
}

// The ground truth's draw (`truth`): every seed its full mesh, never faded (its uniforms reach
// everywhere), each fragment also writing its seed's id, the record index + 1 (0 is no seed).
@fragment
fn fs_truth(in: VertexOut) -> TruthOut {
    return TruthOut(shade(in), in.record + 1u);
}
