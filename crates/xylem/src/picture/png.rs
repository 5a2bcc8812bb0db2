//! PNG files: 8-bit RGB images (sRGB-tagged colour or untagged data maps), previews of linear
//! buffers, looping animated PNGs (APNG), and reading 8-bit PNGs back. Every file is written
//! whole or not at all through [`super::file::stage`].

use super::file::{commit, stage, ImageError};
use super::image::{Image, Rgb8};
use super::srgb::{srgb_to_linear, to_srgb8};
use crate::output::Staged;
use crate::resources::{any_size, SizeCheck};
use glam::Vec3;
use std::path::Path;

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

/// An 8-bit RGB encoder of `width × height` with the colour-space chunk of `tag`.
fn encoder<W: std::io::Write>(
    out: W,
    width: u32,
    height: u32,
    tag: PngTag,
) -> png::Encoder<'static, W> {
    let mut enc = png::Encoder::new(out, width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    if tag == PngTag::Srgb {
        enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    }
    enc
}

/// Encodes 8-bit RGB bytes (row-major, top row first) as a PNG into `out`.
pub(crate) fn encode_png_rgb8(
    out: impl std::io::Write,
    width: u32,
    height: u32,
    rgb: &[u8],
    tag: PngTag,
) -> Result<(), png::EncodingError> {
    encode_png_rgb8_text(out, width, height, rgb, tag, &[])
}

/// [`encode_png_rgb8`] with `tEXt` chunks (keyword, Latin-1 text), e.g. who wrote the file.
pub(crate) fn encode_png_rgb8_text(
    out: impl std::io::Write,
    width: u32,
    height: u32,
    rgb: &[u8],
    tag: PngTag,
    text: &[(&str, &str)],
) -> Result<(), png::EncodingError> {
    let mut enc = encoder(out, width, height, tag);
    for (k, v) in text {
        enc.add_text_chunk(k.to_string(), v.to_string())?;
    }
    let mut w = enc.write_header()?;
    w.write_image_data(rgb)?;
    w.finish()
}

/// An sRGB-tagged PNG with `tEXt` chunks, staged beside `path` to [`commit`] later.
pub(crate) fn stage_png_rgb8_text(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
    text: &[(&str, &str)],
) -> Result<Staged, ImageError> {
    check_rgb8(path, width, height, rgb)?;
    stage(path, |out| {
        encode_png_rgb8_text(out, width, height, rgb, PngTag::Srgb, text).map_err(png_error(path))
    })
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

fn png_error(path: &Path) -> impl Fn(png::EncodingError) -> ImageError + '_ {
    move |source| ImageError::Png {
        path: path.display().to_string(),
        source,
    }
}

