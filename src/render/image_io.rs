//! Writing images people look at: sRGB PNG previews of linear RGB buffers, and multi-layer
//! OpenEXR files (beauty plus AOV layers) through the `exr` crate.

use crate::output::Staged;
use glam::Vec3;
use std::io::BufWriter;
use std::path::Path;

/// Errors while writing an image, naming the file.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// The file could not be created or written.
    #[error("cannot write image {path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// Why.
        source: std::io::Error,
    },
    /// The PNG encoder failed.
    #[error("cannot encode PNG {path}: {source}")]
    Png {
        /// The file.
        path: String,
        /// Why.
        source: png::EncodingError,
    },
    /// The exr crate could not write the file.
    #[error("cannot write EXR {path}: {message}")]
    ExrWrite {
        /// The file.
        path: String,
        /// The exr crate's message.
        message: String,
    },
    /// The exr crate could not read the file.
    #[error("cannot read EXR {path}: {message}")]
    ExrRead {
        /// The file.
        path: String,
        /// The exr crate's message.
        message: String,
    },
    /// A pixel buffer whose length does not match the image size.
    #[error("image {path}: buffer holds {got} pixels, {width}x{height} needs {want}")]
    Size {
        /// The file.
        path: String,
        /// Image width in pixels.
        width: u32,
        /// Image height in pixels.
        height: u32,
        /// Pixels the buffer holds.
        got: usize,
        /// Pixels the size needs (width × height).
        want: usize,
    },
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value, clamped to [0, 1].
#[inline]
pub fn linear_to_srgb(x: f32) -> f32 {
    let x = if x.is_finite() {
        x.clamp(0.0, 1.0)
    } else {
        0.0
    };
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// The inverse sRGB transfer function (IEC 61966-2-1): the linear value of an encoded x in [0, 1].
#[inline]
pub fn srgb_to_linear(x: f32) -> f32 {
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// 8-bit sRGB bytes (RGB, row-major, top row first) of a linear buffer scaled by `2^exposure`.
pub fn to_srgb8(pixels: &[Vec3], exposure: f32) -> Vec<u8> {
    let scale = exposure.exp2();
    pixels
        .iter()
        .flat_map(|c| (*c * scale).to_array())
        .map(|v| (linear_to_srgb(v) * 255.0 + 0.5) as u8)
        .collect()
}

/// Writes 8-bit RGB bytes as a PNG, whole or not at all ([`crate::output::Staged`]).
pub fn write_png_rgb8(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), ImageError> {
    let staged = stage_png_rgb8(path, width, height, rgb)?;
    commit(staged)
}

/// Renames a staged image over its final name.
pub fn commit(staged: Staged) -> Result<(), ImageError> {
    let path = staged.path().display().to_string();
    staged
        .commit()
        .map_err(|source| ImageError::Io { path, source })
}

/// How a PNG labels its samples: colour images carry an `sRGB` chunk; data maps (normals,
/// anisotropy, roughness, masks) carry no colour-space chunk at all (no `sRGB`, `gAMA`, `cHRM`
/// or `iCCP`), as glTF 2.0 §5.22 ("Image") asks of every image a glTF asset embeds: the asset,
/// not the file, says how the samples are meant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PngTag {
    /// A colour image: sRGB-encoded samples, with an `sRGB` chunk.
    Srgb,
    /// A data map: no colour-space chunk.
    Untagged,
}

/// Encodes 8-bit RGB bytes (row-major, top row first) as a PNG into `out`.
pub fn encode_png_rgb8(
    out: impl std::io::Write,
    width: u32,
    height: u32,
    rgb: &[u8],
    tag: PngTag,
) -> Result<(), png::EncodingError> {
    let mut enc = png::Encoder::new(out, width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    if tag == PngTag::Srgb {
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    let mut w = enc.write_header()?;
    w.write_image_data(rgb)?;
    w.finish()
}

/// Checks that `rgb` holds `width × height` RGB pixels, naming `path` if not.
fn check_rgb8(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), ImageError> {
    let want = width as usize * height as usize;
    if rgb.len() == want * 3 {
        return Ok(());
    }
    Err(ImageError::Size {
        path: path.display().to_string(),
        width,
        height,
        got: rgb.len() / 3,
        want,
    })
}

/// Encodes an sRGB-tagged PNG into a uniquely named temporary file beside `path`, to
/// [`commit`] later.
pub fn stage_png_rgb8(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
) -> Result<Staged, ImageError> {
    stage_png_tagged(path, width, height, rgb, PngTag::Srgb)
}

/// Writes 8-bit codes of a data map (no transfer curve) as an untagged PNG ([`PngTag`]), whole
/// or not at all.
pub fn write_png_data8(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), ImageError> {
    commit(stage_png_tagged(
        path,
        width,
        height,
        rgb,
        PngTag::Untagged,
    )?)
}

fn stage_png_tagged(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
    tag: PngTag,
) -> Result<Staged, ImageError> {
    check_rgb8(path, width, height, rgb)?;
    let name = path.display().to_string();
    let mut staged = Staged::new(path).map_err(|source| ImageError::Io {
        path: name.clone(),
        source,
    })?;
    let mut out = BufWriter::new(staged.file());
    encode_png_rgb8(&mut out, width, height, rgb, tag).map_err(|source| ImageError::Png {
        path: name.clone(),
        source,
    })?;
    flush(out, &name)?;
    Ok(staged)
}

/// Writes a linear RGB buffer as an sRGB PNG preview with exposure `exposure` stops.
pub fn write_png_linear(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[Vec3],
    exposure: f32,
) -> Result<(), ImageError> {
    write_png_rgb8(path, width, height, &to_srgb8(pixels, exposure))
}

/// [`write_png_linear`] staged, to [`commit`] later.
pub fn stage_png_linear(
    path: &Path,
    width: u32,
    height: u32,
    pixels: &[Vec3],
    exposure: f32,
) -> Result<Staged, ImageError> {
    stage_png_rgb8(path, width, height, &to_srgb8(pixels, exposure))
}

/// One named layer of a multi-layer EXR: `channels` are the channel suffixes (e.g. `["R","G","B"]`
/// or `["X","Y","Z"]`), `data` is row-major with `channels.len()` values per pixel.
pub struct ExrLayer<'a> {
    /// Layer name; empty for the beauty layer (plain `R`, `G`, `B` channels).
    pub name: &'a str,
    /// Channel suffixes, e.g. `["R", "G", "B"]`.
    pub channels: &'a [&'a str],
    /// Row-major values, `channels.len()` per pixel, top row first.
    pub data: Vec<f32>,
}

/// The lossless compression of an EXR file: a trade of file size against CPU time.
///
/// Measured on a 512×384 sweep frame (RGB + standard error, 32-bit float, path-traced noise):
/// ZIP 2.31 MB, RLE 2.89 MB, none 3.15 MB; writing 48 such frames costs ≈ 2.5 s of CPU with ZIP
/// and ≈ 0.3 s with RLE (notes/sweep.md). Noisy float data leaves deflate little to find.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
pub enum ExrCompression {
    /// Deflate in blocks of 16 scan lines: the smallest files, the slowest to write.
    #[default]
    Zip,
    /// Run-length encoding in 64×64 tiles: almost as fast as no compression.
    Rle,
    /// No compression.
    None,
}

impl ExrCompression {
    fn encoding(self) -> exr::prelude::Encoding {
        use exr::prelude::Encoding;
        match self {
            ExrCompression::Zip => Encoding::SMALL_LOSSLESS,
            // Chunks in increasing order: the parallel compressor otherwise writes them as they
            // finish, so equal pixels gave different bytes run to run.
            ExrCompression::Rle => Encoding {
                line_order: exr::prelude::LineOrder::Increasing,
                ..Encoding::FAST_LOSSLESS
            },
            ExrCompression::None => Encoding::UNCOMPRESSED,
        }
    }
}

/// Writes a single-part EXR whose layers are channel-name prefixes (`albedo.R`, `depth.Z`, ...),
/// the OpenEXR multi-layer convention that compositors read. 32-bit float, ZIP compression.
/// Written to a temporary name and renamed, so a failure never leaves a half-written file.
pub fn write_exr_layers(
    path: &Path,
    width: u32,
    height: u32,
    layers: &[ExrLayer],
) -> Result<(), ImageError> {
    write_exr_layers_with(path, width, height, layers, ExrCompression::Zip, &[])
}

/// [`write_exr_layers`] with the compression and header text attributes chosen by the caller.
pub fn write_exr_layers_with(
    path: &Path,
    width: u32,
    height: u32,
    layers: &[ExrLayer],
    compression: ExrCompression,
    meta: ExrMeta,
) -> Result<(), ImageError> {
    commit(stage_exr_layers(
        path,
        width,
        height,
        layers,
        compression,
        meta,
    )?)
}

/// Encodes a multi-layer EXR into a uniquely named temporary file beside `path`, to [`commit`]
/// later.
///
/// The header carries the standard `software` attribute ("xylem VERSION") and `meta`, text
/// attributes (name, value) such as a render's scene, spp, seed and camera ([`ExrMeta`]).
pub fn stage_exr_layers(
    path: &Path,
    width: u32,
    height: u32,
    layers: &[ExrLayer],
    compression: ExrCompression,
    meta: ExrMeta,
) -> Result<Staged, ImageError> {
    use exr::prelude::*;
    let name = path.display().to_string();
    let n = width as usize * height as usize;
    let mut channels: Vec<AnyChannel<FlatSamples>> = Vec::new();
    for layer in layers {
        let k = layer.channels.len();
        if layer.data.len() != n * k {
            return Err(ImageError::Size {
                path: name,
                width,
                height,
                got: layer.data.len() / k.max(1),
                want: n,
            });
        }
        for (c, suffix) in layer.channels.iter().enumerate() {
            let full = if layer.name.is_empty() {
                suffix.to_string()
            } else {
                format!("{}.{}", layer.name, suffix)
            };
            let samples: Vec<f32> = layer.data.iter().skip(c).step_by(k).copied().collect();
            channels.push(AnyChannel::new(full.as_str(), FlatSamples::F32(samples)));
        }
    }
    let mut attributes = LayerAttributes {
        software_name: Some(exr_text(&format!("xylem {}", env!("CARGO_PKG_VERSION")))),
        ..LayerAttributes::default()
    };
    for (key, value) in meta {
        attributes
            .other
            .insert(exr_text(key), AttributeValue::Text(exr_text(value)));
    }
    let layer = Layer::new(
        (width as usize, height as usize),
        attributes,
        compression.encoding(),
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let mut staged = Staged::new(path).map_err(|source| ImageError::Io {
        path: name.clone(),
        source,
    })?;
    let mut out = BufWriter::new(staged.file());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut out)
        .map_err(|e| ImageError::ExrWrite {
            path: name.clone(),
            message: e.to_string(),
        })?;
    flush(out, &name)?;
    Ok(staged)
}

/// Text attributes of an EXR header, (name, value): e.g. `("spp", "64")`.
pub type ExrMeta<'a> = &'a [(&'a str, String)];

/// An EXR text attribute: OpenEXR text is 8-bit (Latin-1 here); other characters become `?`.
fn exr_text(s: &str) -> exr::prelude::Text {
    let latin1: String = s
        .chars()
        .map(|c| if (c as u32) < 256 { c } else { '?' })
        .collect();
    exr::prelude::Text::new_or_panic(latin1)
}

/// Flushes a buffered writer, naming the file on failure (a dropped `BufWriter` would hide it).
fn flush(mut out: BufWriter<&mut std::fs::File>, name: &str) -> Result<(), ImageError> {
    std::io::Write::flush(&mut out).map_err(|source| ImageError::Io {
        path: name.to_string(),
        source,
    })
}

/// Writes a rendered image as EXR: beauty `R G B A` (alpha = the fraction of the pixel's camera
/// samples that hit something; misses add what they saw, black without an environment light)
/// plus the AOV layers `albedo` (RGB), `normal` (XYZ), `depth` (Z, +∞ where nothing was hit),
/// `fiber` (XYZ), `ray_mask` (Y), `growth_time` (Y) and `std_error` (Y), with `meta` in the
/// header ([`stage_exr_layers`]).
pub fn write_image_exr(path: &Path, image: &super::Image, meta: ExrMeta) -> Result<(), ImageError> {
    commit(stage_image_exr(path, image, meta)?)
}

/// [`write_image_exr`] staged, to [`commit`] later.
pub fn stage_image_exr(
    path: &Path,
    image: &super::Image,
    meta: ExrMeta,
) -> Result<Staged, ImageError> {
    let mut layers = vec![beauty_rgba(&image.beauty, &image.aov)];
    layers.extend(aov_layers(&image.aov));
    layers.push(ExrLayer {
        name: "std_error",
        channels: &["Y"],
        data: image.std_error.clone(),
    });
    stage_exr_layers(
        path,
        image.width,
        image.height,
        &layers,
        ExrCompression::Zip,
        meta,
    )
}

/// The beauty layer `R G B A` of radiance and the AOVs' coverage (alpha).
pub fn beauty_rgba(beauty: &[Vec3], aov: &[super::Aov]) -> ExrLayer<'static> {
    ExrLayer {
        name: "",
        channels: &["R", "G", "B", "A"],
        data: beauty
            .iter()
            .zip(aov)
            .flat_map(|(c, a)| [c.x, c.y, c.z, a.coverage])
            .collect(),
    }
}

/// The AOV layers of [`write_image_exr`] (`albedo` … `growth_time`), e.g. for a file of AOVs that
/// several images share.
pub fn aov_layers(aov: &[super::Aov]) -> Vec<ExrLayer<'static>> {
    let v3 = |f: &dyn Fn(&super::Aov) -> Vec3| -> Vec<f32> {
        aov.iter().flat_map(|a| f(a).to_array()).collect()
    };
    let s = |f: &dyn Fn(&super::Aov) -> f32| -> Vec<f32> { aov.iter().map(f).collect() };
    vec![
        ExrLayer {
            name: "albedo",
            channels: &["R", "G", "B"],
            data: v3(&|a| a.albedo),
        },
        ExrLayer {
            name: "normal",
            channels: &["X", "Y", "Z"],
            data: v3(&|a| a.normal),
        },
        ExrLayer {
            name: "depth",
            channels: &["Z"],
            data: s(&|a| a.depth),
        },
        ExrLayer {
            name: "fiber",
            channels: &["X", "Y", "Z"],
            data: v3(&|a| a.fiber),
        },
        ExrLayer {
            name: "ray_mask",
            channels: &["Y"],
            data: s(&|a| a.ray_mask),
        },
        ExrLayer {
            name: "growth_time",
            channels: &["Y"],
            data: s(&|a| a.growth_time),
        },
    ]
}

/// Reads the RGB channels of the first layer of an EXR (alpha ignored): (width, height, pixels).
pub fn read_exr_rgb(path: &Path) -> Result<(usize, usize, Vec<Vec3>), ImageError> {
    let img = exr::prelude::read_first_rgba_layer_from_file(
        path,
        |res, _| {
            (
                res.width(),
                res.height(),
                vec![Vec3::ZERO; res.width() * res.height()],
            )
        },
        |buf: &mut (usize, usize, Vec<Vec3>), pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let w = buf.0;
            buf.2[pos.y() * w + pos.x()] = Vec3::new(r, g, b);
        },
    )
    .map_err(|e| ImageError::ExrRead {
        path: path.display().to_string(),
        message: e.to_string(),
    })?;
    Ok(img.layer_data.channel_data.pixels)
}

