//! How it works: an imagery pack stores its tiles in one of three texel formats, named by the
//! manifest's `format`: plain RGBA8 sRGB, or block-compressed BC1 (the paper's DXT1: 8 bytes per
//! 4 × 4 block, colour only) or BC7 (16 bytes per block, colour and coverage). A tile's payload is
//! its mips one after another, each in whole blocks, south row of blocks first, laid out exactly as
//! a GPU copies the mip into a texture: a mip whose edge is not a multiple of 4 (mip 3 is 66
//! texels) has its last column and row of blocks padded, as the GPU's own mip is (its "physical"
//! size), so one `write_texture` per mip uploads it unchanged.
//!
//! The GPU samples the blocks itself where the adapter can (`TEXTURE_COMPRESSION_BC`); elsewhere,
//! and for every reader on the CPU (twins, the ground truth), `decode_tile` turns a payload back
//! into RGBA8, block by block, with `bcdec_rs` (decoders written to the format's specification;
//! BC7 decoding is exact by its specification, so GPU and CPU agree texel for texel).

use super::pyramid::Pyramid;

/// How an imagery pack stores its texels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ImageryFormat {
    /// 4 bytes per texel, RGBA8 sRGB, alpha the source's coverage.
    Rgba8,
    /// BC1 (DXT1), sRGB: 0.5 bytes per texel; coverage is 1 bit (punch-through: a texel without
    /// data is transparent black).
    Bc1,
    /// BC7, sRGB, coverage kept in alpha: 1 byte per texel.
    Bc7,
}

/// How one mip of a tile lies in its payload and in a texture: whole blocks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct MipLayout {
    /// Block columns (texels for an uncompressed format).
    pub blocks_x: u32,
    /// Block rows.
    pub blocks_y: u32,
    /// Bytes of one row of blocks.
    pub bytes_per_row: u32,
    /// The extent the copy covers, texels: the mip's edge rounded up to whole blocks.
    pub copy_extent: u32,
}

impl MipLayout {
    /// The layout of a square mip of `extent` texels of `format`.
    pub fn of(format: wgpu::TextureFormat, extent: u32) -> Self {
        let (block_w, block_h) = format.block_dimensions();
        let block_bytes = format.block_copy_size(None).unwrap_or(4);
        let (blocks_x, blocks_y) = (extent.div_ceil(block_w), extent.div_ceil(block_h));
        Self { blocks_x, blocks_y, bytes_per_row: blocks_x * block_bytes, copy_extent: blocks_x * block_w }
    }

    /// Bytes of the whole mip.
    pub fn bytes(&self) -> usize {
        self.bytes_per_row as usize * self.blocks_y as usize
    }
}

impl ImageryFormat {
    /// Every format, the default (`Rgba8`) first.
    pub const ALL: [Self; 3] = [Self::Rgba8, Self::Bc1, Self::Bc7];

