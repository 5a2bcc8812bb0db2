//! The node and leaf-packet tests: the portable lane loops and their AVX2 compilation, the same
//! IEEE operations in the same order so that both return the same bits.

use super::*;

/// Slab test of a ray against a node's eight child boxes (Kay & Kajiya 1986): the bit mask of
/// the children whose [t_near, t_far] meets [t_min, t_max], and each child's t_near.
#[inline(always)]
pub(super) fn intersect_node(
    node: &Node,
    r: &RayData,
    t_min: f32,
    t_max: f32,
) -> (u32, [f32; WIDTH]) {
    let [nx, ny, nz] = r.near;
    let (near_x, far_x) = (&node.bounds[nx][0], &node.bounds[1 - nx][0]);
    let (near_y, far_y) = (&node.bounds[ny][1], &node.bounds[1 - ny][1]);
    let (near_z, far_z) = (&node.bounds[nz][2], &node.bounds[1 - nz][2]);
    let [ox, oy, oz] = r.o;
    let [ix, iy, iz] = r.inv;
    let max = |a: f32, b: f32| if a > b { a } else { b };
    let min = |a: f32, b: f32| if a < b { a } else { b };
    let mut t_near = [0.0; WIDTH];
    let mut hit = [false; WIDTH];
    for l in 0..WIDTH {
        let tn = max(
            max((near_x[l] - ox) * ix, (near_y[l] - oy) * iy),
            max((near_z[l] - oz) * iz, t_min),
        );
        let tf = min(
            min((far_x[l] - ox) * ix, (far_y[l] - oy) * iy),
            min((far_z[l] - oz) * iz, t_max),
        );
        t_near[l] = tn;
        hit[l] = tn <= tf * ROBUST_FAR;
    }
    let mut mask = 0u32;
    for (l, &h) in hit.iter().enumerate() {
        mask |= (h as u32) << l;
    }
    (mask, t_near)
}

/// A hit lane of a leaf packet: (lane, t, u, v).
pub(super) type LaneHit = (usize, f32, f32, f32);

/// The node and packet tests as one compilation target runs them best; every implementation does
/// the same IEEE operations in the same order as [`intersect_node`] and [`intersect_packet`],
/// so all return the same bits.
pub(super) trait Kernel {
    fn node(node: &Node, r: &RayData, t_min: f32, t_max: f32) -> (u32, [f32; WIDTH]);
    fn packet(p: &Packet, r: &RayData, t_min: f32, t_max: f32) -> Option<LaneHit>;
}

/// The baseline target: the auto-vectorised lane loops.
pub(super) struct Portable;

impl Kernel for Portable {
    #[inline(always)]
    fn node(node: &Node, r: &RayData, t_min: f32, t_max: f32) -> (u32, [f32; WIDTH]) {
        intersect_node(node, r, t_min, t_max)
    }

    #[inline(always)]
    fn packet(p: &Packet, r: &RayData, t_min: f32, t_max: f32) -> Option<LaneHit> {
        intersect_packet(p, r, t_min, t_max)
    }
}

/// AVX2 intrinsics: LLVM builds the hit masks of the lane loops from `bool` arrays with chains
/// of pack/shift/or steps and picks the nearest lane with scalar compares; `vmovmskps` and a
/// vector minimum do each in a few instructions.
#[cfg(target_arch = "x86_64")]
pub(super) struct Avx2;

#[cfg(target_arch = "x86_64")]
impl Kernel for Avx2 {
    #[inline(always)]
    fn node(node: &Node, r: &RayData, t_min: f32, t_max: f32) -> (u32, [f32; WIDTH]) {
        // SAFETY: `Avx2` is only used by the traversals compiled for the AVX2 level
        // (`simd_level!`), which run only when `Simd::best` allows that level.
        unsafe { intersect_node_avx2(node, r, t_min, t_max) }
    }

    #[inline(always)]
    fn packet(p: &Packet, r: &RayData, t_min: f32, t_max: f32) -> Option<LaneHit> {
        // SAFETY: as in `node`.
        unsafe { intersect_packet_avx2(p, r, t_min, t_max) }
    }
}

