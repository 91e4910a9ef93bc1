//! How it works: `save` writes a sample's folder under a hidden name beside its final place, then
//! puts it in place (`crate::publish`), so `<dir>/texcells/<code>` is never half-written. `load` reads the manifest's
//! version alone first (another version is refused as such, not as a malformed file), then the
//! manifest, then the images, checking their checksum and that every image the manifest lists is
//! where and as large as it says, and that the levels have the shapes the pyramid gives them.

use std::fs;
use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::impostor::replace_folder;

use super::{
    Chain, FORMAT_VERSION, ForestSample, MANIFEST_FILE, PREVIEW_FILE, SampleTree, TEXCELLS_DIR, TEXELS_FILE,
    TexcellError, VolumeLevel,
};

/// `texcell.toml`.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Manifest {
    format_version: u32,
    class_code: u8,
    class_name: String,
    /// Always "premultiplied".
    alpha: String,
    cell_m: f32,
    height_m: f32,
    /// Bytes of `texels.bin`, and their CRC-32.
    bytes: u64,
    crc32: u32,
    #[serde(rename = "tree", default)]
    trees: Vec<SampleTree>,
    #[serde(rename = "image")]
    images: Vec<ImageEntry>,
}

#[derive(Deserialize)]
struct VersionOnly {
    format_version: u32,
}

/// Where one image lies in `texels.bin`.
#[derive(Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ImageEntry {
    /// "slice" (level, slice, mip) or "volume" (level = its mip).
    kind: String,
    level: u32,
    slice: u32,
    mip: u32,
    side: u32,
    depth: u32,
    offset: u64,
}

/// The folder of the sample of class `code` under the impostor folder `dir`.
pub fn sample_dir(dir: &Path, code: u8) -> PathBuf {
    dir.join(TEXCELLS_DIR).join(code.to_string())
}

fn io(path: &Path) -> impl FnOnce(std::io::Error) -> TexcellError + '_ {
    move |source| TexcellError::Io { path: path.to_owned(), source }
}

/// Writes `sample` as `sample_dir(dir, sample.class_code)`, replacing an earlier one; returns it.
pub fn save(dir: &Path, sample: &ForestSample) -> Result<PathBuf, TexcellError> {
    let out = sample_dir(dir, sample.class_code);
    replace_folder(
        &out,
        |staging| write_all(staging, sample),
        |path, source| TexcellError::Io { path: path.to_owned(), source },
    )?;
    Ok(out)
}

fn write_all(folder: &Path, sample: &ForestSample) -> Result<(), TexcellError> {
    let mut bytes: Vec<u8> = Vec::new();
    let mut images = Vec::new();
    let mut push = |kind: &str, level: u32, slice: u32, mip: u32, side: u32, depth: u32, data: &[u8]| {
        images.push(ImageEntry {
            kind: kind.into(),
            level,
            slice,
            mip,
            side,
            depth,
            offset: bytes.len() as u64,
        });
        bytes.extend_from_slice(data);
    };
    for (level, slices) in sample.slices.iter().enumerate() {
        for (slice, chain) in slices.iter().enumerate() {
            for (mip, data) in chain.levels.iter().enumerate() {
                push("slice", level as u32, slice as u32, mip as u32, (chain.side >> mip).max(1), 1, data);
            }
        }
    }
    for (level, v) in sample.volume.iter().enumerate() {
        push("volume", level as u32, 0, 0, v.side, v.depth, &v.bytes);
    }
    let manifest = Manifest {
        format_version: FORMAT_VERSION,
        class_code: sample.class_code,
        class_name: sample.class_name.clone(),
        alpha: "premultiplied".into(),
        cell_m: sample.cell_m,
        height_m: sample.height_m,
        bytes: bytes.len() as u64,
        crc32: crc32fast::hash(&bytes),
        trees: sample.trees.clone(),
        images,
    };
    let texels = folder.join(TEXELS_FILE);
    fs::write(&texels, &bytes).map_err(io(&texels))?;
    let text = toml::to_string(&manifest)
        .map_err(|e| TexcellError::Manifest { path: folder.join(MANIFEST_FILE), message: e.to_string() })?;
    let manifest_path = folder.join(MANIFEST_FILE);
    fs::write(&manifest_path, text).map_err(io(&manifest_path))?;
    let side = sample.volume.first().map_or(0, |v| v.side);
    let preview = folder.join(PREVIEW_FILE);
    if let Some(image) = image::RgbaImage::from_raw(side, side, straight(&sample.top_view())) {
        image
            .save(&preview)
            .map_err(|e| TexcellError::Io { path: preview, source: std::io::Error::other(e) })?;
    }
    Ok(())
}

