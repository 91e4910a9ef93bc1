//! `compose`: lays pictures out on a grid, for the figures in `docs/` (`scripts/docs_images.sh`).
//!
//! How it works: each input is read (PNG and whatever else the `image` crate reads, or an X Window
//! Dump, `.xwd`, as `xwd` writes a window's contents), cropped to `--crop`, scaled by `--scale`
//! with `--filter`, put over a checkerboard when `--checker` is given (so an atlas's transparent
//! texels show), and placed left to right, top to bottom, `--columns` to a row, `--gap` pixels
//! apart on `--background`. Cells are as large as the largest input after cropping and scaling;
//! smaller ones sit at their cell's top left. Nothing here judges or changes a picture's colours:
//! the figures show what the renderer wrote.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail, ensure};
use image::{Rgba, RgbaImage, imageops};

#[derive(clap::Args)]
pub struct ComposeArgs {
    /// The pictures, in reading order (left to right, then top to bottom).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    /// The picture to write (PNG).
    #[arg(long)]
    out: PathBuf,
    /// Pictures per row (default: all in one row).
    #[arg(long)]
    columns: Option<usize>,
    /// The part of every input kept, in its own pixels: X,Y,WIDTH,HEIGHT.
    #[arg(long, value_delimiter = ',')]
    crop: Option<Vec<u32>>,
    /// Scale of every input after cropping (0.75 shrinks a 960 × 540 frame to 720 × 405).
    #[arg(long, default_value_t = 1.0)]
    scale: f64,
    /// How a scaled picture is resampled: nearest (pixels stay squares), triangle or lanczos.
    #[arg(long, default_value = "triangle")]
    filter: String,
    /// Pixels between neighbouring pictures.
    #[arg(long, default_value_t = 3)]
    gap: u32,
    /// Colour of the gaps and of unused cell area, as R,G,B.
    #[arg(long, value_delimiter = ',', default_values_t = [255, 255, 255])]
    background: Vec<u8>,
    /// Put each input over a grey checkerboard of squares this many pixels wide (shows alpha).
    #[arg(long)]
    checker: Option<u32>,
    /// Show each input as its FLIP error map against this picture (the same size), and print its
    /// mean FLIP (dark: no error; yellow: large).
    #[arg(long)]
    flip_reference: Option<PathBuf>,
}

pub fn compose(args: &ComposeArgs) -> Result<()> {
    let filter = match args.filter.as_str() {
        "nearest" => imageops::FilterType::Nearest,
        "triangle" => imageops::FilterType::Triangle,
        "lanczos" => imageops::FilterType::Lanczos3,
        other => bail!("--filter {other}: give nearest, triangle or lanczos"),
    };
    ensure!(args.scale.is_finite() && args.scale > 0.0, "--scale {}: must be a positive number", args.scale);
    let reference = args.flip_reference.as_deref().map(read_picture).transpose()?;
    let mut pictures = Vec::with_capacity(args.inputs.len());
    for path in &args.inputs {
        let mut picture = read_picture(path)?;
        if let Some(reference) = &reference {
            let (map, mean) = flip_picture(reference, &picture)
                .with_context(|| format!("FLIP of {} against the reference", path.display()))?;
            println!("{}: mean FLIP {mean:.4}", path.display());
            picture = map;
        }
        let picture = match &args.crop {
            Some(crop) => cropped(&picture, crop).with_context(|| format!("cropping {}", path.display()))?,
            None => picture,
        };
        let picture = scaled(&picture, args.scale, filter);
        pictures.push(match args.checker {
            Some(square) => over_checkerboard(&picture, square.max(1)),
            None => picture,
        });
    }
    let columns = args.columns.unwrap_or(pictures.len()).clamp(1, pictures.len());
    let rows = pictures.len().div_ceil(columns);
    let cell = [
        pictures.iter().map(RgbaImage::width).max().unwrap_or(1),
        pictures.iter().map(RgbaImage::height).max().unwrap_or(1),
    ];
    let span =
        |cells: usize, size: u32| cells as u64 * u64::from(size) + (cells as u64 - 1) * u64::from(args.gap);
    let (width, height) = (span(columns, cell[0]), span(rows, cell[1]));
    ensure!(width * height <= 1 << 28, "the composed picture would be {width} × {height} pixels: too large");
    let &[r, g, b] = args.background.as_slice() else { bail!("--background takes three numbers: R,G,B") };
    let mut out = RgbaImage::from_pixel(width as u32, height as u32, Rgba([r, g, b, 255]));
    for (k, picture) in pictures.iter().enumerate() {
        let (column, row) = ((k % columns) as u32, (k / columns) as u32);
        let at = [column * (cell[0] + args.gap), row * (cell[1] + args.gap)];
        imageops::replace(&mut out, picture, i64::from(at[0]), i64::from(at[1]));
    }
    out.save(&args.out).with_context(|| format!("writing {}", args.out.display()))?;
    println!("{}: {} × {}, {} pictures", args.out.display(), out.width(), out.height(), pictures.len());
    Ok(())
}

