//! How it works: a partitioned build in three commands any scheduler can run. `plan` fixes
//! everything the jobs must agree on (the source, each layer's split, the land cover's palette;
//! for GeoTIFF inputs also the DEM's scan and the imagery's stretch, `build::parts`) in a TOML
//! file with a hash of all of it, and lists each partition's subtrees and input window.
//! `build --plan P --partition i` writes partition `i`'s part packs into a hidden folder beside
//! the others and puts it in place (`terramp::publish`) with a receipt (the plan's hash, time, peak
//! memory) only when complete: a killed job leaves nothing that counts, and a partition whose receipt carries
//! the plan's hash is skipped, so rerunning every job resumes a build. `merge --plan P --out D`
//! checks every receipt and assembles the dataset atomically (`terramp::synth::SynthParts`).

use std::fs;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result, bail, ensure};
use serde::{Deserialize, Serialize};
use terramp::dataset::lcc::{LCC_SOURCE_LEVEL, LccCoding};
use terramp::dataset::partition::Split;
use terramp::dataset::{ImageryFormat, PACK_VERSION};
use terramp::synth::{SynthParams, SynthParts};

use crate::build::InputArgs;
use crate::build::parts::{GeotiffParts, GeotiffSource};

/// The plan file's format; a job refuses a plan of another.
const PLAN_FORMAT: u32 = 1;
/// The receipt a finished partition's folder holds.
const RECEIPT_FILE: &str = "done.toml";

#[derive(Debug, clap::Args)]
#[command(group(clap::ArgGroup::new("what").required(true).args(["synth_size", "dem"])))]
pub struct PlanArgs {
    /// Plan the build of these GeoTIFF inputs (`build`'s arguments).
    #[command(flatten)]
    inputs: InputArgs,
    /// Plan the synthetic dataset of this many DEM samples per side (`synth --size`) instead.
    #[arg(long, conflicts_with = "dem")]
    synth_size: Option<u32>,
    /// The synthetic dataset's seed (`synth --seed`).
    #[arg(long, default_value_t = SynthParams::default().seed, requires = "synth_size")]
    seed: u64,
    /// How many jobs to cut the build into.
    #[arg(long)]
    partitions: u32,
    /// The plan file to write.
    #[arg(long)]
    out: PathBuf,
    /// How the merged dataset stores its imagery (`build --imagery-format`): the partitions write
    /// plain texels, which the merge turns into blocks once every level is made.
    #[arg(long, default_value = "rgba8", value_parser = crate::parse_imagery_format)]
    imagery_format: ImageryFormat,
    /// The folder the jobs write their parts into, shared by every node (default: beside the plan,
    /// `<plan>.parts`); relative paths are from the plan's folder.
    #[arg(long)]
    parts: Option<PathBuf>,
}

/// What is built.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
enum Source {
    /// `terramp-data synth`'s dataset.
    Synth { size: u32, seed: u64 },
    /// `terramp-data build`'s dataset from GeoTIFF inputs.
    Geotiff(Box<GeotiffSource>),
}