    /// The format's name in a manifest's `format` (and on command lines, its first word).
    pub fn name(self) -> &'static str {
        match self {
            Self::Rgba8 => "rgba8 srgb",
            Self::Bc1 => "bc1 srgb",
            Self::Bc7 => "bc7 srgb",
        }
    }

    /// The format a manifest's `format` names; `None` for one this build does not know.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The short name a command line takes: `rgba8`, `bc1`, `bc7`.
    pub fn short_name(self) -> &'static str {
        self.name().split(' ').next().unwrap_or_default()
    }

    /// Whether a texel without data is transparent black (BC1's punch-through: a filtered colour
    /// is then the covered texels' colour times their coverage), rather than a colour with alpha 0.
    pub fn holes_are_transparent(self) -> bool {
        self == Self::Bc1
    }

    /// Whether the texels are stored in 4 × 4 blocks.
    pub fn is_block_compressed(self) -> bool {
        self != Self::Rgba8
    }

    /// The texture format that samples the stored payload as it is.
    pub fn texture_format(self) -> wgpu::TextureFormat {
        match self {
            Self::Rgba8 => wgpu::TextureFormat::Rgba8UnormSrgb,
            Self::Bc1 => wgpu::TextureFormat::Bc1RgbaUnormSrgb,
            Self::Bc7 => wgpu::TextureFormat::Bc7RgbaUnormSrgb,
        }
    }

    /// The layout of mip `mip` of a tile of `pyramid`.
    pub fn mip_layout(self, pyramid: &Pyramid, mip: u32) -> MipLayout {
        MipLayout::of(self.texture_format(), pyramid.mip_extent(mip))
    }

    /// Payload bytes of one tile with `mips` mips: the pack's tile size.
    pub fn tile_bytes(self, pyramid: &Pyramid, mips: u32) -> u64 {
        (0..mips).map(|mip| self.mip_layout(pyramid, mip).bytes() as u64).sum()
    }

    /// A tile's payload as RGBA8 texels, every mip `mip_extent(m)`² texels, south row first: the
    /// payload itself for `Rgba8`, decoded block by block otherwise (padding dropped). `payload`
    /// must be `tile_bytes(pyramid, mips)` long, as a pack's tiles are.
    pub fn decode_tile(self, pyramid: &Pyramid, mips: u32, payload: &[u8]) -> Vec<u8> {
        if self == Self::Rgba8 {
            return payload.to_vec();
        }
        let decode_block: fn(&[u8], &mut [u8], usize) = match self {
            Self::Bc1 => bcdec_rs::bc1,
            _ => bcdec_rs::bc7,
        };
        let block_bytes = self.texture_format().block_copy_size(None).unwrap_or(16) as usize;
        let mut texels =
            Vec::with_capacity((0..mips).map(|m| pyramid.mip_extent(m).pow(2) as usize * 4).sum());
        let mut offset = 0;
        for mip in 0..mips {
            let (layout, extent) = (self.mip_layout(pyramid, mip), pyramid.mip_extent(mip) as usize);
            // The padded mip decoded whole, then cropped to the mip's own texels.
            let pitch = layout.copy_extent as usize * 4;
            let mut padded = vec![0u8; pitch * layout.copy_extent as usize];
            for (k, block) in payload[offset..offset + layout.bytes()].chunks_exact(block_bytes).enumerate() {
                let (bx, by) = (k % layout.blocks_x as usize, k / layout.blocks_x as usize);
                decode_block(block, &mut padded[by * 4 * pitch + bx * 16..], pitch);
            }
            for row in padded.chunks_exact(pitch).take(extent) {
                texels.extend_from_slice(&row[..extent * 4]);
            }
            offset += layout.bytes();
        }
        texels
    }
}

impl std::fmt::Display for ImageryFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.short_name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dataset::LayerSpec;

    #[test]
    fn tile_sizes_follow_blocks_with_the_odd_mip_padded() {
        let spec = LayerSpec::imagery([1024, 1024]);
        let extents: Vec<u32> = (0..spec.mips).map(|m| spec.pyramid.mip_extent(m)).collect();
        assert_eq!(extents, [528, 264, 132, 66]);
        let texels: u64 = extents.iter().map(|&e| u64::from(e * e)).sum();
        assert_eq!(ImageryFormat::Rgba8.tile_bytes(&spec.pyramid, spec.mips), texels * 4);
        // 66 texels take 17 blocks (68 texels) a side.
        let blocks: u64 = [132u64, 66, 33, 17].iter().map(|b| b * b).sum();
        assert_eq!(ImageryFormat::Bc1.tile_bytes(&spec.pyramid, spec.mips), blocks * 8);
        assert_eq!(ImageryFormat::Bc7.tile_bytes(&spec.pyramid, spec.mips), blocks * 16);
        let odd = ImageryFormat::Bc7.mip_layout(&spec.pyramid, 3);
        assert_eq!((odd.blocks_x, odd.copy_extent, odd.bytes_per_row), (17, 68, 17 * 16));
        let plain = ImageryFormat::Rgba8.mip_layout(&spec.pyramid, 3);
        assert_eq!((plain.blocks_x, plain.copy_extent, plain.bytes_per_row), (66, 66, 66 * 4));
    }

    #[test]
    fn names_round_trip_and_unknown_names_are_none() {
        for format in ImageryFormat::ALL {
            assert_eq!(ImageryFormat::from_name(format.name()), Some(format));
        }
        assert_eq!(ImageryFormat::Bc7.short_name(), "bc7");
        assert_eq!(ImageryFormat::from_name("bc3 srgb"), None);
    }

    #[test]
    fn a_solid_bc1_block_decodes_to_its_colour_in_every_texel_of_every_mip() {
        let spec = LayerSpec::imagery([512, 512]);
        let bytes = ImageryFormat::Bc1.tile_bytes(&spec.pyramid, spec.mips) as usize;
        // Endpoints both pure red (565: 0xF800), every index 0.
        let block = [0x00, 0xF8, 0x00, 0xF8, 0, 0, 0, 0];
        let payload: Vec<u8> = block.iter().copied().cycle().take(bytes).collect();
        let texels = ImageryFormat::Bc1.decode_tile(&spec.pyramid, spec.mips, &payload);
        assert_eq!(texels.len(), spec.tile_texels() * 4);
        assert!(texels.chunks_exact(4).all(|t| t == [255, 0, 0, 255]));
    }
}