fn read_picture(path: &Path) -> Result<RgbaImage> {
    if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("xwd")) {
        let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
        return xwd_picture(&bytes)
            .with_context(|| format!("{}: not an X Window Dump of a TrueColor window", path.display()));
    }
    Ok(image::open(path).with_context(|| format!("reading {}", path.display()))?.to_rgba8())
}

/// The FLIP error map of `test` against `reference` in FLIP's magma colours, and its mean.
fn flip_picture(reference: &RgbaImage, test: &RgbaImage) -> Result<(RgbaImage, f64)> {
    let errors = terramp::reference::image_metrics::flip_map(reference, test)?;
    let mean = errors.iter().map(|&e| f64::from(e)).sum::<f64>() / errors.len().max(1) as f64;
    let map = nv_flip::FlipImageFloat::with_data(test.width(), test.height(), &errors);
    let rgb = map.apply_color_lut(&nv_flip::magma_lut()).to_vec();
    let picture = RgbaImage::from_fn(test.width(), test.height(), |x, y| {
        let at = 3 * (y as usize * test.width() as usize + x as usize);
        Rgba([rgb[at], rgb[at + 1], rgb[at + 2], 255])
    });
    Ok((picture, mean))
}

fn cropped(picture: &RgbaImage, crop: &[u32]) -> Result<RgbaImage> {
    let &[x, y, w, h] = crop else { bail!("--crop takes four numbers: X,Y,WIDTH,HEIGHT") };
    let fits = x.checked_add(w).is_some_and(|r| r <= picture.width())
        && y.checked_add(h).is_some_and(|b| b <= picture.height());
    ensure!(
        fits && w > 0 && h > 0,
        "{w} × {h} at ({x}, {y}) is not inside the {} × {} picture",
        picture.width(),
        picture.height()
    );
    Ok(imageops::crop_imm(picture, x, y, w, h).to_image())
}

fn scaled(picture: &RgbaImage, scale: f64, filter: imageops::FilterType) -> RgbaImage {
    if scale == 1.0 {
        return picture.clone();
    }
    let size = |n: u32| ((f64::from(n) * scale).round() as u32).max(1);
    imageops::resize(picture, size(picture.width()), size(picture.height()), filter)
}

fn over_checkerboard(picture: &RgbaImage, square: u32) -> RgbaImage {
    let mut out = RgbaImage::from_fn(picture.width(), picture.height(), |x, y| {
        let v = if (x / square + y / square).is_multiple_of(2) { 200 } else { 150 };
        Rgba([v, v, v, 255])
    });
    imageops::overlay(&mut out, picture, 0, 0);
    out
}

