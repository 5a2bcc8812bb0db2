//! Planar cuts through a wood volume (the three principal planes of Liu et al. 2016 Fig. 3):
//! transverse (xy, end grain), radial (xz through the pith, quartersawn) and tangential (yz off the
//! pith, flat-sawn). Pure functions; the CLI and the notes images use them.

use super::{Needs, WoodVolume};
use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// A cutting plane in tree space (pith along z).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Plane {
    /// z = offset: transverse (end-grain) cut.
    Xy,
    /// y = offset: radial cut when the offset is 0 (through the pith).
    Xz,
    /// x = offset: tangential cut at distance `offset` from the pith.
    Yz,
}

impl Plane {
    /// Tree-space point of in-plane coordinates `uv` on the plane at `offset`.
    #[inline]
    pub fn point(self, uv: Vec2, offset: f32) -> Vec3 {
        match self {
            Plane::Xy => Vec3::new(uv.x, uv.y, offset),
            Plane::Xz => Vec3::new(uv.x, offset, uv.y),
            Plane::Yz => Vec3::new(offset, uv.x, uv.y),
        }
    }

    /// Unit normal of the plane.
    pub fn normal(self) -> Vec3 {
        match self {
            Plane::Xy => Vec3::Z,
            Plane::Xz => Vec3::Y,
            Plane::Yz => Vec3::X,
        }
    }
}

/// A square window on a plane: `center` in in-plane coordinates, `size` its side (mm).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Slice {
    pub plane: Plane,
    pub offset: f32,
    pub center: Vec2,
    pub size: f32,
}

impl Slice {
    /// The cut a person expects for each plane: the end grain centred on the pith, the radial cut
    /// from near the pith outwards, the tangential cut `size` from the pith.
    pub fn standard(plane: Plane, size: f32) -> Slice {
        let (offset, center) = match plane {
            Plane::Xy => (0.0, Vec2::ZERO),
            Plane::Xz => (0.0, Vec2::new(0.1 * size + 0.5 * size, 0.0)),
            Plane::Yz => (1.0 * size, Vec2::ZERO),
        };
        Slice {
            plane,
            offset,
            center,
            size,
        }
    }

    /// Tree-space point at the centre of pixel (i, j) of a `res`×`res` image (row 0 at the top).
    #[inline]
    pub fn pixel_point(&self, i: u32, j: u32, res: u32) -> Vec3 {
        let u = ((i as f32 + 0.5) / res as f32 - 0.5) * self.size;
        let v = (0.5 - (j as f32 + 0.5) / res as f32) * self.size;
        self.plane.point(self.center + Vec2::new(u, v), self.offset)
    }
}

/// Render a cut: diffuse colour per pixel, optionally with a fibre highlight as seen with light and
/// eye along the cut's normal: a fibre at angle ψ out of the plane reflects like the Marschner
/// lobe's Gaussian, ∝ exp(−ψ² / 2β²) with the texel's highlight width β, tinted by the fibre
/// colour. That makes the figure of curly, quilted and interlocked woods visible in a flat image.
pub fn render_slice(volume: &WoodVolume, slice: &Slice, res: u32, shade_fibers: bool) -> Vec<Vec3> {
    let needs = if shade_fibers {
        Needs::COLOR_FIBERS
    } else {
        Needs::COLOR
    };
    let n = slice.plane.normal();
    (0..res * res)
        .into_par_iter()
        .map(|k| {
            let t = volume.eval(slice.pixel_point(k % res, k / res, res), needs);
            if shade_fibers {
                let psi = crate::math::safe_asin(t.fiber_dir.dot(n).abs());
                let beta = t.highlight_width.max(1e-3);
                let lobe = (-psi * psi / (2.0 * beta * beta)).exp();
                0.8 * t.diffuse + 0.4 * lobe * t.fiber_color
            } else {
                t.diffuse
            }
        })
        .collect()
}
