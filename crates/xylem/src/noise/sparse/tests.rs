use super::cylindrical::band_cells;
use super::impulses::poisson_with;
use super::*;
use crate::math::{uniform_sphere, Pcg32};

impl Band {
    /// Oracle for the search window: every cell within `w` cells (Cartesian) or every band
    /// within `w` bands and every angular cell (cylindrical), same kernels and shrink.
    fn brute(&self, p: Vec3, frame: &Frame, cylindrical: bool, w: i32) -> f32 {
        let mut acc = (0.0, Vec3::ZERO);
        if !cylindrical {
            let ext = bbox_half_extent(self.env, frame);
            let sb = (self.cell / ext).min_element().min(1.0);
            let map = KernelMap {
                axes: Some(*frame),
                inv: 1.0 / (sb * self.env),
            };
            let pc = p / self.cell;
            let base = [floor_i32(pc.x), floor_i32(pc.y), floor_i32(pc.z)];
            let f = pc - Vec3::new(base[0] as f32, base[1] as f32, base[2] as f32);
            let m = self.intensity * self.cell.x * self.cell.y * self.cell.z;
            for oz in -w..=w {
                for oy in -w..=w {
                    for ox in -w..=w {
                        let h =
                            cell3_offset(base[0] + ox, base[1] + oy, base[2] + oz, &self.offsets);
                        let o = Vec3::new(ox as f32, oy as f32, oz as f32);
                        for k in 0..poisson(h[0], m) {
                            let (u, wt) = impulse(h, k);
                            let wt = if self.signed { wt } else { 1.0 };
                            map.add::<false>(self.kernel, (f - o - u) * self.cell, wt, &mut acc);
                        }
                    }
                }
            }
        } else {
            let r = (p.x * p.x + p.y * p.y).sqrt();
            let radial = Vec3::new(p.x / r, p.y / r, 0.0);
            let cyl = Frame {
                s: radial,
                t: Vec3::new(-radial.y, radial.x, 0.0),
                n: Vec3::Z,
            };
            let rel = Frame {
                s: cyl.to_local(frame.s),
                t: cyl.to_local(frame.t),
                n: cyl.to_local(frame.n),
            };
            let sb = (self.cell / bbox_half_extent(self.env, &rel))
                .min_element()
                .min(1.0);
            let map = KernelMap {
                axes: Some(*frame),
                inv: 1.0 / (sb * self.env),
            };
            let (cr, ca, cz) = (self.cell.x, self.cell.y, self.cell.z);
            let bz = floor_i32(p.z / cz);
            let fz = p.z / cz - bz as f32;
            let j0 = floor_i32(r / cr);
            for j in (j0 - w).max(0)..=j0 + w {
                let n = band_cells(j, cr, ca);
                let width = 2.0 * PI / n as f32;
                let m = self.intensity * PI * (2 * j + 1) as f32 * cr * cr * cz / n as f32;
                let (r0, r1) = (j as f32 * cr, (j + 1) as f32 * cr);
                for oz in -w..=w {
                    for a in 0..n {
                        let h = cell3_offset(j, a, bz + oz, &self.offsets);
                        for k in 0..poisson(h[0], m) {
                            let (u, wt) = impulse(h, k);
                            let rk = (r0 * r0 + u.x * (r1 * r1 - r0 * r0)).sqrt();
                            let tk = (a as f32 + u.y) * width;
                            let d = Vec3::new(
                                p.x - rk * tk.cos(),
                                p.y - rk * tk.sin(),
                                (fz - oz as f32 - u.z) * cz,
                            );
                            let wt = if self.signed { wt } else { 1.0 };
                            map.add::<false>(self.kernel, d, wt, &mut acc);
                        }
                    }
                }
            }
        }
        acc.0
    }
}

