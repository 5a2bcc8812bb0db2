//! Many points at once: colour-only blocks whose stages between the noise lookups run in SIMD
//! lanes, bit for bit the texels of one point at a time.

use super::*;

/// Points per block of [`WoodVolume::eval_many`] (16 f32 lanes: one AVX-512 register).
const BATCH: usize = 16;

impl WoodVolume {
    /// [`WoodVolume::eval`] at every point of `points` into `out` (same length): the same texels,
    /// bit for bit. Colour alone (`Needs::COLOR`, no knots: what flat texture slices and colour
    /// previews ask for) runs in blocks of `BATCH` points, stage by stage: the noise lookups
    /// (distortion, pores, rays) point by point, everything between them (frames, growth time,
    /// rings, interlock, Beer's law) in SIMD lanes. Anything else, and a last partial block, goes
    /// point by point.
    pub fn eval_many(&self, points: &[Vec3], needs: Needs, out: &mut [WoodTexel]) {
        self.eval_many_on(Simd::best(), points, needs, out);
    }

    /// [`WoodVolume::eval_many`] with the lane stages compiled for `simd` (which the CPU must
    /// have; tests run every level).
    #[doc(hidden)]
    pub fn eval_many_on(&self, simd: Simd, points: &[Vec3], needs: Needs, out: &mut [WoodTexel]) {
        assert_eq!(points.len(), out.len(), "eval_many: one texel per point");
        assert!(simd <= Simd::best(), "{simd:?} not available");
        let mut done = 0;
        if needs == Needs::COLOR && self.knots.is_none() && self.eyes.is_none() {
            for (p, o) in points.chunks_exact(BATCH).zip(out.chunks_exact_mut(BATCH)) {
                let p: &[Vec3; BATCH] = p.try_into().expect("a whole block");
                let o: &mut [WoodTexel; BATCH] = o.try_into().expect("a whole block");
                if !self.color_block_on(simd, p, o) {
                    for (o, &p) in o.iter_mut().zip(p) {
                        *o = self.eval(p, needs);
                    }
                }
                done += BATCH;
            }
        }
        for (o, &p) in out[done..].iter_mut().zip(&points[done..]) {
            *o = self.eval(p, needs);
        }
    }

    /// [`WoodVolume::color_block`] compiled for `simd`.
    #[inline]
    fn color_block_on(&self, simd: Simd, p: &[Vec3; BATCH], out: &mut [WoodTexel; BATCH]) -> bool {
        #[cfg(target_arch = "x86_64")]
        match simd {
            // SAFETY: the caller checked `simd <= Simd::best()`, which detected its features.
            Simd::Avx512 => return unsafe { self.color_block_avx512(p, out) },
            Simd::Avx2 => return unsafe { self.color_block_avx2(p, out) },
            _ => {}
        }
        let _ = simd;
        self.color_block(p, out)
    }

    simd_wide! {
        unsafe fn color_block_avx2 / color_block_avx512(
            &self,
            p: &[Vec3; BATCH],
            out: &mut [WoodTexel; BATCH],
        ) -> bool {
            self.color_block(p, out)
        }
    }

