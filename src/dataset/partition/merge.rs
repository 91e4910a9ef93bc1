//! How it works: the merge writes a layer's pack as `write_layer` (or `write_lcc_layer`) would,
//! level by level in the same order, but takes the tiles at and below the split level from the
//! part packs instead of making them: each tile's stored bytes are copied as they are (checked
//! against their checksum, never decoded), so the places, the index and the file come out the same,
//! byte for byte. A copied tile's range is completed as `write_layer` completes it, with the ranges
//! of the tiles one level down that it was reduced from, already merged. The levels above the
//! split are then reduced from the merged tiles by `write_layer`'s own code.

use std::path::{Path, PathBuf};

use indicatif::ProgressBar;

use super::{PartSlots, Split};
use crate::dataset::layer_writer::{level_ids, range_below, union, write_reduced_level};
use crate::dataset::lcc::{LccCoding, LccTiles, lcc_pyramid};
use crate::dataset::pack::{Pack, PackWriter};
use crate::dataset::{LayerError, LayerSpec, Pyramid, Texel, TileId, Window};

/// The part packs of one layer, each with the slots of the tiles it holds.
struct Parts {
    packs: Vec<(Pack, PartSlots)>,
}

impl Parts {
    /// Opens `paths` (one per partition, in order) and checks each holds its partition's tiles as
    /// `tile_bytes`-byte payloads stored like `codec`'s.
    fn open(
        pyramid: &Pyramid,
        split: &Split,
        paths: &[PathBuf],
        tile_bytes: u64,
    ) -> Result<Self, LayerError> {
        if paths.len() != split.partitions as usize {
            return Err(LayerError::Parts {
                path: paths.first().cloned().unwrap_or_default(),
                message: format!("{} part packs for {} partitions", paths.len(), split.partitions),
            });
        }
        let mut packs = Vec::with_capacity(paths.len());
        for (part, path) in paths.iter().enumerate() {
            let pack = Pack::open(path)?;
            let slots = PartSlots::new(pyramid, &split.tiles(part as u32));
            if pack.tile_count() != slots.len() || pack.tile_bytes() != tile_bytes {
                return Err(LayerError::Parts {
                    path: path.clone(),
                    message: format!(
                        "holds {} tiles of {} bytes; partition {part} of this plan has {} of {tile_bytes}",
                        pack.tile_count(),
                        pack.tile_bytes(),
                        slots.len()
                    ),
                });
            }
            packs.push((pack, slots));
        }
        Ok(Self { packs })
    }

    /// Copies every tile of `level` (at or below the split) into `writer`, in global order; `range`
    /// turns a tile's own range into the one the dataset records.
    fn copy_level(
        &self,
        pyramid: &Pyramid,
        split: &Split,
        writer: &PackWriter,
        level: u32,
        range: impl Fn(TileId, Option<[f32; 2]>) -> Result<Option<[f32; 2]>, LayerError>,
        progress: &ProgressBar,
    ) -> Result<(), LayerError> {
        for id in level_ids(pyramid, level) {
            let global = pyramid.tile_index(id).unwrap_or(u64::MAX);
            let (pack, slots) = &self.packs[split.part_of(id) as usize];
            let slot = slots.slot(global).ok_or_else(|| LayerError::Parts {
                path: pack.path().to_owned(),
                message: format!("does not hold tile {id:?}"),
            })?;
            // Read, not mapped: the merge copies whole packs and must not hold them resident.
            let stored = pack.read_stored(slot)?;
            writer.place_stored(global, &stored, range(id, pack.tile_range(slot)?)?)?;
            progress.inc(1);
        }
        Ok(())
    }
}

/// Merges the part packs `parts` (partition 0 first) of `spec`'s layer, cut by `split`, into the
/// pack at `path`: the pack `write_layer` writes from the same source.
pub fn merge_layer<T: Texel>(
    path: &Path,
    spec: &LayerSpec,
    split: &Split,
    parts: &[PathBuf],
    progress: &ProgressBar,
) -> Result<(), LayerError> {
    let pyramid = &spec.pyramid;
    let parts = Parts::open(pyramid, split, parts, spec.tile_bytes::<T>())?;
    let writer = PackWriter::create(path, spec.tile_bytes::<T>(), pyramid.tile_count(), T::codec())?;
    progress.set_length(pyramid.tile_count());
    for level in 0..pyramid.levels {
        if level > split.level {
            write_reduced_level::<T>(spec, &writer, level, progress)?;
            continue;
        }
        let range = |id: TileId, own: Option<[f32; 2]>| -> Result<_, LayerError> {
            Ok(if level == 0 { own } else { union(own, range_below(pyramid, &writer, id)?) })
        };
        parts.copy_level(pyramid, split, &writer, level, range, progress)?;
    }
    writer.finish()?;
    Ok(())
}

/// Merges the part packs of a land-cover layer (`write_lcc_layer`'s `source_size` and `coding`)
/// into the pack at `path`: the pack `write_lcc_layer` writes from the same source.
pub fn merge_lcc(
    path: &Path,
    source_size: [u32; 2],
    coding: &LccCoding,
    split: &Split,
    parts: &[PathBuf],
    progress: &ProgressBar,
) -> Result<(), LayerError> {
    let tiles = LccTiles::new(source_size, coding)?;
    let pyramid = lcc_pyramid(source_size);
    let parts = Parts::open(&pyramid, split, parts, tiles.tile_bytes())?;
    let writer = tiles.create(path, pyramid.tile_count())?;
    progress.set_length(pyramid.tile_count());
    for level in LccTiles::LEVEL_ORDER {
        if level <= split.level {
            parts.copy_level(&pyramid, split, &writer, level, |_, own| Ok(own), progress)?;
        } else {
            // Level 2 packs the merged level 1; only level 1 reads the source, and it is copied.
            let no_source = |_: Window| Err("the merge reads no source".to_owned());
            let ids = level_ids(&pyramid, level);
            tiles.write_level(&writer, level, ids, |id| pyramid.tile_index(id), &no_source, progress)?;
        }
    }
    writer.finish()?;
    Ok(())
}