simd_level! { Avx2
    /// [`intersect_node`] with AVX2 intrinsics: `vmaxps(a, b)` is `a > b ? a : b` and
    /// `vminps(a, b)` is `a < b ? a : b`, the portable code's `max` and `min` exactly.
    #[inline]
    unsafe fn intersect_node_avx2(
        node: &Node,
        r: &RayData,
        t_min: f32,
        t_max: f32,
    ) -> (u32, [f32; WIDTH]) {
        use std::arch::x86_64::*;
        let slab = |plane: &[f32; WIDTH], o: f32, inv: f32| {
            _mm256_mul_ps(
                _mm256_sub_ps(_mm256_loadu_ps(plane.as_ptr()), _mm256_set1_ps(o)),
                _mm256_set1_ps(inv),
            )
        };
        let [nx, ny, nz] = r.near;
        let [ox, oy, oz] = r.o;
        let [ix, iy, iz] = r.inv;
        let t_near = _mm256_max_ps(
            _mm256_max_ps(
                slab(&node.bounds[nx][0], ox, ix),
                slab(&node.bounds[ny][1], oy, iy),
            ),
            _mm256_max_ps(slab(&node.bounds[nz][2], oz, iz), _mm256_set1_ps(t_min)),
        );
        let t_far = _mm256_min_ps(
            _mm256_min_ps(
                slab(&node.bounds[1 - nx][0], ox, ix),
                slab(&node.bounds[1 - ny][1], oy, iy),
            ),
            _mm256_min_ps(slab(&node.bounds[1 - nz][2], oz, iz), _mm256_set1_ps(t_max)),
        );
        let far = _mm256_mul_ps(t_far, _mm256_set1_ps(ROBUST_FAR));
        let hit = _mm256_cmp_ps::<_CMP_LE_OQ>(t_near, far);
        let mut out = [0.0; WIDTH];
        _mm256_storeu_ps(out.as_mut_ptr(), t_near);
        (_mm256_movemask_ps(hit) as u32, out)
    }
}

simd_level! { Avx2
    /// [`intersect_packet`] with AVX2 intrinsics on the eight lanes of a packet: the same
    /// operations in the same order (`_CMP_NEQ_UQ` is Rust's `!=`, the ordered compares its `>=`
    /// and `<`), then the first lane holding the minimum t, as the portable scan picks it.
    #[inline]
    unsafe fn intersect_packet_avx2(
        p: &Packet,
        r: &RayData,
        t_min: f32,
        t_max: f32,
    ) -> Option<LaneHit> {
        use std::arch::x86_64::*;
        let load = |a: &[f32; PACKET]| _mm256_loadu_ps(a.as_ptr());
        let (mul, sub, add) = (_mm256_mul_ps, _mm256_sub_ps, _mm256_add_ps);
        let dot = |a: [__m256; 3], b: [__m256; 3]| {
            add(add(mul(a[0], b[0]), mul(a[1], b[1])), mul(a[2], b[2]))
        };
        let [dx, dy, dz] = r.d.map(|x| _mm256_set1_ps(x));
        let [ox, oy, oz] = r.o.map(|x| _mm256_set1_ps(x));
        let c = [
            sub(load(&p.v0[0]), ox),
            sub(load(&p.v0[1]), oy),
            sub(load(&p.v0[2]), oz),
        ];
        let rv = [
            sub(mul(dy, c[2]), mul(dz, c[1])),
            sub(mul(dz, c[0]), mul(dx, c[2])),
            sub(mul(dx, c[1]), mul(dy, c[0])),
        ];
        let [e1, e2] = [&p.e1, &p.e2].map(|a| [load(&a[0]), load(&a[1]), load(&a[2])]);
        let ng = [
            sub(mul(e1[1], e2[2]), mul(e2[1], e1[2])),
            sub(mul(e1[2], e2[0]), mul(e2[2], e1[0])),
            sub(mul(e1[0], e2[1]), mul(e2[0], e1[1])),
        ];
        let det = dot(ng, [dx, dy, dz]);
        let inv_det = _mm256_div_ps(_mm256_set1_ps(1.0), det);
        let u = mul(dot(rv, e2), inv_det);
        let v = mul(dot(rv, e1), inv_det);
        let w = sub(sub(_mm256_set1_ps(1.0), u), v);
        let t = mul(dot(ng, c), inv_det);
        let signs = _mm256_castps_si256(_mm256_or_ps(_mm256_or_ps(u, v), w));
        let ok = _mm256_and_ps(
            _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_NEQ_UQ>(det, _mm256_setzero_ps()),
                _mm256_castsi256_ps(_mm256_cmpgt_epi32(signs, _mm256_set1_epi32(-1))),
            ),
            _mm256_and_ps(
                _mm256_cmp_ps::<_CMP_GE_OQ>(t, _mm256_set1_ps(t_min)),
                _mm256_cmp_ps::<_CMP_LT_OQ>(t, _mm256_set1_ps(t_max)),
            ),
        );
        let t = _mm256_blendv_ps(_mm256_set1_ps(f32::INFINITY), t, ok);
        // Horizontal minimum: halves, then pairs, then neighbours.
        let m = _mm256_min_ps(t, _mm256_permute2f128_ps::<1>(t, t));
        let m = _mm256_min_ps(m, _mm256_permute_ps::<0b01_00_11_10>(m));
        let m = _mm256_min_ps(m, _mm256_permute_ps::<0b10_11_00_01>(m));
        let t_best = _mm256_cvtss_f32(m);
        (t_best < t_max).then(|| {
            let lane =
                _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_EQ_OQ>(t, m)).trailing_zeros() as usize;
            let (mut us, mut vs) = ([0.0; PACKET], [0.0; PACKET]);
            _mm256_storeu_ps(us.as_mut_ptr(), u);
            _mm256_storeu_ps(vs.as_mut_ptr(), v);
            (lane, t_best, us[lane], vs[lane])
        })
    }
}