fn band(env: Vec3, cell: Vec3, seed: u32) -> Band {
    let intensity = 3.0 / (4.0 / 3.0 * PI * env.x * env.y * env.z);
    Band::new(Kernel::Wyvill, env, cell, intensity, true, seed)
}

/// The bounding-box fit (eq. 9–12) keeps every contributing kernel inside the searched cells:
/// the windowed sum equals, bit for bit up to summation order, the sum over a ±3-cell block.
#[test]
fn oriented_kernels_stay_in_search_window() {
    let mut rng = Pcg32::new(11, 0);
    for i in 0..300 {
        // Strongly prolate kernels (aspect 8) in random orientations, cells partway (§4.5).
        let b = band(Vec3::new(0.2, 0.2, 1.6), Vec3::new(0.4, 0.4, 1.2), i);
        let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 20.0 - 10.0;
        let f = Frame::from_normal(uniform_sphere(rng.next_vec2()));
        let fast = b.cartesian::<false>(p, Some(&f), 1.0).0;
        let slow = b.brute(p, &f, false, 3);
        assert!(
            (fast - slow).abs() <= 1e-5 * (1.0 + slow.abs()),
            "{fast} vs {slow} at {p}"
        );
    }
    // Axis-aligned kernels (no frame: the per-cell ellipsoid skip) against the same oracle.
    let identity = Frame {
        s: Vec3::X,
        t: Vec3::Y,
        n: Vec3::Z,
    };
    for i in 0..300 {
        let b = band(Vec3::new(0.35, 0.2, 1.0), Vec3::new(0.4, 0.4, 1.2), i);
        let p = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 20.0 - 10.0;
        let fast = b.cartesian::<false>(p, None, 1.0).0;
        let slow = b.brute(p, &identity, false, 3);
        assert!(
            (fast - slow).abs() <= 1e-5 * (1.0 + slow.abs()),
            "{fast} vs {slow} at {p}"
        );
    }
    let mut nonzero = 0;
    for i in 0..200 {
        let b = band(Vec3::new(0.3, 0.5, 2.0), Vec3::new(0.4, 0.6, 1.5), i);
        let r = 0.2 + 30.0 * rng.next_f32();
        let t = 2.0 * PI * rng.next_f32();
        let p = Vec3::new(r * t.cos(), r * t.sin(), 10.0 * rng.next_f32());
        // Mostly along the pith (as wood features are), some far off it.
        let n = Vec3::Z + 0.7 * uniform_sphere(rng.next_vec2());
        let f = Frame::from_normal(n.normalize());
        let fast = b.cylindrical::<false>(p, Some(&f), 1.0).0;
        let slow = b.brute(p, &f, true, 3);
        nonzero += (slow != 0.0) as i32;
        assert!(
            (fast - slow).abs() <= 1e-5 * (1.0 + slow.abs()),
            "{fast} vs {slow} at {p}"
        );
    }
    assert!(nonzero > 60, "the comparison must see kernels");
}

