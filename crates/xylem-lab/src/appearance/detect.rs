//! The grain direction and cut of a measured board, read from its maps ([`detect_board`]).

use super::*;

/// What [`detect_board`] reads from a measured board's maps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DetectedBoard {
    /// The fibres run along the image columns (x): the mean |u_x| exceeds the mean |u_y|.
    pub grain_along_x: bool,
    /// Fraction of the face whose ring lines turn more than [`ARCH_TURN_DEG`] from the grain.
    pub arch_fraction: f64,
    /// 0 (flat-sawn) when `arch_fraction` exceeds [`FLAT_ARCH_FRACTION`], else 90 (quartersawn).
    pub ring_angle_deg: f32,
}

/// A ring line turned this far from the grain belongs to an arch (degrees).
pub const ARCH_TURN_DEG: f64 = 20.0;
/// Above this fraction of arch texels a face is flat-sawn. The measured boards give 0.12
/// (maple) and 0.07 (padauk), both quartersawn, and 0.47 (walnut1, flat-sawn with a cathedral)
/// at the scales of [`detect_board`] (notes/appearance.md).
pub const FLAT_ARCH_FRACTION: f64 = 0.25;

/// The grain direction and cut of a measured board in `dir`: grain from the fibre-axis map, cut
/// from the ring lines of the diffuse luminance. A flat-sawn face cuts the rings in arches whose
/// lines turn across the grain near their tips; a quartersawn face shows them as stripes along
/// it. The ring lines' direction is the structure tensor's (Bigün and Granlund 1987: the
/// Gaussian-weighted mean of ∇L ∇Lᵀ, whose major eigenvector is normal to the lines) of the
/// luminance smoothed over 1 mm (pores and fibre noise dropped), weighted over 2 mm; pitch
/// 0.25 mm as notes/measured.md assumes.
pub fn detect_board(dir: &Path) -> Result<DetectedBoard, String> {
    let board = MeasuredBoard::load(dir).map_err(|e| e.to_string())?;
    let n = board.fiber_axis.len().max(1) as f64;
    let (ux, uy) = board.fiber_axis.iter().fold((0.0, 0.0), |(x, y), u| {
        (x + u.x.abs() as f64 / n, y + u.y.abs() as f64 / n)
    });
    let grain_along_x = ux > uy;
    let (w, h) = (board.width as usize, board.height as usize);
    let lum: Vec<f64> = board.diffuse.iter().map(|c| luminance(*c) as f64).collect();
    let smooth = gaussian_blur(&lum, w, h, 4.0);
    let (mut gxx, mut gyy, mut gxy) = (vec![0.0; w * h], vec![0.0; w * h], vec![0.0; w * h]);
    for y in 0..h {
        for x in 0..w {
            let at = |x: usize, y: usize| smooth[y * w + x];
            let gx = (at((x + 1).min(w - 1), y) - at(x.saturating_sub(1), y)) * 0.5;
            let gy = (at(x, (y + 1).min(h - 1)) - at(x, y.saturating_sub(1))) * 0.5;
            let i = y * w + x;
            (gxx[i], gyy[i], gxy[i]) = (gx * gx, gy * gy, gx * gy);
        }
    }
    let (jxx, jyy, jxy) = (
        gaussian_blur(&gxx, w, h, 8.0),
        gaussian_blur(&gyy, w, h, 8.0),
        gaussian_blur(&gxy, w, h, 8.0),
    );
    // The gradient's mean direction (normal to the ring lines) against the across-grain axis:
    // the ring lines' turn from the grain.
    let turned = (0..w * h)
        .filter(|&i| {
            let (ja, jc) = if grain_along_x {
                (jxx[i], jyy[i])
            } else {
                (jyy[i], jxx[i])
            };
            let turn = 0.5 * (2.0 * jxy[i]).atan2(jc - ja);
            turn.abs().to_degrees() > ARCH_TURN_DEG
        })
        .count();
    let arch_fraction = turned as f64 / (w * h).max(1) as f64;
    Ok(DetectedBoard {
        grain_along_x,
        arch_fraction,
        ring_angle_deg: if arch_fraction > FLAT_ARCH_FRACTION {
            0.0
        } else {
            90.0
        },
    })
}

/// A separable Gaussian blur of standard deviation `sigma` texels, edges clamped.
fn gaussian_blur(v: &[f64], w: usize, h: usize, sigma: f64) -> Vec<f64> {
    let r = (3.0 * sigma).ceil() as isize;
    let k: Vec<f64> = (-r..=r)
        .map(|i| (-(i * i) as f64 / (2.0 * sigma * sigma)).exp())
        .collect();
    let sum: f64 = k.iter().sum();
    let pass = |src: &[f64], horizontal: bool| -> Vec<f64> {
        let mut out = vec![0.0; w * h];
        for y in 0..h {
            for x in 0..w {
                let mut acc = 0.0;
                for (j, kj) in (-r..=r).zip(&k) {
                    let (xx, yy) = if horizontal {
                        ((x as isize + j).clamp(0, w as isize - 1) as usize, y)
                    } else {
                        (x, (y as isize + j).clamp(0, h as isize - 1) as usize)
                    };
                    acc += kj * src[yy * w + xx];
                }
                out[y * w + x] = acc / sum;
            }
        }
        out
    };
    pass(&pass(v, true), false)
}
