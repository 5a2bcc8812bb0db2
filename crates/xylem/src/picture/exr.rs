//! OpenEXR files of any float layers: single-part files whose layers are channel-name prefixes
//! (`albedo.R`, `depth.Z`), written whole or not at all ([`super::file::stage`]) and
//! byte-identical for equal input, and read back with their declared size checked before any
//! pixel is decoded. What a render puts into them (beauty with alpha, AOV layers) is
//! [`crate::render::image_io`]'s.

use super::file::{commit, stage, ImageError};
use super::Image;
use crate::output::Staged;
use crate::resources::{any_size, SizeCheck};
use glam::Vec3;
use std::path::Path;

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
    /// Every compression, in the order of [`ExrCompression::NAMES`].
    pub const ALL: [ExrCompression; 3] = [
        ExrCompression::Zip,
        ExrCompression::Rle,
        ExrCompression::None,
    ];
    /// Their command-line names (`--exr-compression`).
    pub const NAMES: [&'static str; 3] = ["zip", "rle", "none"];

    /// The command-line name (`rle`).
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }
}

impl std::str::FromStr for ExrCompression {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let i = Self::NAMES.iter().position(|n| *n == s).ok_or_else(|| {
            format!(
                "`{s}` is not an EXR compression (allowed: {})",
                Self::NAMES.join(", ")
            )
        })?;
        Ok(Self::ALL[i])
    }
}

