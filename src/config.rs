//! How it works: settings are layers of TOML merged in order: `config/default.toml` (every knob,
//! documented; compiled in, so it is the one place defaults live), a named preset
//! (`config/presets/*.toml`), then an optional user file. Each layer is checked against the default
//! table before merging, so a misspelt key is reported with its full name and the file it came
//! from; the merged table is then deserialised and range-checked, naming the key again.
//!
//! These are user settings. The uniforms a shader reads are separate types built from them.

use std::path::Path;

use serde::Deserialize;
use thiserror::Error;
use toml::{Table, Value};

use crate::gpu::AdapterChoice;

mod atmosphere;
mod clouds;
mod display;
mod draw_seeds;
mod faults;
pub mod knobs;
mod seeds;
mod texcells;
pub mod time;
mod tlm;
mod wind;

pub use atmosphere::AtmosphereSettings;
pub use clouds::CloudSettings;
pub use display::{DisplaySettings, EV100_RANGE, ToneCurve};
pub use draw_seeds::DrawSeedsSettings;
pub use faults::FaultSettings;
pub use seeds::{OcclusionTolerance, SeedSettings};
pub use texcells::TexcellSettings;
pub use tlm::TlmSettings;
pub use wind::{MAX_WIND_M_S, WindSettings};

const DEFAULTS: &str = include_str!("../config/default.toml");
/// The named presets (`--preset`) and their TOML text, compiled in from `config/presets/`; each is
/// a layer over the defaults.
pub const PRESETS: &[(&str, &str)] = &[
    ("fast", include_str!("../config/presets/fast.toml")),
    ("balanced", include_str!("../config/presets/balanced.toml")),
    ("accurate", include_str!("../config/presets/accurate.toml")),
];