/// The SIMD block search (AVX-512 and AVX2) gives the one-cell-at-a-time value and gradient
/// bit for bit, for
/// axis-aligned, upright (turned about z, the layer shrink) and tilted kernels, sparse and
/// dense cells (counts past the threshold table, many rounds), and both signs of coordinates.
#[test]
fn block_search_matches_the_cell_loop() {
    let mut rng = Pcg32::new(5, 0);
    let mut compared = 0;
    for i in 0..3000u32 {
        let env = Vec3::new(
            0.2 + rng.next_f32(),
            0.2 + 2.0 * rng.next_f32(),
            0.2 + 4.0 * rng.next_f32(),
        );
        let per_cell = [0.05f32, 1.2, 6.0][i as usize % 3];
        let cell = env * (0.6 + 0.8 * rng.next_f32());
        let kernel = if i % 4 == 1 {
            Kernel::Bump { sharpness: 1.0 }
        } else {
            Kernel::Wyvill
        };
        let intensity = per_cell / (cell.x * cell.y * cell.z);
        let b = Band::new(kernel, env, cell, intensity, i % 2 == 0, i);
        let p = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - 1.0) * 200.0;
        let angle = 2.0 * PI * rng.next_f32();
        let (c, s) = (angle.cos(), angle.sin());
        let upright = Frame {
            s: Vec3::new(c, s, 0.0),
            t: Vec3::new(-s, c, 0.0),
            n: Vec3::Z,
        };
        let tilted = Frame::from_normal(uniform_sphere(rng.next_vec2()));
        for frame in [None, Some(&upright), Some(&tilted)] {
            let q = b.cartesian_query(p, frame, 1.0);
            let reference = b.cartesian_cells::<true>(&q);
            let value = b.cartesian_cells::<false>(&q).0;
            // The dispatched search and the search at every level this CPU has.
            let mut searches = vec![(
                b.cartesian::<true>(p, frame, 1.0),
                b.cartesian::<false>(p, frame, 1.0).0,
            )];
            for simd in Simd::ALL.into_iter().filter(|&s| s <= Simd::best()) {
                // SAFETY: no wider than `Simd::best()`.
                searches.push(unsafe {
                    (
                        b.cartesian_search_on::<true>(simd, &q),
                        b.cartesian_search_on::<false>(simd, &q).0,
                    )
                });
            }
            for (fast, fast_value) in searches {
                assert_eq!(
                    fast.0.to_bits(),
                    reference.0.to_bits(),
                    "value at {p} ({i})"
                );
                assert_eq!(fast_value.to_bits(), value.to_bits(), "value at {p} ({i})");
                for k in 0..3 {
                    assert_eq!(
                        fast.1[k].to_bits(),
                        reference.1[k].to_bits(),
                        "∇ at {p} ({i})"
                    );
                }
            }
            compared += (reference.0 != 0.0) as u32;
        }
    }
    assert!(
        compared > 3000,
        "the comparison must see kernels ({compared})"
    );
}

/// The integer thresholds reproduce the f64 walk exactly: at random hashes, at every threshold
/// and one below it (where a rounding slip would show), and past the table (the walk fallback).
#[test]
fn poisson_table_matches_the_walk() {
    for m in [1e-4f64, 0.0716, 0.256, 1.19, 3.0, 11.0, 64.0] {
        let table = PoissonTable::new(m);
        let walk = |h: u32| poisson_with(h, m, (-m).exp());
        // The lane count equals the walk below the table's end and says so past it.
        let check = |h: u32| {
            assert_eq!(table.count(h), walk(h), "m {m} h {h}");
            let lanes = table.table_count(h);
            assert_eq!(lanes, walk(h).min(TABLE as u32), "lanes: m {m} h {h}");
        };
        (0..20_000u32).for_each(|i| check(mix32(i ^ 0x1234_5678)));
        for &t in &table.thresholds {
            for h in [t.saturating_sub(1), t, t + 1] {
                if h <= u32::MAX as u64 {
                    check(h as u32);
                }
            }
        }
        [0, 1, u32::MAX - 1, u32::MAX].into_iter().for_each(check);
    }
}

#[test]
fn poisson_mean_and_variance() {
    // Mean and variance of the count both equal m; 10⁵ draws: σ(mean) = sqrt(m/1e5).
    for m in [0.3f32, 2.0, 10.0, 60.0] {
        let n = 100_000;
        let (mut s, mut s2) = (0.0f64, 0.0f64);
        for i in 0..n {
            let k = poisson(mix32(i), m) as f64;
            s += k;
            s2 += k * k;
        }
        let mean = s / n as f64;
        let var = s2 / n as f64 - mean * mean;
        let sd = (m as f64 / n as f64).sqrt();
        assert!((mean - m as f64).abs() < 5.0 * sd, "m={m} mean={mean}");
        assert!((var / m as f64 - 1.0).abs() < 0.03, "m={m} var={var}");
    }
}
