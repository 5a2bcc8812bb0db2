//! Planar slices of a solid function, for looking at textures, noises and (through the same
//! code) wood presets: a square window of side `size` centred on the axis, at `offset` along the
//! plane's normal, each pixel the mean over a regular grid of `samples × samples` points in it (a
//! box filter over the pixel: what a pixel of the slice shows, not the texture at one point,
//! which aliases wherever the texture has detail finer than a pixel), rows in parallel.

use glam::Vec3;
use rayon::prelude::*;
use std::str::FromStr;

/// The slicing plane; the image's right and up directions are the first and second axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plane {
    /// Image right = +x, up = +y; normal z.
    Xy,
    /// Image right = +x, up = +z; normal y.
    Xz,
    /// Image right = +y, up = +z; normal x.
    Yz,
}

/// The planes by their command-line names (parsed and printed from this one table).
const PLANES: [(Plane, &str); 3] = [(Plane::Xy, "xy"), (Plane::Xz, "xz"), (Plane::Yz, "yz")];

impl FromStr for Plane {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let s_low = s.to_ascii_lowercase();
        (PLANES.iter().find(|(_, n)| *n == s_low).map(|(p, _)| *p))
            .ok_or_else(|| format!("unknown plane `{s}`; valid planes: xy, xz, yz"))
    }
}

/// The command-line name (`xz`), not the Rust variant.
impl std::fmt::Display for Plane {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let name = PLANES
            .iter()
            .find(|(p, _)| p == self)
            .map_or("?", |(_, n)| n);
        f.write_str(name)
    }
}

/// A square slice: `res × res` pixels covering `size × size` (mm) centred on the plane's origin,
/// the plane at `offset` (mm) along its normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slice {
    /// Which plane.
    pub plane: Plane,
    /// Position of the plane along its normal (mm).
    pub offset: f32,
    /// Side of the square (mm).
    pub size: f32,
    /// Pixels along each side.
    pub res: u32,
    /// Samples along each side of a pixel, 1 to [`MAX_SLICE_SAMPLES`] (1: the pixel centre).
    pub samples: u32,
}

/// The most samples along a pixel's side a slice takes (256 per pixel).
pub const MAX_SLICE_SAMPLES: u32 = 16;

/// Samples along a pixel's side of `xylem texture` and the preset cuts: 16 per pixel, within
/// the error of notes/picture.md of a 16 × 16 supersampled slice at the README's sizes.
pub const DEFAULT_SLICE_SAMPLES: u32 = 4;

impl Slice {
    /// The point at the centre of pixel (column `i`, row `j`; row 0 at the top).
    pub fn point(&self, i: u32, j: u32) -> Vec3 {
        self.point_at(i as f32 + 0.5, j as f32 + 0.5)
    }

    /// The point at pixel coordinates (`x` right, `y` down; pixel (i, j) spans [i, i + 1] ×
    /// [j, j + 1]).
    fn point_at(&self, x: f32, y: f32) -> Vec3 {
        let step = self.size / self.res as f32;
        let a = x * step - 0.5 * self.size;
        let b = 0.5 * self.size - y * step;
        match self.plane {
            Plane::Xy => Vec3::new(a, b, self.offset),
            Plane::Xz => Vec3::new(a, self.offset, b),
            Plane::Yz => Vec3::new(self.offset, a, b),
        }
    }

    /// Each pixel's mean of `f` over its sample points (rows in parallel); row-major, top row
    /// first.
    pub fn render(&self, f: &(dyn Fn(Vec3) -> Vec3 + Sync)) -> Vec<Vec3> {
        self.render_rows(&|points, out| {
            for (p, o) in points.iter().zip(out) {
                *o = f(*p);
            }
        })
    }

    /// [`Slice::render`] with a batch function: `f(points, out)` fills the colours of a row of
    /// points (one row of sub-pixel samples at a time, rows of pixels in parallel), so a batch
    /// noise call can fill its SIMD lanes.
    pub fn render_rows(&self, f: &(dyn Fn(&[Vec3], &mut [Vec3]) + Sync)) -> Vec<Vec3> {
        let n = self.res as usize;
        let k = self.samples.clamp(1, MAX_SLICE_SAMPLES) as usize;
        let mut pixels = vec![Vec3::ZERO; n * n];
        pixels
            .par_chunks_mut(n.max(1))
            .enumerate()
            .for_each(|(j, row)| {
                // The sub-pixel grid's row `sy`: k points per pixel, the pixels side by side.
                let mut points = vec![Vec3::ZERO; n * k];
                let mut colours = vec![Vec3::ZERO; n * k];
                let mut sums = vec![Vec3::ZERO; n];
                for sy in 0..k {
                    let y = j as f32 + (sy as f32 + 0.5) / k as f32;
                    for (m, p) in points.iter_mut().enumerate() {
                        *p = self.point_at((m / k) as f32 + ((m % k) as f32 + 0.5) / k as f32, y);
                    }
                    f(&points, &mut colours);
                    for (s, c) in sums.iter_mut().zip(colours.chunks_exact(k)) {
                        *s += c.iter().copied().sum::<Vec3>();
                    }
                }
                let w = 1.0 / (k * k) as f32;
                for (o, s) in row.iter_mut().zip(sums) {
                    *o = s * w;
                }
            });
        pixels
    }
}

/// The first pixel (column, row) whose colour is not finite, if any.
pub fn first_non_finite(pixels: &[Vec3], res: u32) -> Option<(u32, u32)> {
    pixels
        .iter()
        .position(|c| !c.is_finite())
        .map(|k| ((k % res as usize) as u32, (k / res as usize) as u32))
}
