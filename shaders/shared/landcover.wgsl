// Reading the land cover through its cache (the LCC quadtree, `dataset::lcc`): every pass that
// reads it declares `lcc_page_table` and `lcc_tiles` and passes its page-table levels.

// Palette index of level-1 land-cover texel `q`, read from `wanted` or, while that streams in,
// another resident level (they all decode to the same class), and the level it came from;
// NO_CLASS when none is resident. `page_levels`: each level's first page-table entry and tiles
// along x and y; `sub_bits`: bits per level-2 sub-code.
fn landcover_class(q: vec2<u32>, wanted: u32, page_levels: array<vec4<u32>, 4>, sub_bits: u32) -> vec2<u32> {
    var levels = page_levels;
    for (var n = 0u; n < LCC_LEVELS; n += 1u) {
        let level = (wanted + n) % LCC_LEVELS;
        var texel = q << vec2<u32>(1u);
        if level == LCC_SOURCE_LEVEL {
            texel = q;
        } else if level == LCC_PACKED_LEVEL {
            texel = q >> vec2<u32>(1u);
        }
        let info = levels[level];
        let tile = min(texel / LCC_TILE_TEXELS, info.yz - 1u);
        let slot = lcc_page_table[info.x + tile.y * info.y + tile.x];
        if slot != PAGE_EMPTY {
            let word = textureLoad(lcc_tiles, vec2<i32>(texel - tile * LCC_TILE_TEXELS), page_layer(slot), 0).x;
            if level != LCC_PACKED_LEVEL {
                return vec2<u32>(word, level);
            }
            let shift = sub_bits * ((q.x & 1u) + 2u * (q.y & 1u));
            return vec2<u32>((word >> shift) & ((1u << sub_bits) - 1u), level);
        }
    }
    return vec2<u32>(NO_CLASS, 0u);
}