/// Premultiplied RGBA8 (colour sRGB-encoded) as straight alpha, as PNG viewers expect.
fn straight(premultiplied: &[u8]) -> Vec<u8> {
    let texels = super::pyramid::decode(premultiplied);
    texels
        .iter()
        .flat_map(|t| {
            let a = t[3];
            let c = |v: f32| super::pyramid::encode_srgb(if a > 0.0 { v / a } else { 0.0 });
            [c(t[0]), c(t[1]), c(t[2]), (a.clamp(0.0, 1.0) * 255.0).round() as u8]
        })
        .collect()
}

/// Reads the sample of class `code` under the impostor folder `dir`; `Ok(None)` when there is none.
pub fn load(dir: &Path, code: u8) -> Result<Option<ForestSample>, TexcellError> {
    let folder = sample_dir(dir, code);
    let manifest_path = folder.join(MANIFEST_FILE);
    if !manifest_path.exists() {
        return Ok(None);
    }
    let text = fs::read_to_string(&manifest_path).map_err(io(&manifest_path))?;
    let bad_manifest =
        |e: toml::de::Error| TexcellError::Manifest { path: manifest_path.clone(), message: e.to_string() };
    let version: VersionOnly = toml::from_str(&text).map_err(bad_manifest)?;
    if version.format_version != FORMAT_VERSION {
        return Err(TexcellError::Version { path: manifest_path, found: version.format_version });
    }
    let manifest: Manifest = toml::from_str(&text).map_err(bad_manifest)?;
    let texels_path = folder.join(TEXELS_FILE);
    let bytes = fs::read(&texels_path).map_err(io(&texels_path))?;
    let corrupt = |problem: String| TexcellError::Corrupt { path: texels_path.clone(), problem };
    if bytes.len() as u64 != manifest.bytes || crc32fast::hash(&bytes) != manifest.crc32 {
        return Err(corrupt(format!(
            "{} bytes with CRC-32 {:08x}; the manifest says {} bytes, {:08x}",
            bytes.len(),
            crc32fast::hash(&bytes),
            manifest.bytes,
            manifest.crc32
        )));
    }
    let image = |e: &ImageEntry| -> Result<Vec<u8>, TexcellError> {
        // 4 · side² · depth bytes, which passes u64 for sides near 2^32.
        let len = [e.side, e.side, e.depth].into_iter().try_fold(4u64, |n, k| n.checked_mul(u64::from(k)));
        let end = len.and_then(|len| e.offset.checked_add(len)).filter(|&end| end <= bytes.len() as u64);
        let end = end.ok_or_else(|| {
            let (side, depth) = (e.side, e.depth);
            let place = format!("{} {}/{}/{}", e.kind, e.level, e.slice, e.mip);
            corrupt(format!("image {place} of side {side} and depth {depth} runs past the file"))
        })?;
        Ok(bytes[e.offset as usize..end as usize].to_vec())
    };
    let mut slices: Vec<Vec<Chain>> = Vec::new();
    let mut volume = Vec::new();
    for e in &manifest.images {
        match e.kind.as_str() {
            "slice" => {
                let (level, slice) = (e.level as usize, e.slice as usize);
                if level > slices.len() || (level == slices.len() && slice != 0) {
                    return Err(corrupt(format!("slice level {level} listed out of order")));
                }
                if level == slices.len() {
                    slices.push(Vec::new());
                }
                let chains = &mut slices[level];
                if slice == chains.len() {
                    chains.push(Chain { side: e.side, levels: Vec::new() });
                }
                let chain = chains
                    .get_mut(slice)
                    .ok_or_else(|| corrupt(format!("slice {slice} listed out of order")))?;
                // A chain ends at 1 texel; the side's shift checked only below that.
                let mips = chain.side.max(1).ilog2() + 1;
                if e.mip as usize != chain.levels.len()
                    || e.mip >= mips
                    || e.side != (chain.side >> e.mip).max(1)
                {
                    return Err(corrupt(format!(
                        "slice {level}/{slice}: mip {} of side {} out of place (a chain of side {} has {mips} mips)",
                        e.mip, e.side, chain.side
                    )));
                }
                chain.levels.push(image(e)?);
            }
            "volume" => volume.push(VolumeLevel { side: e.side, depth: e.depth, bytes: image(e)? }),
            other => return Err(corrupt(format!("unknown image kind {other:?}"))),
        }
    }
    let sample = ForestSample {
        class_code: manifest.class_code,
        class_name: manifest.class_name,
        cell_m: manifest.cell_m,
        height_m: manifest.height_m,
        trees: manifest.trees,
        slices,
        volume,
    };
    check_shape(&sample).map_err(corrupt)?;
    Ok(Some(sample))
}