/// One layer's cut, for people and schedulers to read (the jobs recompute it and check).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct LayerPlan {
    name: String,
    /// The level of the subtrees' roots (0 = finest); the merge reduces the levels above.
    split_level: u32,
    /// Per partition: tiles written and the level-0 input window `[x0, y0, width, height]`.
    partitions: Vec<PartPlan>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct PartPlan {
    tiles: u64,
    window: Option<[u32; 4]>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Plan {
    format: u32,
    /// FNV-1a of the source, partitions, palette, pack format and builder version.
    hash: String,
    /// The builder that made the plan; jobs must run the same.
    builder: String,
    partitions: u32,
    parts: PathBuf,
    source: Source,
    /// The merged dataset's imagery format (short name); the parts do not depend on it, so it is
    /// not hashed.
    #[serde(default = "plain_imagery")]
    imagery_format: String,
    /// The land cover's palette (absent without land cover).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    coding: Option<LccCoding>,
    layers: Vec<LayerPlan>,
}

fn plain_imagery() -> String {
    ImageryFormat::Rgba8.short_name().to_owned()
}

/// A finished partition's receipt.
#[derive(Debug, Serialize, Deserialize)]
struct Receipt {
    hash: String,
    partition: u32,
    seconds: f64,
    peak_rss_mib: f64,
}

/// A plan's source, opened for its jobs and merge.
enum Parts {
    Synth(Box<SynthParts>),
    Geotiff(Box<GeotiffParts>),
}

impl Parts {
    /// Each layer's pack name, split and source level.
    fn splits(&self) -> Vec<(&'static str, Split, u32)> {
        match self {
            Parts::Synth(parts) => {
                let names = ["height", "imagery", "landcover"];
                names
                    .into_iter()
                    .zip(parts.splits)
                    .zip([0, 0, LCC_SOURCE_LEVEL])
                    .map(|((n, s), l)| (n, s, l))
                    .collect()
            }
            Parts::Geotiff(parts) => parts.splits.clone(),
        }
    }

    fn write_part(&self, dir: &Path, part: u32, progress: bool) -> Result<()> {
        match self {
            Parts::Synth(parts) => Ok(parts.write_part(dir, part, progress)?),
            Parts::Geotiff(parts) => parts.write_part(dir, part, progress),
        }
    }
}

impl Plan {
    fn hash_of(source: &Source, partitions: u32, coding: Option<&LccCoding>) -> Result<String> {
        /// Everything a job's output depends on.
        #[derive(Serialize)]
        struct Hashed<'a> {
            source: &'a Source,
            partitions: u32,
            coding: Option<&'a LccCoding>,
            pack_version: u32,
            builder: String,
        }
        let hashed = Hashed { source, partitions, coding, pack_version: PACK_VERSION, builder: builder() };
        let text = toml::to_string(&hashed)?;
        let hash = text
            .bytes()
            .fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3));
        Ok(format!("{hash:016x}"))
    }

    fn load(path: &Path) -> Result<Self> {
        let text =
            fs::read_to_string(path).with_context(|| format!("reading the plan {}", path.display()))?;
        let plan: Plan =
            toml::from_str(&text).with_context(|| format!("parsing the plan {}", path.display()))?;
        ensure!(
            plan.format == PLAN_FORMAT,
            "{}: plan format {}, this builder reads {PLAN_FORMAT}",
            path.display(),
            plan.format
        );
        ensure!(
            plan.builder == builder(),
            "{}: planned by {}, this is {}: every job must run the builder that planned",
            path.display(),
            plan.builder,
            builder()
        );
        let hash = Self::hash_of(&plan.source, plan.partitions, plan.coding.as_ref())?;
        ensure!(
            hash == plan.hash,
            "{}: the plan was edited after it was made (hash {hash}, recorded {})",
            path.display(),
            plan.hash
        );
        Ok(plan)
    }

    fn parts_dir(&self, plan_path: &Path) -> PathBuf {
        plan_path.parent().unwrap_or(Path::new(".")).join(&self.parts)
    }

    /// The source opened for jobs and merges; `plan_path` is where the plan lies.
    fn open(&self, plan_path: &Path) -> Result<Parts> {
        let imagery_format = crate::parse_imagery_format(&self.imagery_format).map_err(anyhow::Error::msg)?;
        Ok(match &self.source {
            &Source::Synth { size, seed } => {
                let params = SynthParams { size, seed, imagery_format, ..SynthParams::default() };
                let coding =
                    self.coding.clone().context("a synthetic plan without its land cover's coding")?;
                Parts::Synth(Box::new(SynthParts::new(&params, self.partitions, coding)?))
            }
            Source::Geotiff(source) => {
                let dir = plan_path.parent().unwrap_or(Path::new("."));
                Parts::Geotiff(Box::new(GeotiffParts::open(
                    source,
                    self.coding.clone(),
                    self.partitions,
                    dir,
                )?))
            }
        })
    }
}