/// Why the settings could not be loaded; each names the file (or preset) and the full key at fault.
#[derive(Debug, Error)]
pub enum SettingsError {
    /// The preset asked for is not one of `PRESETS`.
    #[error("unknown preset `{0}`: expected fast, balanced or accurate")]
    UnknownPreset(String),
    /// The user's settings file could not be read.
    #[error("{origin}: {source}")]
    Read {
        /// The file's path, as given.
        origin: String,
        /// The I/O error from reading the file.
        source: std::io::Error,
    },
    /// A layer is not valid TOML.
    #[error("{origin}: not valid TOML: {message}")]
    Syntax {
        /// The layer: a file's path, `preset NAME` or `config/default.toml`.
        origin: String,
        /// The TOML parser's message (line, column and what it expected).
        message: String,
    },
    /// A layer sets a key that `config/default.toml` does not have (a misspelling, usually).
    #[error("{origin}: unknown key `{key}`")]
    UnknownKey {
        /// The layer that sets the key, as in `Syntax`.
        origin: String,
        /// The full dotted key, e.g. `render.fovv`.
        key: String,
    },
    /// A layer sets a key of an earlier release; the error says which key replaced it.
    #[error("{origin}: `{key}` is gone: {instead}")]
    Moved {
        /// The layer that sets the key, as in `Syntax`.
        origin: String,
        /// The full dotted key of the earlier release, e.g. `tlm.radial_lod_m`.
        key: String,
        /// Where the knob went, naming its replacement key(s).
        instead: &'static str,
    },
    /// A layer gives a key a value of another kind than its default (a string for a number, a
    /// value for a table); an integer where a number is expected is accepted.
    #[error("{origin}: `{key}` must be {expected}")]
    WrongType {
        /// The layer that sets the key, as in `Syntax`.
        origin: String,
        /// The full dotted key.
        key: String,
        /// The kind the default has, in words ("an integer", "a table").
        expected: &'static str,
    },
    /// The merged settings hold a value outside its range (checked after every layer is merged).
    #[error("settings: `{key}` = {value}: {rule}")]
    OutOfRange {
        /// The full dotted key, e.g. `render.fov_deg`.
        key: &'static str,
        /// The offending value, as text.
        value: String,
        /// The range the key must lie in, in words.
        rule: &'static str,
    },
    /// The merged table does not deserialise into `Settings` (e.g. an unknown `gpu.adapter` name).
    #[error("settings: {0}")]
    Shape(String),
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
/// Every user setting: `config/default.toml`, then a preset, then the user's file, merged and
/// range-checked. One field per table of that file.
pub struct Settings {
    /// `[gpu]`: the adapter and how passes are timed.
    pub gpu: GpuSettings,
    /// `[render]`: output size, projection, sun.
    pub render: RenderSettings,
    /// `[terrain]`: the LOD rings of the terrain mesh.
    pub terrain: TerrainSettings,
    /// `[imagery]`: level choice and filtering of the aerial imagery.
    pub imagery: ImagerySettings,
    /// `[cache]`: GPU tile slots, loader threads and upload budgets (pass 2).
    pub cache: CacheSettings,
    /// `[tlm]`: the Tile Load Map (pass 1).
    pub tlm: TlmSettings,
    /// `[seeds]`: seed selection (pass 3).
    pub seeds: SeedSettings,
    /// `[draw_seeds]`: the draw LODs' reaches, their cross-fade and the impostors (pass 4).
    pub draw_seeds: DrawSeedsSettings,
    /// `[texcells]`: the far forest, beyond the last seed band.
    pub texcells: TexcellSettings,
    /// `[wind]`: how the plants sway.
    pub wind: WindSettings,
    /// `[clouds]`: the shadows of clouds drifting over the land.
    pub clouds: CloudSettings,
    /// `[atmosphere]`: the air the sky is drawn from.
    pub atmosphere: AtmosphereSettings,
    /// `[display]`: the exposure and the tone curve the frame is shown through.
    pub display: DisplaySettings,
    /// `[faults]`: faults injected into tile streaming (tests and soak runs; none by default).
    pub faults: FaultSettings,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
/// The `[gpu]` table, see `config/default.toml`.
pub struct GpuSettings {
    /// Which adapter to run on: auto, hardware or software; `TERRAMP_ADAPTER` overrides it.
    pub adapter: AdapterChoice,
    /// Time passes with GPU timestamp queries where the adapter has them; false times them on the
    /// CPU (submit and wait), which serialises the frame.
    pub timestamps: bool,
    /// Count the foliage passes' fragments shaded and pixels covered, every frame (`profile`'s
    /// overdraw); reads each frame back, which serialises the frames.
    pub count_fragments: bool,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
/// The `[render]` table, see `config/default.toml`.
pub struct RenderSettings {
    /// Output width, pixels (1 to 16384).
    pub width: u32,
    /// Output height, pixels (1 to 16384).
    pub height: u32,
    /// Vertical field of view, degrees (0 < fov < 180).
    pub fov_deg: f64,
    /// Near plane, metres; depth is reversed-Z with an infinite far plane, so small costs nothing.
    pub near_m: f64,
    /// Compass azimuth the sun shines from, degrees clockwise from north.
    pub sun_azimuth_deg: f64,
    /// Sun elevation above the horizon, degrees (-90 to 90).
    pub sun_elevation_deg: f64,
    /// The instant the sun is placed for, RFC 3339 (`2026-06-21T17:30Z`), over the place under
    /// the camera (`sun`); empty: the two angles above place it.
    pub sun_time: String,
    /// Draw the dataset on the Earth's ellipsoid where its manifest says where it lies; false
    /// draws its grid as a flat sheet.
    pub curved_earth: bool,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
/// The `[terrain]` table, see `config/default.toml`.
pub struct TerrainSettings {
    /// Grid cells per side of one terrain node (a power of two from 8 to 256).
    pub node_cells: u32,
    /// Target on-screen length of a triangle edge at the far end of each LOD ring, pixels.
    pub triangle_px: f64,
    /// Fraction of each LOD ring over which vertices morph into the next coarser grid (0 < f < 1).
    pub morph_fraction: f64,
    /// Cull the nodes the Earth hides behind the horizon (on the Earth only).
    pub horizon_culling: bool,
    /// The most a node's mapping onto the Earth may misplace its ground, pixels (> 0; `inf`
    /// splits no node for it).
    pub placing_miss_px: f64,
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
/// The `[imagery]` table, see `config/default.toml`.
pub struct ImagerySettings {
    /// Imagery level bias, log2 of texels per pixel: -1 one level finer, +1 one coarser.
    pub lod_bias: f64,
    /// Anisotropic filtering, 1 (off) to 16, or 0 for automatic (see `anisotropy_on`).
    pub anisotropy: u16,
    /// How block-compressed imagery is held in the cache (see `decode_blocks_on`).
    pub blocks: ImageryBlocks,
}

/// How block-compressed imagery (BC1, BC7) is held in the imagery cache.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ImageryBlocks {
    /// Sampled as stored on a hardware GPU, decoded on load on a software rasteriser.
    Auto,
    /// Sampled as stored (where the adapter can).
    Sample,
    /// Decoded to RGBA8 as each tile loads.
    Decode,
}

impl ImagerySettings {
    /// The anisotropy to use on an adapter (`software`: a CPU rasteriser), resolving 0 = automatic.
    pub fn anisotropy_on(&self, software: bool) -> u16 {
        match (self.anisotropy, software) {
            (0, true) => 1,
            (0, false) => 8,
            (n, _) => n,
        }
    }