/// The first layer of an EXR with every channel and attribute.
fn read_exr_layer(
    path: &Path,
) -> Result<exr::prelude::Layer<exr::prelude::AnyChannels<exr::prelude::FlatSamples>>, ImageError> {
    use exr::prelude::*;
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| ImageError::ExrRead {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
    Ok(img.layer_data)
}

/// Reads every channel of the first layer of an EXR as (name, values).
pub fn read_exr_channels(path: &Path) -> Result<Vec<(String, Vec<f32>)>, ImageError> {
    Ok(read_exr_layer(path)?
        .channel_data
        .list
        .iter()
        .map(|c| (c.name.to_string(), c.sample_data.values_as_f32().collect()))
        .collect())
}

/// The text attributes of an EXR's first layer as (name, value), with the standard `software`
/// attribute first where present ([`stage_exr_layers`] writes both).
pub fn read_exr_text(path: &Path) -> Result<Vec<(String, String)>, ImageError> {
    let a = read_exr_layer(path)?.attributes;
    let mut out: Vec<(String, String)> = a
        .software_name
        .iter()
        .map(|t| ("software".to_string(), t.to_string()))
        .collect();
    let mut other: Vec<(String, String)> = a
        .other
        .iter()
        .filter_map(|(k, v)| match v {
            exr::prelude::AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
            _ => None,
        })
        .collect();
    other.sort();
    out.extend(other);
    Ok(out)
}

/// The chunk types of a PNG byte stream in order (PNG spec §5.3: after the 8-byte signature,
/// length, type, data, CRC), e.g. to check which colour-space chunks a file carries.
pub fn png_chunk_types(bytes: &[u8]) -> Vec<String> {
    let mut at = 8;
    let mut out = Vec::new();
    while at + 8 <= bytes.len() {
        let len = u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
        out.push(String::from_utf8_lossy(&bytes[at + 4..at + 8]).into_owned());
        at += 12 + len;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_endpoints_and_continuity() {
        assert_eq!(linear_to_srgb(0.0), 0.0);
        assert!((linear_to_srgb(1.0) - 1.0).abs() < 1e-6);
        assert_eq!(linear_to_srgb(f32::NAN), 0.0);
        let a = 0.003_130_8_f32;
        assert!((12.92 * a - (1.055 * a.powf(1.0 / 2.4) - 0.055)).abs() < 1e-4);
    }

    #[test]
    fn rendered_exr_has_alpha_infinite_depth_on_misses_and_header_metadata() {
        let hit = crate::render::Aov {
            depth: 250.0,
            coverage: 1.0,
            ..Default::default()
        };
        let miss = crate::render::Aov {
            depth: f32::INFINITY,
            ..Default::default()
        };
        let image = crate::render::Image {
            width: 2,
            height: 1,
            beauty: vec![Vec3::new(0.5, 0.25, 0.125), Vec3::ZERO],
            std_error: vec![0.0; 2],
            aov: vec![hit, miss],
            nonfinite: 0,
        };
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.exr");
        let meta = [
            ("spp", "64".to_string()),
            ("scene", "board – ø".to_string()),
        ];
        write_image_exr(&p, &image, &meta).unwrap();
        let ch = read_exr_channels(&p).unwrap();
        let get = |n: &str| ch.iter().find(|(c, _)| c == n).unwrap().1.clone();
        assert_eq!(get("A"), vec![1.0, 0.0]);
        assert_eq!(get("R"), vec![0.5, 0.0]);
        assert_eq!(get("depth.Z"), vec![250.0, f32::INFINITY]);
        let text = read_exr_text(&p).unwrap();
        let version = format!("xylem {}", env!("CARGO_PKG_VERSION"));
        let get = |k: &str| text.iter().find(|(n, _)| n == k).unwrap().1.clone();
        assert_eq!(get("software"), version);
        assert_eq!(get("spp"), "64");
        assert_eq!(get("scene"), "board ? ø");
    }

    #[test]
    fn data_pngs_carry_no_colour_space_chunk() {
        let rgb = [10u8, 128, 255, 0, 0, 0];
        let chunks = |tag| {
            let mut v = Vec::new();
            encode_png_rgb8(&mut v, 2, 1, &rgb, tag).unwrap();
            png_chunk_types(&v)
        };
        let (srgb, data) = (chunks(PngTag::Srgb), chunks(PngTag::Untagged));
        assert!(srgb.iter().any(|c| c == "sRGB"), "{srgb:?}");
        for c in ["sRGB", "gAMA", "cHRM", "iCCP"] {
            assert!(!data.iter().any(|d| d == c), "{c} in {data:?}");
        }
        assert_eq!(data.first().map(String::as_str), Some("IHDR"));
        assert_eq!(data.last().map(String::as_str), Some("IEND"));
    }

    #[test]
    fn png_round_trip_and_size_check() {
        let dir = std::env::temp_dir().join(format!("xylem-png-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("t.png");
        let px = vec![Vec3::new(1.0, 0.5, 0.0); 6];
        write_png_linear(&p, 3, 2, &px, 0.0).unwrap();
        let dec = png::Decoder::new(std::fs::File::open(&p).unwrap());
        let mut r = dec.read_info().unwrap();
        let mut buf = vec![0; r.output_buffer_size()];
        let info = r.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (3, 2));
        assert_eq!(&buf[..3], &[255, 188, 0]);
        assert!(write_png_linear(&p, 4, 2, &px, 0.0).is_err());
        let e = dir.join("t.exr");
        let layers = [
            ExrLayer {
                name: "",
                channels: &["R", "G", "B"],
                data: px.iter().flat_map(|c| c.to_array()).collect(),
            },
            ExrLayer {
                name: "depth",
                channels: &["Z"],
                data: vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0],
            },
        ];
        for c in [
            ExrCompression::Zip,
            ExrCompression::Rle,
            ExrCompression::None,
        ] {
            write_exr_layers_with(&e, 3, 2, &layers, c, &[]).unwrap();
            let (w, h, rgb) = read_exr_rgb(&e).unwrap();
            assert_eq!((w, h), (3, 2), "{c:?}");
            assert_eq!(rgb, px, "{c:?}");
            let ch = read_exr_channels(&e).unwrap();
            let z = ch.iter().find(|(n, _)| n == "depth.Z").unwrap();
            assert_eq!(z.1, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0], "{c:?}");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