fn builder() -> String {
    format!("terramp-data {}", env!("CARGO_PKG_VERSION"))
}

fn part_dir(parts: &Path, part: u32) -> PathBuf {
    parts.join(format!("part-{part:05}"))
}

/// The receipt of a finished partition of `plan`, if there is one.
fn receipt(plan: &Plan, parts: &Path, part: u32) -> Option<Receipt> {
    let text = fs::read_to_string(part_dir(parts, part).join(RECEIPT_FILE)).ok()?;
    toml::from_str::<Receipt>(&text).ok().filter(|r| r.hash == plan.hash && r.partition == part)
}

pub fn plan(args: &PlanArgs) -> Result<()> {
    ensure!(args.partitions >= 1, "--partitions must be at least 1");
    let stem = args.out.file_stem().map_or_else(|| "plan".into(), |s| s.to_string_lossy().into_owned());
    let (source, parts, coding) = match args.synth_size {
        Some(size) => {
            let params = SynthParams { size, seed: args.seed, ..SynthParams::default() };
            let parts = SynthParts::plan(&params, args.partitions, std::io::stderr().is_terminal())?;
            let coding = parts.coding.clone();
            (Source::Synth { size, seed: args.seed }, Parts::Synth(Box::new(parts)), Some(coding))
        }
        None => {
            // The void fill's coarse surface, beside the plan (recorded by its file name).
            let coarse = args.out.with_file_name(format!("{stem}.coarse.bin"));
            let (mut source, coding) = GeotiffSource::plan(&args.inputs, &coarse)?;
            if let Some(file) = &mut source.heights.coarse {
                file.path = coarse.file_name().map(PathBuf::from).unwrap_or_default();
            }
            let dir = args.out.parent().unwrap_or(Path::new("."));
            let parts = GeotiffParts::open(&source, coding.clone(), args.partitions, dir)?;
            (Source::Geotiff(Box::new(source)), Parts::Geotiff(Box::new(parts)), coding)
        }
    };
    let layers = parts
        .splits()
        .into_iter()
        .map(|(name, split, source_level)| LayerPlan {
            name: name.trim_end_matches(".pack").to_owned(),
            split_level: split.level,
            partitions: (0..split.partitions)
                .map(|p| PartPlan {
                    tiles: split.tiles(p).len() as u64,
                    window: split.input_window(p, source_level).map(|w| [w.x0, w.y0, w.width, w.height]),
                })
                .collect(),
        })
        .collect();
    let plan = Plan {
        format: PLAN_FORMAT,
        hash: Plan::hash_of(&source, args.partitions, coding.as_ref())?,
        builder: builder(),
        partitions: args.partitions,
        parts: args.parts.clone().unwrap_or_else(|| PathBuf::from(format!("{stem}.parts"))),
        source,
        imagery_format: args.imagery_format.short_name().to_owned(),
        coding,
        layers,
    };
    write_atomically(&args.out, toml::to_string_pretty(&plan)?.as_bytes())?;
    println!(
        "wrote {} ({} partitions, hash {}); parts go to {}",
        args.out.display(),
        plan.partitions,
        plan.hash,
        plan.parts_dir(&args.out).display()
    );
    Ok(())
}