    /// Whether block-compressed imagery is decoded on load on an adapter (`software`: a CPU
    /// rasteriser, which decodes blocks at every fetch), resolving `Auto`.
    pub fn decode_blocks_on(&self, software: bool) -> bool {
        match self.blocks {
            ImageryBlocks::Auto => software,
            ImageryBlocks::Sample => false,
            ImageryBlocks::Decode => true,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
/// The `[cache]` table (pass 2's texture caches), see `config/default.toml`. The slot counts fix
/// the caches' GPU memory; each cache needs at least 16 (its coarse levels are pinned).
pub struct CacheSettings {
    /// Height tile slots on the GPU (259² × 4 bytes, 262 KiB each).
    pub height_slots: u32,
    /// Imagery tile slots on the GPU (528² × 4 bytes with mips, 1.41 MiB each; a quarter of that
    /// in BC7 blocks, an eighth in BC1).
    pub imagery_slots: u32,
    /// Land-cover tile slots on the GPU (512² bytes, 256 KiB each), read by seeds near the camera.
    pub landcover_slots: u32,
    /// Threads reading tiles from the packs off the render thread (1 to 64).
    pub loader_threads: u32,
    /// Most tiles each cache uploads in one frame, most important first (at least 1).
    pub upload_tiles_per_frame: u32,
    /// Most bytes each cache uploads in one frame (at least 1 MiB); one tile always goes.
    pub upload_bytes_per_frame: u64,
}

impl Default for Settings {
    fn default() -> Self {
        // The compiled-in defaults are checked by a test; failing here is a build defect.
        Self::from_layers(&[]).expect("config/default.toml is valid")
    }
}

impl Settings {
    /// A named preset over the defaults.
    pub fn preset(name: &str) -> Result<Self, SettingsError> {
        Self::load(name, None)
    }

    /// The defaults, then the preset `preset`, then the user's file if any.
    pub fn load(preset: &str, user_file: Option<&Path>) -> Result<Self, SettingsError> {
        let (_, preset_text) = PRESETS
            .iter()
            .find(|(name, _)| *name == preset)
            .ok_or_else(|| SettingsError::UnknownPreset(preset.to_owned()))?;
        let user = user_file
            .map(|path| {
                let origin = path.display().to_string();
                std::fs::read_to_string(path)
                    .map(|text| (origin.clone(), text))
                    .map_err(|source| SettingsError::Read { origin, source })
            })
            .transpose()?;
        let mut layers = vec![(format!("preset {preset}"), preset_text.to_string())];
        layers.extend(user);
        Self::from_layers(&layers)
    }

    /// The defaults overlaid with `(origin, toml text)` layers, in order.
    pub fn from_layers(layers: &[(String, String)]) -> Result<Self, SettingsError> {
        let mut merged = parse("config/default.toml", DEFAULTS)?;
        let defaults = merged.clone();
        for (origin, text) in layers {
            let layer = parse(origin, text)?;
            check_keys(origin, &layer, &defaults, "")?;
            overlay(&mut merged, layer);
        }
        let settings =
            Settings::deserialize(Value::Table(merged)).map_err(|e| SettingsError::Shape(e.to_string()))?;
        settings.validate()?;
        Ok(settings)
    }

    /// Range-checks every value, naming the first key out of range (as loading does; for
    /// settings changed after loading, such as a turned knob).
    pub fn validate(&self) -> Result<(), SettingsError> {
        let r = &self.render;
        let t = &self.terrain;
        let c = &self.cache;
        let checks: [RangeCheck; 14] = [
            (r.width >= 1 && r.width <= 16384, "render.width", r.width.to_string(), "1 to 16384 pixels"),
            (r.height >= 1 && r.height <= 16384, "render.height", r.height.to_string(), "1 to 16384 pixels"),
            (
                r.fov_deg > 0.0 && r.fov_deg < 180.0,
                "render.fov_deg",
                r.fov_deg.to_string(),
                "between 0 and 180",
            ),
            (r.near_m > 0.0, "render.near_m", r.near_m.to_string(), "must be positive"),
            (
                (-90.0..=90.0).contains(&r.sun_elevation_deg),
                "render.sun_elevation_deg",
                r.sun_elevation_deg.to_string(),
                "-90 to 90",
            ),
            (
                t.node_cells.is_power_of_two() && (8..=256).contains(&t.node_cells),
                "terrain.node_cells",
                t.node_cells.to_string(),
                "a power of two from 8 to 256",
            ),
            (t.triangle_px > 0.0, "terrain.triangle_px", t.triangle_px.to_string(), "must be positive"),
            (
                t.placing_miss_px > 0.0,
                "terrain.placing_miss_px",
                t.placing_miss_px.to_string(),
                "must be positive",
            ),
            (
                t.morph_fraction > 0.0 && t.morph_fraction < 1.0,
                "terrain.morph_fraction",
                t.morph_fraction.to_string(),
                "between 0 and 1",
            ),
            (
                self.imagery.anisotropy <= 16,
                "imagery.anisotropy",
                self.imagery.anisotropy.to_string(),
                "0 (automatic) or 1 to 16",
            ),
            (
                self.cache.height_slots >= 16
                    && self.cache.imagery_slots >= 16
                    && self.cache.landcover_slots >= 16,
                "cache",
                format!("{:?}", self.cache),
                "at least 16 slots per cache (the coarse levels are pinned)",
            ),
            (
                (1..=64).contains(&c.loader_threads),
                "cache.loader_threads",
                c.loader_threads.to_string(),
                "1 to 64 threads",
            ),
            (
                c.upload_tiles_per_frame >= 1,
                "cache.upload_tiles_per_frame",
                c.upload_tiles_per_frame.to_string(),
                "at least 1 tile",
            ),
            (
                c.upload_bytes_per_frame >= 1 << 20,
                "cache.upload_bytes_per_frame",
                c.upload_bytes_per_frame.to_string(),
                "at least 1 MiB (1048576 bytes)",
            ),
        ];
        self.tlm.validate()?;
        self.seeds.validate()?;
        self.draw_seeds.validate(&self.tlm)?;
        self.texcells.validate(&self.draw_seeds)?;
        self.wind.validate()?;
        self.clouds.validate()?;
        self.atmosphere.validate()?;
        self.display.validate()?;
        self.faults.validate()?;
        first_out_of_range(checks)
    }
}

/// A range check: whether it holds, the full key, its value as text, and the rule in words.
type RangeCheck = (bool, &'static str, String, &'static str);

/// The first check that fails, as `SettingsError::OutOfRange`.
fn first_out_of_range(checks: impl IntoIterator<Item = RangeCheck>) -> Result<(), SettingsError> {
    match checks.into_iter().find(|(ok, ..)| !ok) {
        Some((_, key, value, rule)) => Err(SettingsError::OutOfRange { key, value, rule }),
        None => Ok(()),
    }
}

fn parse(origin: &str, text: &str) -> Result<Table, SettingsError> {
    text.parse::<Table>()
        .map_err(|e| SettingsError::Syntax { origin: origin.to_owned(), message: e.to_string() })
}

/// Keys of earlier releases, and what replaced them: a file that still sets one is told where the
/// knob went rather than that it is unknown.
const MOVED_KEYS: &[(&str, &str)] = &[
    (
        "tlm.radial_lod_m",
        "it meant two things: the TLM's distance bands are now `tlm.radial_bands_m`, and the draw \
         LODs' reaches `draw_seeds.reach_m` (the mesh's first, then the three billboard clouds')",
    ),
    ("seeds.mesh_m", "the real mesh's reach is now the first of `draw_seeds.reach_m`"),
    ("seeds.fade_fraction", "use `draw_seeds.fade_fraction`"),
    ("seeds.impostors", "use `draw_seeds.impostors`"),
];

/// Every key of `layer` must exist in `defaults`, with a table where the default has a table.
fn check_keys(origin: &str, layer: &Table, defaults: &Table, prefix: &str) -> Result<(), SettingsError> {
    for (key, value) in layer {
        let full = format!("{prefix}{key}");
        match (defaults.get(key), value) {
            (None, _) => {
                let origin = origin.to_owned();
                return Err(match MOVED_KEYS.iter().find(|(old, _)| *old == full) {
                    Some((_, instead)) => SettingsError::Moved { origin, key: full, instead },
                    None => SettingsError::UnknownKey { origin, key: full },
                });
            }
            (Some(Value::Table(d)), Value::Table(v)) => check_keys(origin, v, d, &format!("{full}."))?,
            (Some(Value::Table(_)), _) => {
                return Err(SettingsError::WrongType {
                    origin: origin.to_owned(),
                    key: full,
                    expected: "a table",
                });
            }
            (Some(d), v) if !same_kind(d, v) => {
                return Err(SettingsError::WrongType {
                    origin: origin.to_owned(),
                    key: full,
                    expected: kind_of(d),
                });
            }
            _ => {}
        }
    }
    Ok(())
}

fn same_kind(default: &Value, value: &Value) -> bool {
    // An integer where a float is expected is what a person means by `fov_deg = 60`.
    kind_of(default) == kind_of(value) || (default.is_float() && value.is_integer())
}

fn kind_of(value: &Value) -> &'static str {
    match value {
        Value::String(_) => "a string",
        Value::Integer(_) => "an integer",
        Value::Float(_) => "a number",
        Value::Boolean(_) => "true or false",
        Value::Datetime(_) => "a date",
        Value::Array(_) => "an array",
        Value::Table(_) => "a table",
    }
}

fn overlay(base: &mut Table, layer: Table) {
    for (key, value) in layer {
        match (base.get_mut(&key), value) {
            (Some(Value::Table(b)), Value::Table(v)) => overlay(b, v),
            (Some(Value::Float(_)), Value::Integer(i)) => {
                base.insert(key, Value::Float(i as f64));
            }
            (_, v) => {
                base.insert(key, v);
            }
        }
    }
}

#[cfg(test)]
mod tests;