/// Möller–Trumbore ray/triangle test on eight triangles at once (Möller & Trumbore 1997, in the
/// form of obvhs's `RtTriangle::intersect`: with c = v0 − o and r = d × c, det = ng·d,
/// u = r·e2 / det, v = r·e1 / det, t = ng·c / det; a hit needs u, v, 1 − u − v with a clear
/// sign bit and t in [t_min, t_max)). Returns the nearest hit lane as (lane, t, u, v).
#[inline(always)]
pub(super) fn intersect_packet(p: &Packet, r: &RayData, t_min: f32, t_max: f32) -> Option<LaneHit> {
    let [ox, oy, oz] = r.o;
    let [dx, dy, dz] = r.d;
    let mut t = [f32::INFINITY; PACKET];
    let mut u = [0f32; PACKET];
    let mut v = [0f32; PACKET];
    for l in 0..PACKET {
        let cx = p.v0[0][l] - ox;
        let cy = p.v0[1][l] - oy;
        let cz = p.v0[2][l] - oz;
        let rx = dy * cz - dz * cy;
        let ry = dz * cx - dx * cz;
        let rz = dx * cy - dy * cx;
        // ng = e1 × e2 in glam's operation order.
        let (e1, e2) = (&p.e1, &p.e2);
        let ngx = e1[1][l] * e2[2][l] - e2[1][l] * e1[2][l];
        let ngy = e1[2][l] * e2[0][l] - e2[2][l] * e1[0][l];
        let ngz = e1[0][l] * e2[1][l] - e2[0][l] * e1[1][l];
        let det = ngx * dx + ngy * dy + ngz * dz;
        let inv_det = 1.0 / det;
        let ul = (rx * p.e2[0][l] + ry * p.e2[1][l] + rz * p.e2[2][l]) * inv_det;
        let vl = (rx * p.e1[0][l] + ry * p.e1[1][l] + rz * p.e1[2][l]) * inv_det;
        let wl = 1.0 - ul - vl;
        let tl = (ngx * cx + ngy * cy + ngz * cz) * inv_det;
        let signs = ul.to_bits() | vl.to_bits() | wl.to_bits();
        let ok = det != 0.0 && signs & 0x8000_0000 == 0 && tl >= t_min && tl < t_max;
        t[l] = if ok { tl } else { f32::INFINITY };
        u[l] = ul;
        v[l] = vl;
    }
    let mut best = 0;
    for l in 1..PACKET {
        if t[l] < t[best] {
            best = l;
        }
    }
    (t[best] < t_max).then(|| (best, t[best], u[best], v[best]))
}