/// `build --plan P --partition i`.
pub fn build_partition(plan_path: &Path, part: u32) -> Result<()> {
    let start = Instant::now();
    let plan = Plan::load(plan_path)?;
    ensure!(
        part < plan.partitions,
        "partition {part}: the plan has {} (0 to {})",
        plan.partitions,
        plan.partitions - 1
    );
    let parts = plan.parts_dir(plan_path);
    let n = plan.partitions;
    if receipt(&plan, &parts, part).is_some() {
        println!("partition {part}/{n}: already built for this plan, skipped");
        return Ok(());
    }
    let done = part_dir(&parts, part);
    // Sweeps what a killed earlier job for this partition left: only one runs per partition at a
    // time.
    let staging = terramp::publish::begin_staging(&done)
        .map_err(|(path, e)| anyhow::Error::new(e).context(format!("preparing {}", path.display())))?;
    plan.open(plan_path)?.write_part(&staging, part, std::io::stderr().is_terminal())?;
    let receipt = Receipt {
        hash: plan.hash.clone(),
        partition: part,
        seconds: start.elapsed().as_secs_f64(),
        peak_rss_mib: peak_rss_mib(),
    };
    fs::write(staging.join(RECEIPT_FILE), toml::to_string(&receipt)?)?;
    sync_folder(&staging)?;
    terramp::publish::publish(&staging, &done)
        .map_err(|(path, e)| anyhow::Error::new(e).context(format!("publishing {}", path.display())))?;
    println!(
        "partition {part}/{n}: built in {:.1} s, peak RSS {:.0} MiB, {:.1} MiB of parts",
        receipt.seconds,
        receipt.peak_rss_mib,
        folder_bytes(&done) as f64 / f64::from(1 << 20)
    );
    Ok(())
}

/// `merge --plan P --out D`.
pub fn merge(plan_path: &Path, out: &Path) -> Result<()> {
    let start = Instant::now();
    let plan = Plan::load(plan_path)?;
    let parts = plan.parts_dir(plan_path);
    let missing: Vec<u32> = (0..plan.partitions).filter(|&p| receipt(&plan, &parts, p).is_none()).collect();
    if !missing.is_empty() {
        let list: Vec<String> = missing.iter().map(u32::to_string).collect();
        bail!(
            "{} of {} partitions are not built for this plan: {} (run `terramp-data build --plan {} --partition N` for each)",
            missing.len(),
            plan.partitions,
            list.join(", "),
            plan_path.display()
        );
    }
    let dirs: Vec<PathBuf> = (0..plan.partitions).map(|p| part_dir(&parts, p)).collect();
    let progress = std::io::stderr().is_terminal();
    let dir = match plan.open(plan_path)? {
        Parts::Synth(parts) => parts.merge(&dirs, out, progress)?,
        Parts::Geotiff(parts) => {
            let imagery_format =
                crate::parse_imagery_format(&plan.imagery_format).map_err(anyhow::Error::msg)?;
            parts.merge(&dirs, out, imagery_format, progress)?
        }
    };
    println!(
        "merged {} partitions into {} in {:.1} s, peak RSS {:.0} MiB",
        plan.partitions,
        dir.display(),
        start.elapsed().as_secs_f64(),
        peak_rss_mib()
    );
    Ok(())
}

/// Writes `bytes` to `path` through a sibling temporary file and a rename.
pub(crate) fn write_atomically(path: &Path, bytes: &[u8]) -> Result<()> {
    let tmp = path.with_extension(format!("partial-{}", std::process::id()));
    fs::write(&tmp, bytes).with_context(|| format!("writing {}", tmp.display()))?;
    fs::File::open(&tmp).and_then(|f| f.sync_all())?;
    fs::rename(&tmp, path).with_context(|| format!("writing {}", path.display()))
}

/// Flushes every file of `dir` to disk, so the rename that publishes it publishes whole files.
fn sync_folder(dir: &Path) -> Result<()> {
    for entry in fs::read_dir(dir)?.flatten() {
        fs::File::open(entry.path())
            .and_then(|f| f.sync_all())
            .with_context(|| format!("syncing {}", entry.path().display()))?;
    }
    Ok(())
}

fn folder_bytes(dir: &Path) -> u64 {
    fs::read_dir(dir)
        .map(|d| d.flatten().filter_map(|e| e.metadata().ok()).map(|m| m.len()).sum())
        .unwrap_or(0)
}

/// The process's peak resident memory (Linux `VmHWM`), MiB.
fn peak_rss_mib() -> f64 {
    let status = fs::read_to_string("/proc/self/status").unwrap_or_default();
    let kib = status
        .lines()
        .find(|l| l.starts_with("VmHWM:"))
        .and_then(|l| l.split_whitespace().nth(1)?.parse::<f64>().ok());
    kib.unwrap_or(0.0) / 1024.0
}
