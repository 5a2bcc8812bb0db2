//! Cartesian cells: the search window after the bounding-box fit (Liu 2016 §4.5, eq. 9–12)
//! and the blocked cell loop.

use super::*;

/// Everything a Cartesian query needs besides the band: the kernel map after the fit, the
/// point's cell `base` and its place `f` in it, the window `lo..=hi` (cell offsets per axis), the
/// per-axis gap scale of the axis-aligned cell test (0 for oriented kernels) and the counts.
#[derive(Clone, Copy)]
pub(super) struct CartesianQuery {
    map: KernelMap,
    reach: Vec3,
    base: [i32; 3],
    f: Vec3,
    gap_scale: Vec3,
}

impl CartesianQuery {
    /// The window: offsets ⌊f − reach⌋ ..= ⌊f + reach⌋ per axis (≤ 3 cells, 4 if rounding).
    #[inline(always)]
    fn window(&self) -> ([i32; 3], [i32; 3]) {
        let (lo, hi) = (self.f - self.reach, self.f + self.reach);
        (
            [floor_i32(lo.x), floor_i32(lo.y), floor_i32(lo.z)],
            [floor_i32(hi.x), floor_i32(hi.y), floor_i32(hi.z)],
        )
    }

    /// Whether the window lies in the 3 × 3 × 3 block (⌊f − reach⌋ ≥ −1 and ⌊f + reach⌋ ≤ 1 per
    /// axis, tested on the same rounded sums without converting them).
    #[inline(always)]
    fn in_block(&self) -> bool {
        let (lo, hi) = (self.f - self.reach, self.f + self.reach);
        lo.cmpge(Vec3::splat(-1.0)).all() && hi.cmplt(Vec3::splat(2.0)).all()
    }

    /// Cell height in fitted kernel semi-axes along z (for upright kernels, whose local z is z).
    #[inline(always)]
    fn gap_scale_z_upright(&self) -> f32 {
        1.0 / (self.reach.z.max(f32::MIN_POSITIVE))
    }
}

/// Whether a kernel frame only turns about z (n = ẑ, s and t horizontal), as the distortion's
/// cylindrical frame does: then the kernel's local z is the world z.
#[inline(always)]
fn is_upright(frame: &Frame) -> bool {
    frame.n == Vec3::Z && frame.s.z == 0.0 && frame.t.z == 0.0
}

/// Slack on [`layer_shrink`], far above f32 rounding, so no cell holding a contributing impulse
/// is ever dropped.
const LAYER_SLACK: f32 = 1e-4;

/// For an upright kernel (z semi-axis e_z, window reach ρ_z = e_z / cell height in cells), the
/// fraction of its x and y extent left in the layer of cells at z offset `oz` from a point at
/// `fz` in its cell: the layer lies g = gap / ρ_z semi-axes away along z, where the ellipsoid's
/// slice is the ellipse scaled by √(1 − g²), so its bounding box (eq. 9) scales by that too.
/// Returned with slack, capped at 1.
#[inline(always)]
fn layer_shrink(oz: i32, fz: f32, cells_per_semi_axis: f32) -> f32 {
    let gap = ((oz as f32 + 0.5 - fz).abs() - 0.5).max(0.0) * cells_per_semi_axis;
    ((1.0 - gap * gap).max(0.0).sqrt() + LAYER_SLACK).min(1.0)
}

/// The indices of the set bits of `mask`, ascending.
#[inline(always)]
fn lanes(mut mask: u32) -> impl Iterator<Item = usize> {
    std::iter::from_fn(move || {
        (mask != 0).then(|| {
            let i = mask.trailing_zeros() as usize;
            mask &= mask - 1;
            i
        })
    })
}

/// Lanes of the block search: the 27 cells of the 3 × 3 × 3 block plus 5 padding lanes.
const BLOCK: usize = 32;