/// An XWD file (X11 window dump, version 7) of a TrueColor window with 32-bit pixels, as `xwd`
/// writes a 24- or 32-bit display's window.
fn xwd_picture(bytes: &[u8]) -> Result<RgbaImage> {
    let word = |i: usize| -> Result<u32> {
        let raw = bytes.get(4 * i..4 * i + 4).context("shorter than its header")?;
        Ok(u32::from_be_bytes(raw.try_into()?))
    };
    let (header, version, width, height) = (word(0)? as usize, word(1)?, word(4)?, word(5)?);
    ensure!(version == 7, "XWD version {version}, 7 expected");
    let (byte_order, bits_per_pixel, bytes_per_line) = (word(7)?, word(11)?, word(12)? as usize);
    let (visual_class, colours) = (word(13)?, word(19)? as usize);
    ensure!(
        visual_class == 4 || visual_class == 5,
        "visual class {visual_class}: TrueColor (4) or DirectColor (5) expected"
    );
    ensure!(bits_per_pixel == 32, "{bits_per_pixel} bits per pixel: 32 expected");
    let masks = [word(14)?, word(15)?, word(16)?];
    ensure!(masks.iter().all(|&m| m != 0), "a colour mask is empty");
    let start = header.checked_add(12 * colours).context("its colour map is too long")?;
    let end = (height as usize).checked_mul(bytes_per_line).and_then(|n| n.checked_add(start));
    ensure!(
        end.is_some_and(|end| end <= bytes.len()) && bytes_per_line >= 4 * width as usize,
        "its {width} × {height} pixels lie past its end"
    );
    let pixels = &bytes[start..];
    Ok(RgbaImage::from_fn(width, height, |px, py| {
        let at = py as usize * bytes_per_line + 4 * px as usize;
        let raw = [pixels[at], pixels[at + 1], pixels[at + 2], pixels[at + 3]];
        let v = if byte_order == 0 { u32::from_le_bytes(raw) } else { u32::from_be_bytes(raw) };
        let [r, g, b] = masks.map(|m| ((v & m) >> m.trailing_zeros()) as u8);
        Rgba([r, g, b, 255])
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An XWD header (25 words + a window name) and pixels, as `xwd` writes a 32-bit window.
    fn xwd_file(width: u32, height: u32, pixel: impl Fn(u32, u32) -> [u8; 3]) -> Vec<u8> {
        let name = b"w\0\0\0";
        let header = 100 + name.len() as u32;
        let mut words = [0u32; 25];
        words[0] = header;
        words[1] = 7;
        words[2] = 2; // ZPixmap
        words[3] = 24;
        words[4] = width;
        words[5] = height;
        words[7] = 0; // LSBFirst
        words[11] = 32;
        words[12] = 4 * width;
        words[13] = 4; // TrueColor
        words[14] = 0xff0000;
        words[15] = 0x00ff00;
        words[16] = 0x0000ff;
        let mut bytes: Vec<u8> = words.iter().flat_map(|w| w.to_be_bytes()).collect();
        bytes.extend_from_slice(name);
        for y in 0..height {
            for x in 0..width {
                let [r, g, b] = pixel(x, y);
                bytes.extend_from_slice(&u32::from_be_bytes([0, r, g, b]).to_le_bytes());
            }
        }
        bytes
    }

    #[test]
    fn an_xwd_window_reads_pixel_for_pixel_and_a_damaged_one_is_refused() {
        let colour = |x: u32, y: u32| [x as u8 * 40, y as u8 * 70, 200 - x as u8];
        let bytes = xwd_file(5, 3, colour);
        let picture = xwd_picture(&bytes).unwrap();
        assert_eq!((picture.width(), picture.height()), (5, 3));
        for (x, y, p) in picture.enumerate_pixels() {
            let [r, g, b] = colour(x, y);
            assert_eq!(p.0, [r, g, b, 255], "pixel ({x}, {y})");
        }
        assert!(xwd_picture(&bytes[..bytes.len() - 1]).is_err(), "a truncated dump reads");
        assert!(xwd_picture(&bytes[..40]).is_err(), "a header cut short reads");
    }

    #[test]
    fn lists_parse_from_one_comma_separated_value() {
        #[derive(clap::Parser)]
        struct Cli {
            #[command(flatten)]
            args: ComposeArgs,
        }
        let parse = |line: &[&str]| <Cli as clap::Parser>::try_parse_from(line).map(|c| c.args);
        let args = parse(&[
            "compose",
            "--crop",
            "320,230,640,200",
            "--background",
            "0,10,20",
            "--out",
            "o.png",
            "a.png",
        ])
        .unwrap();
        assert_eq!(args.crop, Some(vec![320, 230, 640, 200]));
        assert_eq!(args.background, vec![0, 10, 20]);
        assert_eq!(parse(&["compose", "--out", "o.png", "a.png"]).unwrap().background, vec![255, 255, 255]);
    }

    #[test]
    fn crops_outside_the_picture_are_refused() {
        let picture = RgbaImage::new(10, 8);
        assert_eq!(cropped(&picture, &[2, 3, 8, 5]).unwrap().dimensions(), (8, 5));
        assert!(cropped(&picture, &[3, 0, 8, 5]).is_err());
        assert!(cropped(&picture, &[0, 0, 0, 5]).is_err());
        assert!(cropped(&picture, &[u32::MAX, 0, 2, 2]).is_err());
    }
}