/// The pyramid's shape: level k has half the slices of level k − 1, each half the side, every
/// chain down to 1 texel; the volume starts as the finest slices stacked and halves to 1³.
fn check_shape(s: &ForestSample) -> Result<(), String> {
    let (n, side) = (s.slice_count(), s.texels());
    if n == 0 || !n.is_power_of_two() || side == 0 || !side.is_power_of_two() {
        return Err(format!("{n} finest slices of {side} texels: both must be powers of two"));
    }
    for (k, level) in s.slices.iter().enumerate() {
        // The manifest may list any number of levels: halving by 32 or more gives 0, no overflow.
        let halved = |v: u32| u32::try_from(k).ok().and_then(|k| v.checked_shr(k)).unwrap_or(0);
        let (want_n, want_side) = (halved(n), halved(side).max(1));
        if level.len() as u32 != want_n || level.iter().any(|c| c.side != want_side) {
            return Err(format!(
                "slice level {k}: {} slices; {want_n} of {want_side} texels expected",
                level.len()
            ));
        }
        if level.iter().any(|c| c.levels.len() as u32 != want_side.ilog2() + 1) {
            return Err(format!("slice level {k}: a mip chain does not reach 1 texel"));
        }
    }
    if s.slices.len() as u32 != n.ilog2() + 1 {
        return Err(format!("{} slice levels; {} expected", s.slices.len(), n.ilog2() + 1));
    }
    // `volume_chain`'s levels: the finest slices stacked, each dimension halved per level (none
    // below 1) down to 1³. The upload cuts each level into slices of 4 · side² bytes.
    let levels = side.ilog2().max(n.ilog2()) + 1;
    let halved = |v: u32, m: usize| (v >> m).max(1);
    let chain =
        s.volume.iter().enumerate().all(|(m, v)| v.side == halved(side, m) && v.depth == halved(n, m));
    match s.volume.len() as u32 == levels && chain {
        true => Ok(()),
        false => {
            Err("the volume's levels are not the finest slices stacked and halved down to 1 texel".into())
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::pyramid::Layer;
    use super::*;

    /// A small sample built by the pyramid from 4 slices of 8 texels.
    fn sample() -> ForestSample {
        let finest: Vec<Layer> = (0..4)
            .map(|k| Layer {
                side: 8,
                texels: (0..64)
                    .map(|i| if (i + k) % 5 == 0 { [0.1, 0.3, 0.05, 0.6] } else { [0.0; 4] })
                    .collect(),
            })
            .collect();
        let (slices, volume) = super::super::sample_images(finest);
        let tree =
            SampleTree { model: "Pine_1".into(), position_m: [3.0, 4.0], height_m: 12.5, angle_deg: 30.0 };
        ForestSample {
            class_code: 5,
            class_name: "forest".into(),
            cell_m: 32.0,
            height_m: 13.0,
            trees: vec![tree],
            slices,
            volume,
        }
    }

    fn temp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("terramp-texcell-{name}-{}", std::process::id()));
        let _ = fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn a_sample_reads_back_as_written() {
        let dir = temp("round-trip");
        let s = sample();
        let written = save(&dir, &s).unwrap();
        assert_eq!(written, sample_dir(&dir, 5));
        assert!(written.join(PREVIEW_FILE).exists());
        assert_eq!(load(&dir, 5).unwrap(), Some(s));
        assert_eq!(load(&dir, 41).unwrap(), None, "no sample of another class");
        let _ = fs::remove_dir_all(&dir);
    }

    #[test]
    fn damaged_samples_are_refused_naming_the_file() {
        let dir = temp("damaged");
        save(&dir, &sample()).unwrap();
        let folder = sample_dir(&dir, 5);
        // One byte flipped: the checksum says so.
        let texels = folder.join(TEXELS_FILE);
        let mut bytes = fs::read(&texels).unwrap();
        bytes[100] ^= 0xff;
        fs::write(&texels, &bytes).unwrap();
        let err = load(&dir, 5).unwrap_err().to_string();
        assert!(err.contains(TEXELS_FILE) && err.contains("CRC-32"), "{err}");
        // Another version: refused as such.
        save(&dir, &sample()).unwrap();
        let manifest = folder.join(MANIFEST_FILE);
        let text = fs::read_to_string(&manifest).unwrap().replace("format_version = 1", "format_version = 9");
        fs::write(&manifest, text).unwrap();
        assert!(matches!(load(&dir, 5), Err(TexcellError::Version { found: 9, .. })));
        // A level missing: the shape check names it.
        let mut short = sample();
        short.slices.pop();
        save(&dir, &short).unwrap();
        let err = load(&dir, 5).unwrap_err().to_string();
        assert!(err.contains("slice levels"), "{err}");
        // Garbage manifest.
        fs::write(&manifest, "format_version = \"one\"").unwrap();
        assert!(matches!(load(&dir, 5), Err(TexcellError::Manifest { .. })));
        let _ = fs::remove_dir_all(&dir);
    }

    /// `texcell.toml`'s sizes feed a product and a shift: an image of 2^32 − 1 texels a side is
    /// 4 · side² bytes, past u64, and a 33rd mip of a 1-texel chain shifts its side by 32 bits.
    /// Both panicked with overflow in a debug build (found by the overflow audit, issue 42); both
    /// are `Corrupt` errors naming the file and the image now.
    #[test]
    fn sizes_whose_arithmetic_would_overflow_are_refused_not_a_panic() {
        let dir = temp("overflow");
        let folder = save(&dir, &sample()).unwrap();
        let manifest_path = folder.join(MANIFEST_FILE);
        let original: toml::Table = toml::from_str(&fs::read_to_string(&manifest_path).unwrap()).unwrap();
        let load_with = |edit: &dyn Fn(&mut toml::Table)| {
            let mut manifest = original.clone();
            edit(&mut manifest);
            fs::write(&manifest_path, toml::to_string(&manifest).unwrap()).unwrap();
            load(&dir, 5).map(|_| ()).unwrap_err()
        };
        let error = load_with(&|m| m["image"][0]["side"] = toml::Value::Integer(i64::from(u32::MAX)));
        assert!(
            matches!(&error, TexcellError::Corrupt { path, .. } if path.ends_with(TEXELS_FILE)),
            "{error}"
        );
        assert!(
            error.to_string().contains("slice 0/0/0") && error.to_string().contains("4294967295"),
            "{error}"
        );
        // One 1-texel slice with 33 mips, each the first 4 bytes of the file: the 33rd shifted the
        // side by 32 bits; now the second is refused, a 1-texel chain having 1 mip.
        let error = load_with(&|m| {
            let image = |mip: i64| {
                let entry =
                    [("kind", "slice".into()), ("level", 0.into()), ("slice", 0.into()), ("mip", mip.into())];
                let sizes = [("side", 1.into()), ("depth", 1.into()), ("offset", 0.into())];
                toml::Value::Table(entry.into_iter().chain(sizes).map(|(k, v)| (k.to_owned(), v)).collect())
            };
            m["image"] = toml::Value::Array((0..33).map(image).collect());
        });
        assert!(matches!(&error, TexcellError::Corrupt { .. }), "{error}");
        assert!(error.to_string().contains("mip 1 of side 1 out of place"), "{error}");
        // A volume level of no texels: the upload would cut it into slices of 0 bytes (found by the
        // same audit: only the volume's finest level was checked).
        let error = load_with(&|m| {
            let images = m["image"].as_array_mut().unwrap();
            let volume = images.iter_mut().filter(|i| i["kind"].as_str() == Some("volume"));
            for image in volume.filter(|i| i["level"].as_integer() == Some(1)) {
                image["side"] = toml::Value::Integer(0);
                image["depth"] = toml::Value::Integer(0);
            }
        });
        assert!(error.to_string().contains("the volume's levels"), "{error}");
        // The manifest as saved still loads: the checks refuse only what is wrong.
        fs::write(&manifest_path, toml::to_string(&original).unwrap()).unwrap();
        assert!(load(&dir, 5).unwrap().is_some());
        let _ = fs::remove_dir_all(&dir);
    }
}