/// Cell offsets (x, y, z) of each block lane, z outermost and x innermost like the scalar loop;
/// the padding lanes sit at z = 2, outside every window.
const BLOCK_OFFSETS: [[i32; BLOCK]; 3] = {
    let mut o = [[0; BLOCK]; 3];
    let mut i = 0;
    while i < BLOCK {
        o[0][i] = (i % 3) as i32 - 1;
        o[1][i] = ((i / 3) % 3) as i32 - 1;
        o[2][i] = (i / 9) as i32 - 1;
        i += 1;
    }
    o
};

impl Band {
    /// The query setup shared by both Cartesian paths: the fit, the kernel map and the window.
    #[inline(always)]
    pub(super) fn cartesian_query(
        &self,
        p: Vec3,
        frame: Option<&Frame>,
        kernel_scale: f32,
    ) -> CartesianQuery {
        // Kernel extent per axis before the fit (eq. 9), then the fit (eq. 11) against the cell.
        let env = self.env * kernel_scale;
        let (ext, axes) = match frame {
            None => (env, None),
            Some(f) => (bbox_half_extent(env, f), Some(*f)),
        };
        let sb = (self.cell.x / ext.x)
            .min(self.cell.y / ext.y)
            .min(self.cell.z / ext.z)
            .min(1.0);
        let map = KernelMap {
            axes,
            inv: 1.0 / (sb * env),
        };
        let reach = sb * ext / self.cell; // ≤ 1 cell per axis
        let pc = p / self.cell;
        let base = [floor_i32(pc.x), floor_i32(pc.y), floor_i32(pc.z)];
        let f = Vec3::new(
            pc.x - base[0] as f32,
            pc.y - base[1] as f32,
            pc.z - base[2] as f32,
        );
        // Axis-aligned kernels: cells whose box lies outside the kernel's ellipsoid about p (semi-
        // axes s_b·Sₑ) cannot hold a contributing centre and are skipped before hashing (each
        // axis' gap to the cell bounds that axis' term of q from below). Oriented kernels: no
        // such test (scale 0) — separating-axis tests against the kernel's box culled ≈ 6 % of
        // the cells of the presets and cost more than they saved (notes/wood.md §12).
        let gap_scale = match frame {
            None => self.cell / (sb * env),
            Some(_) => Vec3::ZERO,
        };
        CartesianQuery {
            map,
            reach,
            base,
            f,
            gap_scale,
        }
    }

    /// Cartesian cells: at the AVX-512 or AVX2 level ([`Simd::best`]) the 3 × 3 × 3 block of
    /// cells is searched in SIMD lanes ([`Band::cartesian_block`]: 32 lanes, two AVX-512 or four
    /// AVX2 registers), else (and for windows wider than the block, which only rounding can
    /// make) one cell at a time. All give the same value, bit for bit.
    pub(super) fn cartesian<const GRAD: bool>(
        &self,
        p: Vec3,
        frame: Option<&Frame>,
        kernel_scale: f32,
    ) -> (f32, Vec3) {
        let q = self.cartesian_query(p, frame, kernel_scale);
        self.cartesian_search::<GRAD>(&q)
    }

    /// The cell search of a prepared query (see [`Band::cartesian`]).
    #[inline(always)]
    pub(super) fn cartesian_search<const GRAD: bool>(&self, q: &CartesianQuery) -> (f32, Vec3) {
        // SAFETY: the level `Simd::best` allows.
        unsafe { self.cartesian_search_on::<GRAD>(Simd::best(), q) }
    }

    /// [`Band::cartesian_search`] at the level `simd` (tests run every level).
    ///
    /// # Safety
    /// `simd` must be no wider than [`Simd::best`]. (A precondition rather than a check: this
    /// runs once per noise query.)
    #[inline(always)]
    pub(super) unsafe fn cartesian_search_on<const GRAD: bool>(
        &self,
        simd: Simd,
        q: &CartesianQuery,
    ) -> (f32, Vec3) {
        #[cfg(target_arch = "x86_64")]
        if q.in_block() {
            let upright = q.map.axes.as_ref().is_some_and(is_upright);
            match simd {
                // SAFETY: `simd` is no wider than `Simd::best()` (the caller's promise), which
                // detected its features.
                Simd::Avx512 => return unsafe { self.cartesian_avx512::<GRAD>(q, upright) },
                Simd::Avx2 => return unsafe { self.cartesian_avx2::<GRAD>(q, upright) },
                Simd::Sse2 | Simd::Scalar => {}
            }
        }
        self.cartesian_cells::<GRAD>(q)
    }