impl ExrCompression {
    /// The exr crate's encoding, always with chunks in increasing order: the crate's parallel
    /// compressor writes them in the order its threads finish unless a line order is set, so
    /// equal pixels could give different bytes run to run.
    fn encoding(self) -> exr::prelude::Encoding {
        use exr::prelude::Encoding;
        let base = match self {
            ExrCompression::Zip => Encoding::SMALL_LOSSLESS,
            ExrCompression::Rle => Encoding::FAST_LOSSLESS,
            ExrCompression::None => Encoding::UNCOMPRESSED,
        };
        Encoding {
            line_order: exr::prelude::LineOrder::Increasing,
            ..base
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
    let mut bytes = std::io::Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .to_buffered(&mut bytes)
        .map_err(|e| ImageError::ExrWrite {
            path: name.clone(),
            message: e.to_string(),
        })?;
    let mut bytes = bytes.into_inner();
    sort_header_attributes(&mut bytes).map_err(|message| ImageError::ExrWrite {
        path: name.clone(),
        message,
    })?;
    stage(path, |out| {
        std::io::Write::write_all(out, &bytes).map_err(|source| ImageError::Io {
            path: name.clone(),
            source,
        })
    })
}

/// Sorts the attributes of a single-part EXR's header by name, in place, so that equal input
/// gives equal bytes: the exr crate keeps the non-standard attributes (our `meta`) in a
/// `HashMap` and writes them in its per-process random order. OpenEXR's own library writes
/// them sorted by name too (its header is a `std::map`).
///
/// The header (OpenEXR file layout: magic number, 4-byte version and flags, then attributes
/// `name\0 type\0 size:i32 value` up to a lone `\0`) keeps its length, so the offset table
/// after it stays valid. Multi-part files (flag bit 12), which xylem does not write, are refused.
fn sort_header_attributes(bytes: &mut [u8]) -> Result<(), String> {
    const MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];
    if bytes.len() < 8 || bytes[..4] != MAGIC {
        return Err("the encoder's output is not an OpenEXR stream".into());
    }
    if bytes[4..8].try_into().map(u32::from_le_bytes).unwrap_or(0) & 0x1000 != 0 {
        return Err("multi-part EXR headers are not sorted".into());
    }
    let truncated = || "the encoder's header is truncated".to_string();
    let nul = |from: usize| -> Result<usize, String> {
        let rest = bytes.get(from..).ok_or_else(truncated)?;
        Ok(from + rest.iter().position(|&b| b == 0).ok_or_else(truncated)?)
    };
    // (start, end of name, end) of each attribute.
    let mut attrs = Vec::new();
    let mut at = 8;
    while *bytes.get(at).ok_or_else(truncated)? != 0 {
        let name_end = nul(at)?;
        let type_end = nul(name_end + 1)?;
        let size = bytes
            .get(type_end + 1..type_end + 5)
            .ok_or_else(truncated)?;
        let size = i32::from_le_bytes(size.try_into().unwrap());
        let end = type_end + 5 + usize::try_from(size).map_err(|_| truncated())?;
        if end > bytes.len() {
            return Err(truncated());
        }
        attrs.push((at, name_end, end));
        at = end;
    }
    attrs.sort_by(|a, b| bytes[a.0..a.1].cmp(&bytes[b.0..b.1]));
    let sorted: Vec<u8> = attrs
        .iter()
        .flat_map(|&(start, _, end)| bytes[start..end].iter().copied())
        .collect();
    bytes[8..at].copy_from_slice(&sorted);
    Ok(())
}

/// Text attributes of an EXR header, (name, value): e.g. `("spp", "64")`.
pub type ExrMeta<'a> = &'a [(&'a str, String)];

/// An EXR text attribute in printable ASCII, every other character escaped as `\u{f1}`:
/// OpenEXR stores bytes with no encoding named, and its Python bindings refuse non-UTF-8 ones
/// (a Latin-1 `ñ`), so only ASCII reads the same everywhere; the escape keeps the name.
fn exr_text(s: &str) -> exr::prelude::Text {
    let mut ascii = String::with_capacity(s.len());
    for c in s.chars() {
        if c.is_ascii() && !c.is_ascii_control() {
            ascii.push(c);
        } else {
            ascii += &format!("\\u{{{:x}}}", c as u32);
        }
    }
    exr::prelude::Text::new_or_panic(ascii)
}

/// The error of an EXR that could not be read.
fn exr_read_failed(path: &Path, message: impl ToString) -> ImageError {
    ImageError::ExrRead {
        path: path.display().to_string(),
        message: message.to_string(),
    }
}

/// Opens an EXR and reads its headers, refusing before any pixel (or offset table) is read a
/// file that is not a regular file of at most
/// [`MAX_IMAGE_BYTES`](crate::resources::MAX_IMAGE_BYTES) or a layer whose declared size fails
/// [`check_image`](crate::resources::check_image) with 8 bytes per channel (the decoded
/// samples and a float copy of them) plus `extra_bytes_per_pixel` (what the caller builds).
/// Every layer's declared size must also pass `size_ok` (the size the caller expects).
fn open_exr(
    path: &Path,
    extra_bytes_per_pixel: u64,
    size_ok: SizeCheck,
) -> Result<exr::block::reader::Reader<std::io::BufReader<std::fs::File>>, ImageError> {
    use crate::resources::{check_image, open_regular, MAX_IMAGE_BYTES};
    use std::io::{BufReader, Seek};
    let fail = |message: String| exr_read_failed(path, message);
    let mut file = open_regular(path, MAX_IMAGE_BYTES).map_err(|e| fail(e.reason()))?;
    let meta = exr::meta::MetaData::read_from_buffered(BufReader::new(&file), false)
        .map_err(|e| fail(e.to_string()))?;
    for h in &meta.headers {
        let bytes = 8 * h.channels.list.len() as u64 + extra_bytes_per_pixel;
        let (w, ht) = (h.layer_size.width(), h.layer_size.height());
        let side = |v: usize| u32::try_from(v).unwrap_or(u32::MAX);
        size_ok(side(w), side(ht)).map_err(fail)?;
        check_image(path, w as u64, ht as u64, bytes).map_err(|e| fail(e.reason()))?;
    }
    file.rewind().map_err(|e| fail(e.to_string()))?;
    exr::block::read(BufReader::new(file), false).map_err(|e| fail(e.to_string()))
}

/// Reads the RGB channels of the first layer of an EXR (alpha ignored). The declared size is
/// checked before decoding. [`Image::read`] reads an `.exr` through it.
pub(crate) fn read_exr_rgb(path: &Path) -> Result<Image, ImageError> {
    read_exr_rgb_checked(path, &any_size)
}

/// [`read_exr_rgb`] refusing, before decoding, a layer whose declared size fails `size_ok`.
pub(crate) fn read_exr_rgb_checked(path: &Path, size_ok: SizeCheck) -> Result<Image, ImageError> {
    // The glob brings the exr crate's own `Image`; ours is `super::Image` here.
    use exr::prelude::*;
    let chunks = open_exr(path, std::mem::size_of::<Vec3>() as u64, size_ok)?;
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .rgba_channels(
            |res, _: &RgbaChannels| {
                let side = |v: usize| u32::try_from(v).unwrap_or(u32::MAX);
                let pixels = vec![Vec3::ZERO; res.width() * res.height()];
                super::Image::new(side(res.width()), side(res.height()), pixels)
            },
            |img: &mut super::Image, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
                let w = img.width as usize;
                img.pixels[pos.y() * w + pos.x()] = Vec3::new(r, g, b);
            },
        )
        .first_valid_layer()
        .all_attributes()
        .from_chunks(chunks)
        .map_err(|e| exr_read_failed(path, e))?;
    Ok(img.layer_data.channel_data.pixels)
}

/// The first layer of an EXR with every channel and attribute (size checked by [`open_exr`]).
fn read_exr_layer(
    path: &Path,
) -> Result<exr::prelude::Layer<exr::prelude::AnyChannels<exr::prelude::FlatSamples>>, ImageError> {
    use exr::prelude::*;
    let chunks = open_exr(path, 0, &any_size)?;
    let img = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_chunks(chunks)
        .map_err(|e| exr_read_failed(path, e))?;
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Every compression xylem offers; the match fails to compile when one is added and not
    /// listed here.
    fn every_compression() -> [ExrCompression; 3] {
        let all = [
            ExrCompression::Zip,
            ExrCompression::Rle,
            ExrCompression::None,
        ];
        for c in all {
            match c {
                ExrCompression::Zip | ExrCompression::Rle | ExrCompression::None => {}
            }
        }
        all
    }

    /// A 200×150 image of fixed-seed noise (several ZIP blocks and RLE tiles) and a depth layer.
    fn noisy_layers() -> (u32, u32, Vec<ExrLayer<'static>>) {
        let (w, h) = (200u32, 150u32);
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 40) as f32 / (1u64 << 24) as f32
        };
        let n = (w * h) as usize;
        let rgb: Vec<f32> = (0..3 * n).map(|_| next()).collect();
        let depth: Vec<f32> = (0..n)
            .map(|i| if i % 7 == 0 { f32::INFINITY } else { i as f32 })
            .collect();
        let layers = vec![
            ExrLayer {
                name: "",
                channels: &["R", "G", "B"],
                data: rgb,
            },
            ExrLayer {
                name: "depth",
                channels: &["Z"],
                data: depth,
            },
        ];
        (w, h, layers)
    }

