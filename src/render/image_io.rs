//! Writing images people look at: sRGB PNG previews of linear RGB buffers.

use glam::Vec3;
use std::io::BufWriter;
use std::path::Path;

/// Errors while writing an image, naming the file.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    #[error("cannot write image {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("cannot encode PNG {path}: {source}")]
    Png {
        path: String,
        source: png::EncodingError,
    },
    #[error("image {path}: buffer holds {got} pixels, {width}x{height} needs {want}")]
    Size {
        path: String,
        width: u32,
        height: u32,
        got: usize,
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

/// 8-bit sRGB bytes (RGB, row-major, top row first) of a linear buffer scaled by `2^exposure`.
pub fn to_srgb8(pixels: &[Vec3], exposure: f32) -> Vec<u8> {
    let scale = exposure.exp2();
    pixels
        .iter()
        .flat_map(|c| (*c * scale).to_array())
        .map(|v| (linear_to_srgb(v) * 255.0 + 0.5) as u8)
        .collect()
}

/// Writes 8-bit RGB bytes as a PNG. The file is written to a temporary name and renamed, so a
/// failure never leaves a half-written image behind.
pub fn write_png_rgb8(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), ImageError> {
    let name = path.display().to_string();
    let want = width as usize * height as usize;
    if rgb.len() != want * 3 {
        return Err(ImageError::Size {
            path: name,
            width,
            height,
            got: rgb.len() / 3,
            want,
        });
    }
    let tmp = path.with_extension("png.partial");
    let io = |source| ImageError::Io {
        path: name.clone(),
        source,
    };
    let file = std::fs::File::create(&tmp).map_err(io)?;
    let mut enc = png::Encoder::new(BufWriter::new(file), width, height);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    enc.set_source_srgb(png::SrgbRenderingIntent::Perceptual);
    let png_err = |source| ImageError::Png {
        path: name.clone(),
        source,
    };
    let mut w = enc.write_header().map_err(png_err)?;
    w.write_image_data(rgb).map_err(png_err)?;
    w.finish().map_err(png_err)?;
    std::fs::rename(&tmp, path).map_err(io)
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
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
