//! The two in-memory pictures: [`Image`], linear RGB floats (what renders, textures and captures
//! are before they become files), read and written as EXR or PNG by the file's extension; and
//! [`Rgb8`], 8-bit sRGB bytes (what a PNG holds, and contact sheets are composed of).

use super::exr::{read_exr_rgb_checked, stage_exr_layers, ExrCompression, ExrLayer};
use super::file::{commit, ImageError};
use super::png::{read_png_linear, stage_png_linear};
use super::srgb::Srgb8;
use crate::output::Staged;
use crate::resources::{any_size, SizeCheck};
use glam::Vec3;
use std::path::Path;

/// A linear RGB image, row-major, top row first.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear RGB, `width × height` of them.
    pub pixels: Vec<Vec3>,
}

/// The file formats of [`Image::read`] and [`Image::write`], by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Format {
    /// `.exr`: 32-bit float RGB, the values as they are.
    Exr,
    /// `.png`: 8-bit sRGB-encoded, clamped to [0, 1].
    Png,
}

impl Format {
    /// The format `path`'s extension names (case-insensitive), or why there is none.
    fn of(path: &Path) -> Result<Format, ImageError> {
        let ext = (path.extension().and_then(|e| e.to_str()))
            .unwrap_or("")
            .to_ascii_lowercase();
        match ext.as_str() {
            "exr" => Ok(Format::Exr),
            "png" => Ok(Format::Png),
            other => Err(ImageError::Invalid {
                path: path.display().to_string(),
                what: format!("extension `{other}` (allowed .exr, .png)"),
            }),
        }
    }
}

impl Image {
    /// A `width × height` image of `pixels` (row-major, top row first).
    pub fn new(width: u32, height: u32, pixels: Vec<Vec3>) -> Self {
        Image {
            width,
            height,
            pixels,
        }
    }

    /// Reads an `.exr` (the first layer's R, G, B; alpha ignored) or a `.png` (8 or 16 bits,
    /// sRGB-decoded; grey repeated, alpha dropped). The declared size is checked before decoding.
    pub fn read(path: &Path) -> Result<Image, ImageError> {
        Self::read_checked(path, &any_size)
    }

    /// [`Image::read`] refusing, before decoding, a declared size that fails `size_ok`.
    pub(crate) fn read_checked(path: &Path, size_ok: SizeCheck) -> Result<Image, ImageError> {
        match Format::of(path)? {
            Format::Exr => read_exr_rgb_checked(path, size_ok),
            Format::Png => {
                read_png_linear(path, true, size_ok).map_err(|what| ImageError::Invalid {
                    path: path.display().to_string(),
                    what,
                })
            }
        }
    }

    /// Writes the image whole or not at all: `.exr` as 32-bit float RGB (ZIP), `.png` as an
    /// sRGB-tagged 8-bit PNG.
    pub fn write(&self, path: &Path) -> Result<(), ImageError> {
        commit(self.stage(path)?)
    }

    /// [`Image::write`] staged, to [`commit`] later.
    pub(crate) fn stage(&self, path: &Path) -> Result<Staged, ImageError> {
        match Format::of(path)? {
            Format::Exr => {
                let layer = ExrLayer {
                    name: "",
                    channels: &["R", "G", "B"],
                    data: self.pixels.iter().flat_map(|p| p.to_array()).collect(),
                };
                let (w, h) = (self.width, self.height);
                stage_exr_layers(path, w, h, &[layer], ExrCompression::Zip, &[])
            }
            Format::Png => stage_png_linear(path, self.width, self.height, &self.pixels, 0.0),
        }
    }

    /// The 8-bit sRGB picture of the image scaled by `2^exposure` (exact encoding,
    /// [`Srgb8`]).
    pub fn to_rgb8(&self, exposure: f32) -> Rgb8 {
        Rgb8 {
            width: self.width,
            height: self.height,
            data: super::srgb::to_srgb8(&self.pixels, exposure),
        }
    }
}

/// An 8-bit sRGB image (RGB, row-major, top row first): what a PNG holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Rgb8 {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// RGB bytes, 3 per pixel.
    pub data: Vec<u8>,
}

impl Rgb8 {
    /// Writes the picture as an sRGB-tagged PNG, whole or not at all (`png::write_png_rgb8`).
    pub fn write_png(&self, path: &Path) -> Result<(), ImageError> {
        super::png::write_png_rgb8(path, self.width, self.height, &self.data)
    }

    /// A `width × height` image filled with one colour.
    pub fn filled(width: u32, height: u32, rgb: [u8; 3]) -> Self {
        let data = rgb
            .iter()
            .copied()
            .cycle()
            .take(width as usize * height as usize * 3)
            .collect();
        Rgb8 {
            width,
            height,
            data,
        }
    }

    /// The pixels as `[r, g, b]`, row-major, top row first.
    pub(crate) fn pixels(&self) -> impl ExactSizeIterator<Item = [u8; 3]> + '_ {
        self.data.chunks_exact(3).map(|p| [p[0], p[1], p[2]])
    }

    /// Sets pixel `(x, y)`; outside the image, nothing.
    pub(crate) fn put(&mut self, x: u32, y: u32, rgb: [u8; 3]) {
        if x < self.width && y < self.height {
            let i = (y as usize * self.width as usize + x as usize) * 3;
            self.data[i..i + 3].copy_from_slice(&rgb);
        }
    }

    /// Copies `src` with its top-left corner at `(x, y)`, clipping what falls outside.
    pub fn blit(&mut self, src: &Rgb8, x: u32, y: u32) {
        for sy in 0..src.height {
            for sx in 0..src.width {
                let i = (sy as usize * src.width as usize + sx as usize) * 3;
                let p = [src.data[i], src.data[i + 1], src.data[i + 2]];
                self.put(x + sx, y + sy, p);
            }
        }
    }

    /// The image shrunk by the smallest whole factor that makes it at most `max_width` wide,
    /// averaging each factor × factor block in linear light (averaging sRGB codes would darken edges).
    pub(crate) fn shrink_to_width(&self, max_width: u32) -> Rgb8 {
        let f = shrink_factor(self.width, max_width);
        if f == 1 {
            return self.clone();
        }
        let (w, h) = ((self.width / f).max(1), (self.height / f).max(1));
        let mut out = Rgb8::filled(w, h, [0, 0, 0]);
        let enc = Srgb8::new();
        for ty in 0..h {
            for tx in 0..w {
                let mut acc = [0.0f32; 3];
                let mut n = 0.0f32;
                for y in ty * f..((ty + 1) * f).min(self.height) {
                    for x in tx * f..((tx + 1) * f).min(self.width) {
                        let i = (y as usize * self.width as usize + x as usize) * 3;
                        for (a, &v) in acc.iter_mut().zip(&self.data[i..i + 3]) {
                            *a += enc.decode(v);
                        }
                        n += 1.0;
                    }
                }
                let px = acc.map(|a| enc.encode(a / n));
                out.put(tx, ty, px);
            }
        }
        out
    }
}

/// The whole factor [`Rgb8::shrink_to_width`] divides a `width`-wide image by.
fn shrink_factor(width: u32, max_width: u32) -> u32 {
    width.div_ceil(max_width.max(1)).max(1)
}

/// The size [`Rgb8::shrink_to_width`] gives a `width × height` image.
pub(crate) fn shrunk_size(width: u32, height: u32, max_width: u32) -> (u32, u32) {
    match shrink_factor(width, max_width) {
        1 => (width, height),
        f => ((width / f).max(1), (height / f).max(1)),
    }
}
