//! Equal-volume cylindrical cells around the pith (Liu 2016 §4.2).

use super::*;

impl Band {
    pub(super) fn cylindrical<const GRAD: bool>(
        &self,
        p: Vec3,
        frame: Option<&Frame>,
        kernel_scale: f32,
    ) -> (f32, Vec3) {
        let env = self.env * kernel_scale;
        let r = (p.x * p.x + p.y * p.y).sqrt();
        let radial = if r > 0.0 {
            Vec3::new(p.x / r, p.y / r, 0.0)
        } else {
            Vec3::X
        };
        let cyl = Frame {
            s: radial,
            t: Vec3::new(-radial.y, radial.x, 0.0),
            n: Vec3::Z,
        };
        let kf = frame.copied().unwrap_or(cyl);
        // Eq. 9 with R expressed in the cylindrical frame at p, against (radial, arc, height).
        let rel = Frame {
            s: cyl.to_local(kf.s),
            t: cyl.to_local(kf.t),
            n: cyl.to_local(kf.n),
        };
        let ext = bbox_half_extent(env, &rel);
        let sb = (self.cell.x / ext.x)
            .min(self.cell.y / ext.y)
            .min(self.cell.z / ext.z)
            .min(1.0);
        let map = KernelMap {
            axes: Some(kf),
            inv: 1.0 / (sb * env),
        };
        // Search window (notes/noise.md): a kernel reaching p has its centre within ρ = s_b·max(Sₑ)
        // of p, so in bands overlapping [r − ρ, r + ρ], at angles within asin(ρ / r) of θ(p), and
        // within s_b·ext_z of p along z.
        let rho = sb * env.max_element();
        let reach_z = sb * ext.z / self.cell.z;
        let theta = p.y.atan2(p.x).rem_euclid(2.0 * PI);
        // A kernel at k reaching p has |(p − k)·θ̂| = r_k |sin Δθ| ≤ s_b·ext_y and
        // |(p − k)·r̂| ≤ s_b·ext_x, so cos Δθ > 0 and r_k ≥ r − s_b·ext_x when r > s_b·ext_x.
        let (ex, ey) = (sb * ext.x, sb * ext.y);
        let dtheta = if ex < r && ey < r - ex {
            (ey / (r - ex)).asin()
        } else {
            PI
        };
        let (cr, ca, cz) = (self.cell.x, self.cell.y, self.cell.z);
        let pz = p.z / cz;
        let bz = floor_i32(pz);
        let fz = pz - bz as f32;
        let (z_lo, z_hi) = (floor_i32(fz - reach_z), floor_i32(fz + reach_z));
        let j_lo = floor_i32((r - rho) / cr).max(0);
        let j_hi = floor_i32((r + rho) / cr);
        let mut acc = (0.0, Vec3::ZERO);
        for j in j_lo..=j_hi {
            let n = band_cells(j, cr, ca);
            let width = 2.0 * PI / n as f32;
            let volume = PI * (2 * j + 1) as f32 * cr * cr * cz / n as f32;
            let counts = PoissonTable::new((self.intensity * volume) as f64);
            let (a_lo, a_hi) = arc_window(theta, dtheta, width, n);
            let (r0, r1) = (j as f32 * cr, (j + 1) as f32 * cr);
            for oz in z_lo..=z_hi {
                for a in a_lo..=a_hi {
                    let cell_a = wrap_arc(a, n);
                    let h = cell3_offset(j, cell_a, bz.wrapping_add(oz), &self.offsets);
                    for k in 0..counts.count(h[0]) {
                        let (u, w) = impulse(h, k);
                        // Uniform in the annular sector: r² uniform between r0² and r1².
                        let rk = (r0 * r0 + u.x * (r1 * r1 - r0 * r0)).sqrt();
                        let tk = (cell_a as f32 + u.y) * width;
                        let d = Vec3::new(
                            p.x - rk * tk.cos(),
                            p.y - rk * tk.sin(),
                            (fz - oz as f32 - u.z) * cz,
                        );
                        let w = if self.signed { w } else { 1.0 };
                        map.add::<GRAD>(self.kernel, d, w, &mut acc);
                    }
                }
            }
        }
        acc
    }
}

/// The cells of a band of `n` cells, each `width` radians, that a kernel reaching the point at
/// angle `theta` can sit in: within `dtheta` of it (every cell when that is π, or covers the
/// band). The ends may lie outside [0, n) ([`wrap_arc`] brings them back).
#[inline]
fn arc_window(theta: f32, dtheta: f32, width: f32, n: i32) -> (i32, i32) {
    if dtheta >= PI {
        return (0, n - 1);
    }
    let lo = floor_i32((theta - dtheta) / width);
    let hi = floor_i32((theta + dtheta) / width);
    if hi - lo + 1 >= n {
        (0, n - 1)
    } else {
        (lo, hi)
    }
}

/// Cell `a` of an [`arc_window`] in a band of `n` cells: a ∈ [−n, 2n) (θ ∈ [0, 2π), window ≤
/// π/2 each side), so it wraps without a division.
#[inline(always)]
fn wrap_arc(a: i32, n: i32) -> i32 {
    if a < 0 {
        a + n
    } else if a >= n {
        a - n
    } else {
        a
    }
}

/// Cells in cylindrical band `j` (Liu 2016 §4.2): proportional to the band's midpoint radius so
/// that every cell is ≈ `arc` long and all cells have ≈ equal volume.
#[inline]
pub(super) fn band_cells(j: i32, radial: f32, arc: f32) -> i32 {
    ((2.0 * PI * (j as f32 + 0.5) * radial / arc).round() as i32).max(1)
}