    /// [`Band::cartesian_query`] for `N` points with their frames and kernel scales: one loop with
    /// no call and no data-dependent branch, which the compiler runs in SIMD lanes.
    #[inline(always)]
    pub(super) fn cartesian_queries<const N: usize>(
        &self,
        p: &[Vec3; N],
        frames: &[Frame; N],
        scale: &[f32; N],
    ) -> [CartesianQuery; N] {
        let mut queries = [CartesianQuery {
            map: KernelMap {
                axes: None,
                inv: Vec3::ZERO,
            },
            reach: Vec3::ZERO,
            base: [0; 3],
            f: Vec3::ZERO,
            gap_scale: Vec3::ZERO,
        }; N];
        for (i, q) in queries.iter_mut().enumerate() {
            *q = self.cartesian_query(p[i], Some(&frames[i]), scale[i]);
        }
        queries
    }

    /// One cell at a time over the window (the reference the block search must equal).
    pub(super) fn cartesian_cells<const GRAD: bool>(&self, q: &CartesianQuery) -> (f32, Vec3) {
        let (f, base) = (q.f, q.base);
        let (lo, hi) = q.window();
        let mut acc = (0.0, Vec3::ZERO);
        for oz in lo[2]..hi[2] + 1 {
            for oy in lo[1]..hi[1] + 1 {
                for ox in lo[0]..hi[0] + 1 {
                    let o = Vec3::new(ox as f32, oy as f32, oz as f32);
                    // Distance from f to the cell [o, o + 1] per axis, in kernel semi-axes.
                    let gap = ((o + 0.5 - f).abs() - 0.5).max(Vec3::ZERO) * q.gap_scale;
                    if gap.length_squared() >= 1.0 {
                        continue;
                    }
                    let h = cell3_offset(
                        base[0].wrapping_add(ox),
                        base[1].wrapping_add(oy),
                        base[2].wrapping_add(oz),
                        &self.offsets,
                    );
                    for k in 0..self.cell_counts.count(h[0]) {
                        let (u, w) = impulse(h, k);
                        let d = (f - o - u) * self.cell;
                        let w = if self.signed { w } else { 1.0 };
                        q.map.add::<GRAD>(self.kernel, d, w, &mut acc);
                    }
                }
            }
        }
        acc
    }

    simd_wide! {
        unsafe fn cartesian_avx2 / cartesian_avx512<const GRAD: bool>(
            &self,
            q: &CartesianQuery,
            upright: bool,
        ) -> (f32, Vec3) {
            self.cartesian_block::<GRAD>(q, upright)
        }
    }