    #[test]
    fn every_compression_reads_back_bit_identically() {
        let dir = tempfile::tempdir().unwrap();
        let e = dir.path().join("t.exr");
        let (w, h, layers) = noisy_layers();
        for c in every_compression() {
            write_exr_layers_with(&e, w, h, &layers, c, &[]).unwrap();
            let img = read_exr_rgb(&e).unwrap();
            assert_eq!((img.width, img.height), (w, h), "{c:?}");
            let flat: Vec<f32> = img.pixels.iter().flat_map(|p| p.to_array()).collect();
            assert!(flat == layers[0].data, "{c:?}: RGB differs");
            let ch = read_exr_channels(&e).unwrap();
            let z = ch.iter().find(|(n, _)| n == "depth.Z").unwrap();
            assert!(z.1 == layers[1].data, "{c:?}: depth differs");
        }
    }

    #[test]
    fn equal_input_gives_equal_bytes_for_every_compression() {
        let dir = tempfile::tempdir().unwrap();
        let (w, h, layers) = noisy_layers();
        // Eight text attributes: in the exr crate's random HashMap order two writes would agree
        // only by chance (1 in 8! orders).
        let meta: Vec<(&str, String)> = [
            "scene", "spp", "seed", "camera", "quality", "light", "crc", "frame",
        ]
        .iter()
        .enumerate()
        .map(|(i, k)| (*k, format!("value {i}")))
        .collect();
        for c in every_compression() {
            let files: Vec<Vec<u8>> = (0..3)
                .map(|k| {
                    let p = dir.path().join(format!("{c:?}_{k}.exr"));
                    write_exr_layers_with(&p, w, h, &layers, c, &meta).unwrap();
                    std::fs::read(&p).unwrap()
                })
                .collect();
            for (k, f) in files.iter().enumerate().skip(1) {
                let differ = f.iter().zip(&files[0]).filter(|(a, b)| a != b).count();
                assert!(
                    f.len() == files[0].len() && differ == 0,
                    "{c:?}: write {k} has {} bytes, {differ} of them differ from write 0 ({} bytes)",
                    f.len(),
                    files[0].len()
                );
            }
            let text = read_exr_text(&dir.path().join(format!("{c:?}_0.exr"))).unwrap();
            assert_eq!(text.len(), 1 + meta.len(), "{c:?}: {text:?}");
        }
    }

    #[test]
    fn header_sorting_refuses_what_is_not_a_single_part_exr() {
        assert!(sort_header_attributes(&mut [0u8; 4]).is_err());
        assert!(sort_header_attributes(&mut b"not an exr file at all".to_vec()).is_err());
        // Magic and version, then an attribute cut short.
        let mut cut = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
        cut.extend_from_slice(b"name\0text\0\x10\0\0\0ab");
        assert!(sort_header_attributes(&mut cut).is_err());
        let mut multi = vec![0x76, 0x2f, 0x31, 0x01, 2, 0x10, 0, 0, 0];
        assert!(sort_header_attributes(&mut multi).is_err());
        // Two attributes out of order are swapped; the lone NUL after them ends the header.
        let mut two = vec![0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0];
        two.extend_from_slice(b"zz\0t\0\x01\0\0\0Zaa\0t\0\x02\0\0\0AA\0rest");
        sort_header_attributes(&mut two).unwrap();
        assert_eq!(&two[8..], b"aa\0t\0\x02\0\0\0AAzz\0t\0\x01\0\0\0Z\0rest");
    }
}