/// Encodes 8-bit RGB with the colour-space chunk of `tag` into a uniquely named temporary file
/// beside `path`, to [`commit`] later.
pub(crate) fn stage_png_tagged(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
    tag: PngTag,
) -> Result<Staged, ImageError> {
    check_rgb8(path, width, height, rgb)?;
    stage(path, |out| {
        encode_png_rgb8(out, width, height, rgb, tag).map_err(png_error(path))
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

/// Writes 8-bit sRGB bytes as an sRGB-tagged PNG, whole or not at all.
pub fn write_png_rgb8(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), ImageError> {
    commit(stage_png_rgb8(path, width, height, rgb)?)
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

/// Writes `frames` (all the same size) as a looping, sRGB-tagged animated PNG (APNG: `acTL`,
/// `fcTL` and `fdAT` chunks), `fps` frames per second, whole or not at all.
pub fn write_apng(path: &Path, frames: &[Rgb8], fps: u16) -> Result<(), ImageError> {
    let invalid = |what: String| ImageError::Invalid {
        path: path.display().to_string(),
        what,
    };
    let first = frames
        .first()
        .ok_or_else(|| invalid("an animation needs at least one frame".into()))?;
    for (k, f) in frames.iter().enumerate() {
        if (f.width, f.height) != (first.width, first.height) {
            return Err(invalid(format!(
                "frame {k} is {}x{}, frame 0 {}x{}",
                f.width, f.height, first.width, first.height
            )));
        }
        check_rgb8(path, f.width, f.height, &f.data)?;
    }
    let staged = stage(path, |out| {
        let err = png_error(path);
        let mut enc = encoder(out, first.width, first.height, PngTag::Srgb);
        enc.set_animated(frames.len() as u32, 0).map_err(&err)?;
        enc.set_frame_delay(1, fps.max(1)).map_err(&err)?;
        let mut w = enc.write_header().map_err(&err)?;
        for f in frames {
            w.write_image_data(&f.data).map_err(&err)?;
        }
        w.finish().map_err(&err)
    })?;
    commit(staged)
}

/// Frames or bands [`write_apng_streamed`] and [`write_png_bands`] make at once (in parallel)
/// before encoding them: two per worker keeps the workers busy and memory flat.
fn stream_chunk() -> usize {
    2 * rayon::current_num_threads().max(1)
}

/// [`write_apng`] of `count` frames of `width × height` made one chunk at a time by `frame(k)`
/// (in parallel within a chunk), so a long sequence is never held whole.
pub(crate) fn write_apng_streamed(
    path: &Path,
    (width, height): (u32, u32),
    count: usize,
    fps: u16,
    frame: impl Fn(usize) -> Result<Rgb8, ImageError> + Sync,
) -> Result<(), ImageError> {
    use rayon::prelude::*;
    if count == 0 {
        return Err(ImageError::Invalid {
            path: path.display().to_string(),
            what: "an animation needs at least one frame".into(),
        });
    }
    let staged = stage(path, |out| {
        let err = png_error(path);
        let mut enc = encoder(out, width, height, PngTag::Srgb);
        enc.set_animated(count as u32, 0).map_err(&err)?;
        enc.set_frame_delay(1, fps.max(1)).map_err(&err)?;
        let mut w = enc.write_header().map_err(&err)?;
        for start in (0..count).step_by(stream_chunk()) {
            let chunk: Vec<Rgb8> = (start..(start + stream_chunk()).min(count))
                .into_par_iter()
                .map(&frame)
                .collect::<Result<_, _>>()?;
            for (k, f) in chunk.iter().enumerate() {
                if (f.width, f.height) != (width, height) {
                    return Err(ImageError::Invalid {
                        path: path.display().to_string(),
                        what: format!(
                            "frame {} is {}x{}, the animation {width}x{height}",
                            start + k,
                            f.width,
                            f.height
                        ),
                    });
                }
                check_rgb8(path, f.width, f.height, &f.data)?;
                w.write_image_data(&f.data).map_err(&err)?;
            }
        }
        w.finish().map_err(&err)
    })?;
    commit(staged)
}

/// Writes an sRGB-tagged PNG of `width × height` made of `bands` horizontal bands stacked top to
/// bottom, each made by `band(k)` (full width; their heights must add up to `height`), a chunk
/// at a time in parallel, so a tall image (a long sweep's contact sheet) is never held whole.
pub fn write_png_bands(
    path: &Path,
    (width, height): (u32, u32),
    bands: usize,
    band: impl Fn(usize) -> Result<Rgb8, ImageError> + Sync,
) -> Result<(), ImageError> {
    use rayon::prelude::*;
    use std::io::Write;
    let invalid = |what: String| ImageError::Invalid {
        path: path.display().to_string(),
        what,
    };
    let staged = stage(path, |out| {
        let err = png_error(path);
        let mut w = encoder(out, width, height, PngTag::Srgb)
            .write_header()
            .map_err(&err)?;
        let mut rows = w.stream_writer().map_err(&err)?;
        let mut written = 0u64;
        for start in (0..bands).step_by(stream_chunk()) {
            let chunk: Vec<Rgb8> = (start..(start + stream_chunk()).min(bands))
                .into_par_iter()
                .map(&band)
                .collect::<Result<_, _>>()?;
            for b in &chunk {
                check_rgb8(path, b.width, b.height, &b.data)?;
                written += b.height as u64;
                if b.width != width || written > height as u64 {
                    return Err(invalid(format!(
                        "a band of {}x{} does not fit the {width}x{height} image",
                        b.width, b.height
                    )));
                }
                rows.write_all(&b.data).map_err(|source| ImageError::Io {
                    path: path.display().to_string(),
                    source,
                })?;
            }
        }
        if written != height as u64 {
            return Err(invalid(format!(
                "bands of {written} rows in all, the image {height}"
            )));
        }
        rows.finish().map_err(&err)?;
        w.finish().map_err(&err)
    })?;
    commit(staged)
}

/// The most bytes the PNG decoder may allocate besides the image itself (chunk buffers, text,
/// ICC profiles): the png crate's default of 64 MiB, stated here so that it stays bounded.
const PNG_DECODER_BYTES: usize = 64 << 20;

/// A PNG decoded into one buffer after its header's size was checked: the declared size must
/// pass `size_ok` (the size the caller expects, e.g. the camera's for a fit's frame), and the
/// decoded buffer plus `extra_bytes_per_pixel` (what the caller builds from it) must pass
/// [`check_image`](crate::resources::check_image), before anything is allocated.
/// Errors name no file: callers do.
pub(crate) fn decode_png(
    path: &Path,
    input: impl std::io::Read,
    transformations: png::Transformations,
    extra_bytes_per_pixel: u64,
    size_ok: SizeCheck,
) -> Result<(png::OutputInfo, Vec<u8>), String> {
    decode_png_text(path, input, transformations, extra_bytes_per_pixel, size_ok)
        .map(|(i, b, _)| (i, b))
}

/// A PNG's `tEXt` chunks: (keyword, text).
pub(crate) type PngText = Vec<(String, String)>;

/// [`decode_png`] with the `tEXt` chunks read before the image data.
pub(crate) fn decode_png_text(
    path: &Path,
    input: impl std::io::Read,
    transformations: png::Transformations,
    extra_bytes_per_pixel: u64,
    size_ok: SizeCheck,
) -> Result<(png::OutputInfo, Vec<u8>, PngText), String> {
    let limits = png::Limits {
        bytes: PNG_DECODER_BYTES,
    };
    let mut dec = png::Decoder::new_with_limits(std::io::BufReader::new(input), limits);
    dec.set_transformations(transformations);
    let mut reader = dec.read_info().map_err(|e| e.to_string())?;
    let (w, h) = (reader.info().width, reader.info().height);
    let text: PngText = (reader.info().uncompressed_latin1_text.iter())
        .map(|t| (t.keyword.clone(), t.text.clone()))
        .collect();
    let (color, depth) = reader.output_color_type();
    let sample_bytes = if depth == png::BitDepth::Sixteen {
        2
    } else {
        1
    };
    let decoded = color.samples() as u64 * sample_bytes;
    size_ok(w, h)?;
    crate::resources::check_image(path, w as u64, h as u64, decoded + extra_bytes_per_pixel)
        .map_err(|e| e.reason())?;
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buf).map_err(|e| e.to_string())?;
    buf.truncate(info.buffer_size());
    Ok((info, buf, text))
}

/// Opens `path` for [`decode_png`] (a regular file of at most
/// [`MAX_IMAGE_BYTES`](crate::resources::MAX_IMAGE_BYTES)).
pub(crate) fn open_png(path: &Path) -> Result<std::io::Take<std::fs::File>, String> {
    use crate::resources::{open_regular, MAX_IMAGE_BYTES};
    use std::io::Read;
    let file = open_regular(path, MAX_IMAGE_BYTES).map_err(|e| e.reason())?;
    Ok(file.take(MAX_IMAGE_BYTES))
}

/// Reads an 8-bit PNG as RGB: RGBA loses its alpha, grey is repeated in R, G and B, palettes
/// are expanded and 16-bit samples keep their high byte.
pub fn read_png_rgb8(path: &Path) -> Result<Rgb8, ImageError> {
    read_png_rgb8_checked(path, &any_size)
}

/// [`read_png_rgb8`] refusing, before decoding, a declared size that fails `size_ok`.
pub(crate) fn read_png_rgb8_checked(path: &Path, size_ok: SizeCheck) -> Result<Rgb8, ImageError> {
    let invalid = |what: String| ImageError::Invalid {
        path: path.display().to_string(),
        what,
    };
    let file = open_png(path).map_err(invalid)?;
    decode_rgb8(path, file, size_ok).map_err(invalid)
}

/// A PNG held in memory (e.g. one a glTF binary embeds) as 8-bit RGB, as [`read_png_rgb8`]
/// reads a file; `name` names it in errors.
pub fn decode_png_rgb8(name: &Path, bytes: &[u8]) -> Result<Rgb8, ImageError> {
    decode_rgb8(name, bytes, &any_size).map_err(|what| ImageError::Invalid {
        path: name.display().to_string(),
        what,
    })
}

/// [`read_png_rgb8`] of any byte source.
fn decode_rgb8(path: &Path, input: impl std::io::Read, size_ok: SizeCheck) -> Result<Rgb8, String> {
    let expand = png::Transformations::EXPAND | png::Transformations::STRIP_16;
    let (info, buf) = decode_png(path, input, expand, 3, size_ok)?;
    Ok(decoded_rgb8(&info, buf))
}

/// A decoded 8-bit PNG (`Transformations::EXPAND`) as an [`Rgb8`], through [`rgb_samples`].
pub(crate) fn decoded_rgb8(info: &png::OutputInfo, buf: Vec<u8>) -> Rgb8 {
    let data = match info.color_type {
        // Already what an `Rgb8` holds: no copy.
        png::ColorType::Rgb => buf,
        _ => rgb_samples(info, &buf)
            .flat_map(|p| p.map(|v| v as u8))
            .collect(),
    };
    Rgb8 {
        width: info.width,
        height: info.height,
        data,
    }
}

/// The pixels of a PNG decoded with `Transformations::EXPAND` (so grey, grey and alpha, RGB or
/// RGBA, of 8 or 16 bits) as RGB samples: grey repeated in R, G and B, alpha dropped, 16-bit
/// samples whole. Every reader of PNG pixels goes through it.
pub(crate) fn rgb_samples<'a>(
    info: &png::OutputInfo,
    buf: &'a [u8],
) -> impl Iterator<Item = [u16; 3]> + 'a {
    let channels = info.color_type.samples();
    let sixteen = info.bit_depth == png::BitDepth::Sixteen;
    let bytes = if sixteen { 2 } else { 1 };
    buf.chunks_exact(channels * bytes).map(move |p| {
        let ch = |i: usize| match sixteen {
            true => u16::from_be_bytes([p[2 * i], p[2 * i + 1]]),
            false => p[i] as u16,
        };
        match channels {
            1 | 2 => [ch(0); 3],
            _ => [ch(0), ch(1), ch(2)],
        }
    })
}

/// The largest sample of a decoded PNG: 255, or 65535 for 16 bits.
pub(crate) fn sample_max(info: &png::OutputInfo) -> f32 {
    match info.bit_depth {
        png::BitDepth::Sixteen => 65535.0,
        _ => 255.0,
    }
}

/// An 8- or 16-bit PNG as a linear image, each sample v / (2^bits − 1), sRGB-decoded
/// (IEC 61966-2-1) when `srgb`. The declared size must pass `size_ok`.
pub(crate) fn read_png_linear(
    path: &Path,
    srgb: bool,
    size_ok: SizeCheck,
) -> Result<Image, String> {
    let (info, buf) = decode_png(
        path,
        open_png(path)?,
        png::Transformations::EXPAND,
        std::mem::size_of::<Vec3>() as u64,
        size_ok,
    )?;
    let max = sample_max(&info);
    let decode = |v: u16| match srgb {
        true => srgb_to_linear(v as f32 / max),
        false => v as f32 / max,
    };
    let pixels = (rgb_samples(&info, &buf))
        .map(|p| Vec3::from_array(p.map(decode)))
        .collect();
    Ok(Image::new(info.width, info.height, pixels))
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
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.png");
        let px = vec![Vec3::new(1.0, 0.5, 0.0); 6];
        write_png_linear(&p, 3, 2, &px, 0.0).unwrap();
        let img = read_png_rgb8(&p).unwrap();
        assert_eq!((img.width, img.height), (3, 2));
        // round(255 · encode(0.5)) = round(255 · 0.735357) = 188 (IEC 61966-2-1).
        assert_eq!(&img.data[..3], &[255, 188, 0]);
        let e = write_png_linear(&p, 4, 2, &px, 0.0).unwrap_err();
        assert!(
            matches!(
                e,
                ImageError::Size {
                    want: 8,
                    got: 6,
                    ..
                }
            ),
            "{e}"
        );
        // Only the final name is left: no temporary survives a write or a refused one.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn animated_png_holds_every_frame_and_refuses_mixed_sizes() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.png");
        let frames: Vec<Rgb8> = (0..3u8)
            .map(|k| Rgb8::filled(2, 2, [k * 100, 7, 255 - k]))
            .collect();
        write_apng(&p, &frames, 12).unwrap();
        let chunks = png_chunk_types(&std::fs::read(&p).unwrap());
        let count = |t: &str| chunks.iter().filter(|c| *c == t).count();
        assert_eq!((count("acTL"), count("fcTL"), count("fdAT")), (1, 3, 2));
        let mut r = png::Decoder::new(std::fs::File::open(&p).unwrap())
            .read_info()
            .unwrap();
        assert_eq!(r.info().animation_control.unwrap().num_frames, 3);
        let mut buf = vec![0; r.output_buffer_size()];
        for f in &frames {
            r.next_frame(&mut buf).unwrap();
            assert_eq!(buf, f.data);
        }
        let mut mixed = frames.clone();
        mixed.push(Rgb8::filled(3, 2, [0, 0, 0]));
        let e = write_apng(&p, &mixed, 12).unwrap_err();
        assert!(e.to_string().contains("frame 3 is 3x2"), "{e}");
        assert!(matches!(
            write_apng(&p, &[], 12),
            Err(ImageError::Invalid { .. })
        ));
        // The refused writes left the earlier animation whole.
        assert_eq!(read_png_rgb8(&p).unwrap(), frames[0]);
    }
}