    /// The window searched in lanes, one lane per cell of the 3 × 3 × 3 block (in the order of
    /// [`Band::cartesian_cells`]): every lane hashes its cell and draws its count; then, impulse k
    /// of every cell at once, each lane tests whether the impulse reaches p (q < 1, the same
    /// operations as the scalar test). Only those impulses — ≈ the density, out of ≈ 20 tested
    /// for the distortion — are then summed one by one, in the scalar order, by the scalar code:
    /// the value is [`Band::cartesian_cells`]' bit for bit. Loops over whole lane arrays with no
    /// early exit, so the compiler vectorises them for the enclosing `target_feature`.
    #[inline(always)]
    fn cartesian_block<const GRAD: bool>(&self, q: &CartesianQuery, upright: bool) -> (f32, Vec3) {
        let (f, base, seed) = (q.f, q.base, &self.offsets);
        let per_semi_axis_z = q.gap_scale_z_upright();
        // Three plain loops over the lanes (each vectorises on its own): which cells the window
        // keeps, their hashes, their counts.
        let mut inside = [false; BLOCK];
        for (i, inside) in inside.iter_mut().enumerate() {
            let o = Vec3::new(
                BLOCK_OFFSETS[0][i] as f32,
                BLOCK_OFFSETS[1][i] as f32,
                BLOCK_OFFSETS[2][i] as f32,
            );
            // Upright kernels: the layer's x and y window (1 keeps the whole window exactly).
            let shrink = if upright {
                layer_shrink(BLOCK_OFFSETS[2][i], f.z, per_semi_axis_z)
            } else {
                1.0
            };
            let (lo, hi) = (f - shrink * q.reach, f + shrink * q.reach);
            // o ≥ ⌊lo⌋ ⇔ lo < o + 1 and o ≤ ⌊hi⌋ ⇔ o ≤ hi for integer o: the window of
            // `cartesian_query` without the float-to-int conversions.
            let gap = ((o + 0.5 - f).abs() - 0.5).max(Vec3::ZERO) * q.gap_scale;
            *inside = (lo.x < o.x + 1.0)
                & (o.x <= hi.x)
                & (lo.y < o.y + 1.0)
                & (o.y <= hi.y)
                & (f.z - q.reach.z < o.z + 1.0)
                & (o.z <= f.z + q.reach.z)
                & (gap.length_squared() < 1.0);
        }
        let mut h = [[0u32; BLOCK]; 3];
        for i in 0..BLOCK {
            let hash = pcg3d([
                (base[0].wrapping_add(BLOCK_OFFSETS[0][i]) as u32).wrapping_add(seed[0]),
                (base[1].wrapping_add(BLOCK_OFFSETS[1][i]) as u32).wrapping_add(seed[1]),
                (base[2].wrapping_add(BLOCK_OFFSETS[2][i]) as u32).wrapping_add(seed[2]),
            ]);
            (h[0][i], h[1][i], h[2][i]) = (hash[0], hash[1], hash[2]);
        }
        let mut count = [0u32; BLOCK];
        let mut walk = 0u32;
        for i in 0..BLOCK {
            let c = self.cell_counts.table_count(h[0][i]);
            count[i] = if inside[i] { c } else { 0 };
            walk |= ((count[i] >= TABLE as u32) as u32) << i;
        }
        for i in lanes(walk) {
            count[i] = self.cell_counts.count(h[0][i]);
        }
        let rounds = count.iter().fold(0, |m, &c| m.max(c));
        if rounds > u32::BITS {
            return self.cartesian_cells::<GRAD>(q);
        }
        // Bit k of lane i: impulse k of cell i reaches p.
        let mut hits = [0u32; BLOCK];
        let axes = q.map.axes;
        for k in 0..rounds {
            for i in 0..BLOCK {
                let (u, _) = impulse_numbers(impulse_stream(h[1][i], h[2][i], k));
                let o = Vec3::new(
                    BLOCK_OFFSETS[0][i] as f32,
                    BLOCK_OFFSETS[1][i] as f32,
                    BLOCK_OFFSETS[2][i] as f32,
                );
                let d = (f - o - u) * self.cell;
                let local = match &axes {
                    None => d,
                    Some(fr) => fr.to_local(d),
                };
                let reaches = (local * q.map.inv).length_squared() < 1.0;
                hits[i] |= ((reaches & (k < count[i])) as u32) << k;
            }
        }
        let mut hit_cells = 0u32;
        for (i, &bits) in hits.iter().enumerate() {
            hit_cells |= ((bits != 0) as u32) << i;
        }
        let mut acc = (0.0, Vec3::ZERO);
        for i in lanes(hit_cells) {
            for k in lanes(hits[i]) {
                let k = k as u32;
                let o = Vec3::new(
                    BLOCK_OFFSETS[0][i] as f32,
                    BLOCK_OFFSETS[1][i] as f32,
                    BLOCK_OFFSETS[2][i] as f32,
                );
                let (u, w) = impulse([h[0][i], h[1][i], h[2][i]], k);
                let d = (f - o - u) * self.cell;
                let w = if self.signed { w } else { 1.0 };
                q.map.add::<GRAD>(self.kernel, d, w, &mut acc);
            }
        }
        acc
    }
}
