//! How it works: the synthetic dataset built as partitions (`crate::dataset::partition`). The plan
//! fixes what every job must agree on before any tile is written: each layer's split, and the land
//! cover's palette (one pass over the codes, which a job could not know from its part alone). A
//! job writes its part of each layer into a folder of part packs named like the dataset's; the
//! merge assembles them into the dataset `synthesize` writes from the same parameters, byte for
//! byte, through the same staging.

use std::path::{Path, PathBuf};

use indicatif::ProgressBar;

use super::layers::{HEIGHT_PACK, IMAGERY_PACK, LANDCOVER_PACK, Layers};
use super::{SynthError, SynthParams, commit, progress_bar};
use crate::dataset::lcc::{LccCoding, lcc_pyramid};
use crate::dataset::partition::{Split, merge_layer, merge_lcc, write_layer_part, write_lcc_part};
use crate::dataset::{Staging, Window};

/// A synthetic dataset cut into partitions.
pub struct SynthParts {
    layers: Layers,
    /// The land cover's coding, fixed for every job.
    pub coding: LccCoding,
    /// The heights', imagery's and land cover's splits.
    pub splits: [Split; 3],
}

impl SynthParts {
    /// Plans `params` for `partitions` jobs: the splits, and the palette from a pass over the codes.
    pub fn plan(params: &SynthParams, partitions: u32, progress: bool) -> Result<Self, SynthError> {
        let layers = Layers::new(params)?;
        let bar = progress_bar(progress, "classes");
        let coding = layers.coding(&bar)?;
        bar.finish();
        Ok(Self::with_coding(layers, partitions, coding))
    }

    /// The plan of `params` for `partitions` jobs whose palette is already known (`coding`).
    pub fn new(params: &SynthParams, partitions: u32, coding: LccCoding) -> Result<Self, SynthError> {
        Ok(Self::with_coding(Layers::new(params)?, partitions, coding))
    }

    fn with_coding(layers: Layers, partitions: u32, coding: LccCoding) -> Self {
        let splits = [
            Split::new(layers.height.pyramid, partitions, size_of::<f32>() as u64, 0),
            Split::new(layers.imagery.pyramid, partitions, size_of::<[u8; 4]>() as u64, 0),
            Split::new(lcc_pyramid(layers.class_texels), partitions, coding.word_bytes() as u64, 1),
        ];
        Self { layers, coding, splits }
    }

    /// Writes partition `part`'s part packs into the folder `dir` (which must exist).
    pub fn write_part(&self, dir: &Path, part: u32, progress: bool) -> Result<(), SynthError> {
        let [height, imagery, landcover] = &self.splits;
        let layers = &self.layers;
        let bar = progress_bar(progress, "height");
        write_layer_part(&dir.join(HEIGHT_PACK), &layers.height, height, part, |w| layers.heights(w), &bar)?;
        let bar = progress_bar(progress, "imagery");
        write_layer_part(&dir.join(IMAGERY_PACK), &layers.imagery, imagery, part, |w| layers.paint(w), &bar)?;
        let bar = progress_bar(progress, "landcover");
        let classify = |w: Window| layers.classify(w);
        let path = dir.join(LANDCOVER_PACK);
        write_lcc_part(&path, layers.class_texels, &self.coding, landcover, part, classify, &bar)?;
        bar.finish();
        Ok(())
    }

    /// Merges the part folders `parts` (partition 0 first) into the dataset at `out`, atomically.
    pub fn merge(&self, parts: &[PathBuf], out: &Path, progress: bool) -> Result<PathBuf, SynthError> {
        let [height, imagery, landcover] = &self.splits;
        let layers = &self.layers;
        let staging = Staging::begin(out)?;
        let packs = |name: &str| parts.iter().map(|dir| dir.join(name)).collect::<Vec<_>>();
        let bar: ProgressBar = progress_bar(progress, "height");
        merge_layer::<f32>(&staging.path(HEIGHT_PACK), &layers.height, height, &packs(HEIGHT_PACK), &bar)?;
        let bar = progress_bar(progress, "imagery");
        merge_layer::<[u8; 4]>(
            &staging.path(IMAGERY_PACK),
            &layers.imagery,
            imagery,
            &packs(IMAGERY_PACK),
            &bar,
        )?;
        let bar = progress_bar(progress, "landcover");
        let path = staging.path(LANDCOVER_PACK);
        merge_lcc(&path, layers.class_texels, &self.coding, landcover, &packs(LANDCOVER_PACK), &bar)?;
        bar.finish();
        let range = layers.height_range(&staging.path(HEIGHT_PACK))?;
        let manifest = layers.manifest(range, self.coding.clone())?;
        commit(staging, manifest, layers.params().imagery_format, progress)
    }
}