    /// One block of colour-only texels (see [`WoodVolume::eval_many`]): the operations of
    /// [`WoodVolume::eval_filtered`] with footprint 0, in its order, so the same bits. The lane
    /// stages hold one array per coordinate and loop with no call and no data-dependent branch,
    /// which the compiler vectorises. `false` (nothing written) where a point lies beyond the
    /// growth wave's fast range: the caller then evaluates the block point by point.
    #[inline(always)]
    fn color_block(&self, p: &[Vec3; BATCH], out: &mut [WoodTexel; BATCH]) -> bool {
        type Lanes = [f32; BATCH];
        let (mut qx, mut qy, mut qz): (Lanes, Lanes, Lanes) =
            ([0.0; BATCH], [0.0; BATCH], [0.0; BATCH]);
        for i in 0..BATCH {
            (qx[i], qy[i], qz[i]) = (p[i].x, p[i].y, p[i].z);
        }
        // f(p) (`Distortion::add`'s point update q += m a, in its order r̂, θ̂, ẑ): the magnitudes
        // point by point, frames and sums in lanes.
        if self.distortion.iter().any(Option::is_some) {
            let (mut c, mut s) = ([0.0; BATCH], [0.0; BATCH]);
            for i in 0..BATCH {
                (c[i], s[i]) = cylinder_cos_sin(p[i].x, p[i].y);
            }
            for (axis, noise) in self.distortion.iter().enumerate() {
                let Some(noise) = noise else { continue };
                let mut frames = [cylinder_frame_from(1.0, 0.0); BATCH];
                for i in 0..BATCH {
                    frames[i] = cylinder_frame_from(c[i], s[i]);
                }
                let m = noise.eval_many(p, &frames);
                for i in 0..BATCH {
                    // a = r̂ = (c, s, 0), θ̂ = (−s, c, 0) or ẑ = (0, 0, 1).
                    let (ax, ay, az) = match axis {
                        0 => (c[i], s[i], 0.0),
                        1 => (-s[i], c[i], 0.0),
                        _ => (0.0, 0.0, 1.0),
                    };
                    qx[i] += m[i] * ax;
                    qy[i] += m[i] * ay;
                    qz[i] += m[i] * az;
                }
            }
        }
        // Growth time and rings in lanes.
        let mut r: Lanes = [0.0; BATCH];
        for i in 0..BATCH {
            r[i] = (qx[i] * qx[i] + qy[i] * qy[i]).sqrt();
        }
        if let Some(w) = &self.growth {
            let mut ok = true;
            for &r in &r {
                let shift = self.growth_phase.map_or(0.0, |m| m.amp);
                ok &= w.in_fast_range((r * self.inv_ring_width).abs() + shift);
            }
            if !ok {
                return false;
            }
        }
        let (mut time, mut g): (Lanes, Lanes) = ([0.0; BATCH], [0.0; BATCH]);
        for i in 0..BATCH {
            time[i] = self.time_with::<false>(r[i]).0;
        }
        for i in 0..BATCH {
            g[i] = self.rings.eval(time[i]);
        }
        // Pores: the fibre frame in lanes, the noise point by point.
        let mut pore: Lanes = [0.0; BATCH];
        if let Some(pores) = &self.pores {
            let (mut c, mut s) = ([0.0; BATCH], [0.0; BATCH]);
            for i in 0..BATCH {
                (c[i], s[i]) = cylinder_cos_sin(qx[i], qy[i]);
            }
            let (mut sin, mut cos) = ([0.0; BATCH], [1.0; BATCH]);
            if let Some(n) = &self.interlock {
                for i in 0..BATCH {
                    (sin[i], cos[i]) = crate::math::elementary::sin_cos(n.eval(r[i]).0);
                }
            }
            let mut frames = [cylinder_frame_from(1.0, 0.0); BATCH];
            let mut q = [Vec3::ZERO; BATCH];
            for i in 0..BATCH {
                let frame = cylinder_frame_from(c[i], s[i]);
                frames[i] = if self.interlock.is_some() {
                    rotate_by(&frame, sin[i], cos[i])
                } else {
                    frame
                };
                q[i] = Vec3::new(qx[i], qy[i], qz[i]);
            }
            pore = pores.mask_many(&q, &frames, &g);
        }
        let mut ray: Lanes = [0.0; BATCH];
        if let Some(rays) = self.rays.as_ref().filter(|_| self.color_uses_rays()) {
            for i in 0..BATCH {
                ray[i] = rays.mask(Vec3::new(qx[i], qy[i], qz[i]));
            }
        }
        let mut texture: Lanes = [0.0; BATCH];
        if let Some(t) = &self.texture {
            for i in 0..BATCH {
                texture[i] = t.path(Vec3::new(qx[i], qy[i], qz[i]), 0.0);
            }
        }
        // Beer's law in lanes, a channel at a time.
        let mut diffuse = [[0.0f32; BATCH]; 3];
        let mut fiber = [[0.0f32; BATCH]; 3];
        for ch in 0..3 {
            for i in 0..BATCH {
                let a = self
                    .color
                    .channel_absorbance(ch, g[i], pore[i], ray[i], texture[i]);
                (diffuse[ch][i], fiber[ch][i]) = self.color.channel_colors(ch, a);
            }
        }
        for i in 0..BATCH {
            out[i] = WoodTexel {
                diffuse: Vec3::new(diffuse[0][i], diffuse[1][i], diffuse[2][i]),
                fiber_color: Vec3::new(fiber[0][i], fiber[1][i], fiber[2][i]),
                pore_mask: pore[i],
                ray_mask: ray[i],
                growth_time: time[i],
                ..WoodTexel::default()
            };
        }
        true
    }
}
