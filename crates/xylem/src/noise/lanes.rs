//! Lane-wise `f32` / `u32` vectors for the lattice-noise kernels, so one kernel body
//! (gradient.rs) serves SSE2 (4 lanes, the x86-64 baseline), AVX2 (8) and AVX-512 (16).
//!
//! Every method is `#[inline(always)]`: it compiles into the `#[target_feature]` function that
//! calls it, with that function's instructions. Callers must only use a lane type whose level
//! the CPU has ([`crate::simd::Simd::best`]); that is what makes the methods `unsafe`.
//! Every operation is lane-wise and exact in the same way as its scalar counterpart (IEEE f32
//! add / sub / mul without contraction, wrapping u32 arithmetic), so kernels built from them
//! give the scalar kernel's values.

#[cfg(target_arch = "x86_64")]
use glam::Vec3;
#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::*;

/// A vector of `N` f32 lanes with a matching vector `I` of u32 lanes.
#[cfg(target_arch = "x86_64")]
pub(crate) trait Lanes: Copy {
    type I: Copy;
    const N: usize;
    unsafe fn splat(v: f32) -> Self;
    unsafe fn splat_i(v: u32) -> Self::I;
    /// The first `N` values of `v` (`v.len() ≥ N`).
    unsafe fn load(v: &[f32]) -> Self;
    unsafe fn load_i(v: &[u32]) -> Self::I;
    /// Writes the lanes to the first `N` places of `out`.
    unsafe fn store(self, out: &mut [f32]);
    /// The x, y and z lanes of the first `N` points of `p` (`p.len() ≥ N`).
    unsafe fn load_xyz(p: &[Vec3]) -> (Self, Self, Self);
    unsafe fn add(self, b: Self) -> Self;
    unsafe fn sub(self, b: Self) -> Self;
    unsafe fn mul(self, b: Self) -> Self;
    /// |self| (sign bit cleared, as `f32::abs`).
    unsafe fn abs(self) -> Self;
    unsafe fn add_i(a: Self::I, b: Self::I) -> Self::I;
    unsafe fn xor_i(a: Self::I, b: Self::I) -> Self::I;
    unsafe fn and_i(a: Self::I, b: Self::I) -> Self::I;
    /// Low 32 bits of the lane-wise product (wrapping multiply).
    unsafe fn mul_lo(a: Self::I, b: Self::I) -> Self::I;
    /// Logical right shift by `k` bits (a constant after inlining, so an immediate shift).
    unsafe fn shr(a: Self::I, k: i32) -> Self::I;
    /// The lattice cell `trunc(x) − signbit(x)` (as `gradient::cell_of`) and `x − cell`.
    unsafe fn cell(self) -> (Self::I, Self);
    /// `self` with its sign bit flipped where bit `bit` of `bits` is set. (By a bit test, not a
    /// shift of the bit to the sign: LLVM turns a left shift of the hash product into a second
    /// vector multiply, which is slower.)
    unsafe fn flip_sign(self, bits: Self::I, bit: u32) -> Self;
    /// `self` with the lanes where `a == b` replaced by +0.
    unsafe fn zero_where_eq(self, a: Self::I, b: u32) -> Self;
}

#[cfg(target_arch = "x86_64")]
impl Lanes for __m128 {
    type I = __m128i;
    const N: usize = 4;
    #[inline(always)]
    unsafe fn splat(v: f32) -> Self {
        _mm_set1_ps(v)
    }
    #[inline(always)]
    unsafe fn splat_i(v: u32) -> __m128i {
        _mm_set1_epi32(v as i32)
    }
    #[inline(always)]
    unsafe fn load(v: &[f32]) -> Self {
        _mm_loadu_ps(v[..4].as_ptr())
    }
    #[inline(always)]
    unsafe fn load_i(v: &[u32]) -> __m128i {
        _mm_loadu_si128(v[..4].as_ptr() as *const __m128i)
    }
    #[inline(always)]
    unsafe fn store(self, out: &mut [f32]) {
        _mm_storeu_ps(out[..4].as_mut_ptr(), self)
    }
    #[inline(always)]
    unsafe fn load_xyz(p: &[Vec3]) -> (Self, Self, Self) {
        let p = &p[..4];
        (
            _mm_setr_ps(p[0].x, p[1].x, p[2].x, p[3].x),
            _mm_setr_ps(p[0].y, p[1].y, p[2].y, p[3].y),
            _mm_setr_ps(p[0].z, p[1].z, p[2].z, p[3].z),
        )
    }
    #[inline(always)]
    unsafe fn add(self, b: Self) -> Self {
        _mm_add_ps(self, b)
    }
    #[inline(always)]
    unsafe fn sub(self, b: Self) -> Self {
        _mm_sub_ps(self, b)
    }
    #[inline(always)]
    unsafe fn mul(self, b: Self) -> Self {
        _mm_mul_ps(self, b)
    }
    #[inline(always)]
    unsafe fn abs(self) -> Self {
        _mm_and_ps(self, _mm_castsi128_ps(_mm_set1_epi32(i32::MAX)))
    }
    #[inline(always)]
    unsafe fn add_i(a: __m128i, b: __m128i) -> __m128i {
        _mm_add_epi32(a, b)
    }
    #[inline(always)]
    unsafe fn xor_i(a: __m128i, b: __m128i) -> __m128i {
        _mm_xor_si128(a, b)
    }
    #[inline(always)]
    unsafe fn and_i(a: __m128i, b: __m128i) -> __m128i {
        _mm_and_si128(a, b)
    }
    /// SSE2 has only the 32×32→64 `pmuludq`: multiply even and odd lanes, keep the low halves.
    #[inline(always)]
    unsafe fn mul_lo(a: __m128i, b: __m128i) -> __m128i {
        let even = _mm_mul_epu32(a, b);
        let odd = _mm_mul_epu32(_mm_srli_epi64(a, 32), _mm_srli_epi64(b, 32));
        _mm_unpacklo_epi32(
            _mm_shuffle_epi32(even, 0b10_00_10_00),
            _mm_shuffle_epi32(odd, 0b10_00_10_00),
        )
    }
    #[inline(always)]
    unsafe fn shr(a: __m128i, k: i32) -> __m128i {
        _mm_srl_epi32(a, _mm_cvtsi32_si128(k))
    }
    #[inline(always)]
    unsafe fn cell(self) -> (__m128i, Self) {
        let i = _mm_add_epi32(
            _mm_cvttps_epi32(self),
            _mm_srai_epi32(_mm_castps_si128(self), 31),
        );
        (i, _mm_sub_ps(self, _mm_cvtepi32_ps(i)))
    }
    #[inline(always)]
    unsafe fn flip_sign(self, bits: __m128i, bit: u32) -> Self {
        let b = _mm_set1_epi32((1u32 << bit) as i32);
        let set = _mm_cmpeq_epi32(_mm_and_si128(bits, b), b);
        let sign = _mm_and_si128(set, _mm_set1_epi32(i32::MIN));
        _mm_xor_ps(self, _mm_castsi128_ps(sign))
    }
    #[inline(always)]
    unsafe fn zero_where_eq(self, a: __m128i, b: u32) -> Self {
        let eq = _mm_cmpeq_epi32(a, _mm_set1_epi32(b as i32));
        _mm_andnot_ps(_mm_castsi128_ps(eq), self)
    }
}

#[cfg(target_arch = "x86_64")]
impl Lanes for __m256 {
    type I = __m256i;
    const N: usize = 8;
    #[inline(always)]
    unsafe fn splat(v: f32) -> Self {
        _mm256_set1_ps(v)
    }
    #[inline(always)]
    unsafe fn splat_i(v: u32) -> __m256i {
        _mm256_set1_epi32(v as i32)
    }
    #[inline(always)]
    unsafe fn load(v: &[f32]) -> Self {
        _mm256_loadu_ps(v[..8].as_ptr())
    }
    #[inline(always)]
    unsafe fn load_i(v: &[u32]) -> __m256i {
        _mm256_loadu_si256(v[..8].as_ptr() as *const __m256i)
    }
    #[inline(always)]
    unsafe fn store(self, out: &mut [f32]) {
        _mm256_storeu_ps(out[..8].as_mut_ptr(), self)
    }
    /// Eight points are 24 consecutive floats in three registers; component c of point i sits at
    /// float 3i + c, and for each c those 8 positions fall in distinct lanes (3 is invertible mod
    /// 8). So two blends gather each component into one register and one permute orders it.
    #[inline(always)]
    unsafe fn load_xyz(p: &[Vec3]) -> (Self, Self, Self) {
        let f = p[..8].as_ptr() as *const f32;
        let (m0, m1, m2) = (
            _mm256_loadu_ps(f),
            _mm256_loadu_ps(f.add(8)),
            _mm256_loadu_ps(f.add(16)),
        );
        // Lanes taken from m1 / m2: x at m1 {1, 4, 7}, m2 {2, 5}; y at m1 {2, 5}, m2 {0, 3, 6};
        // z at m1 {0, 3, 6}, m2 {1, 4, 7}.
        let x = _mm256_blend_ps::<0b0010_0100>(_mm256_blend_ps::<0b1001_0010>(m0, m1), m2);
        let y = _mm256_blend_ps::<0b0100_1001>(_mm256_blend_ps::<0b0010_0100>(m0, m1), m2);
        let z = _mm256_blend_ps::<0b1001_0010>(_mm256_blend_ps::<0b0100_1001>(m0, m1), m2);
        (
            _mm256_permutevar8x32_ps(x, _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5)),
            _mm256_permutevar8x32_ps(y, _mm256_setr_epi32(1, 4, 7, 2, 5, 0, 3, 6)),
            _mm256_permutevar8x32_ps(z, _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7)),
        )
    }
    #[inline(always)]
    unsafe fn add(self, b: Self) -> Self {
        _mm256_add_ps(self, b)
    }
    #[inline(always)]
    unsafe fn sub(self, b: Self) -> Self {
        _mm256_sub_ps(self, b)
    }
    #[inline(always)]
    unsafe fn mul(self, b: Self) -> Self {
        _mm256_mul_ps(self, b)
    }
    #[inline(always)]
    unsafe fn abs(self) -> Self {
        _mm256_and_ps(self, _mm256_castsi256_ps(_mm256_set1_epi32(i32::MAX)))
    }
    #[inline(always)]
    unsafe fn add_i(a: __m256i, b: __m256i) -> __m256i {
        _mm256_add_epi32(a, b)
    }
    #[inline(always)]
    unsafe fn xor_i(a: __m256i, b: __m256i) -> __m256i {
        _mm256_xor_si256(a, b)
    }
    #[inline(always)]
    unsafe fn and_i(a: __m256i, b: __m256i) -> __m256i {
        _mm256_and_si256(a, b)
    }
    #[inline(always)]
    unsafe fn mul_lo(a: __m256i, b: __m256i) -> __m256i {
        _mm256_mullo_epi32(a, b)
    }
    #[inline(always)]
    unsafe fn shr(a: __m256i, k: i32) -> __m256i {
        _mm256_srl_epi32(a, _mm_cvtsi32_si128(k))
    }
    #[inline(always)]
    unsafe fn cell(self) -> (__m256i, Self) {
        let i = _mm256_add_epi32(
            _mm256_cvttps_epi32(self),
            _mm256_srai_epi32(_mm256_castps_si256(self), 31),
        );
        (i, _mm256_sub_ps(self, _mm256_cvtepi32_ps(i)))
    }
    #[inline(always)]
    unsafe fn flip_sign(self, bits: __m256i, bit: u32) -> Self {
        let b = _mm256_set1_epi32((1u32 << bit) as i32);
        let set = _mm256_cmpeq_epi32(_mm256_and_si256(bits, b), b);
        let sign = _mm256_and_si256(set, _mm256_set1_epi32(i32::MIN));
        _mm256_xor_ps(self, _mm256_castsi256_ps(sign))
    }
    #[inline(always)]
    unsafe fn zero_where_eq(self, a: __m256i, b: u32) -> Self {
        let eq = _mm256_cmpeq_epi32(a, _mm256_set1_epi32(b as i32));
        _mm256_andnot_ps(_mm256_castsi256_ps(eq), self)
    }
}

#[cfg(target_arch = "x86_64")]
impl Lanes for __m512 {
    type I = __m512i;
    const N: usize = 16;
    #[inline(always)]
    unsafe fn splat(v: f32) -> Self {
        _mm512_set1_ps(v)
    }
    #[inline(always)]
    unsafe fn splat_i(v: u32) -> __m512i {
        _mm512_set1_epi32(v as i32)
    }
    #[inline(always)]
    unsafe fn load(v: &[f32]) -> Self {
        _mm512_loadu_ps(v[..16].as_ptr())
    }
    #[inline(always)]
    unsafe fn load_i(v: &[u32]) -> __m512i {
        _mm512_loadu_si512(v[..16].as_ptr() as *const __m512i)
    }
    #[inline(always)]
    unsafe fn store(self, out: &mut [f32]) {
        _mm512_storeu_ps(out[..16].as_mut_ptr(), self)
    }
    /// Sixteen points are 48 consecutive floats in three registers; component c of point i is
    /// float 3i + c. A two-source permute picks those below 32 from the first two registers,
    /// a second one keeps them and fills in the rest from the third.
    #[inline(always)]
    unsafe fn load_xyz(p: &[Vec3]) -> (Self, Self, Self) {
        let f = p[..16].as_ptr() as *const f32;
        let (m0, m1, m2) = (
            _mm512_loadu_ps(f),
            _mm512_loadu_ps(f.add(16)),
            _mm512_loadu_ps(f.add(32)),
        );
        (
            component::<0>(m0, m1, m2),
            component::<1>(m0, m1, m2),
            component::<2>(m0, m1, m2),
        )
    }
    #[inline(always)]
    unsafe fn add(self, b: Self) -> Self {
        _mm512_add_ps(self, b)
    }
    #[inline(always)]
    unsafe fn sub(self, b: Self) -> Self {
        _mm512_sub_ps(self, b)
    }
    #[inline(always)]
    unsafe fn mul(self, b: Self) -> Self {
        _mm512_mul_ps(self, b)
    }
    #[inline(always)]
    unsafe fn abs(self) -> Self {
        _mm512_castsi512_ps(_mm512_and_si512(
            _mm512_castps_si512(self),
            _mm512_set1_epi32(i32::MAX),
        ))
    }
    #[inline(always)]
    unsafe fn add_i(a: __m512i, b: __m512i) -> __m512i {
        _mm512_add_epi32(a, b)
    }
    #[inline(always)]
    unsafe fn xor_i(a: __m512i, b: __m512i) -> __m512i {
        _mm512_xor_si512(a, b)
    }
    #[inline(always)]
    unsafe fn and_i(a: __m512i, b: __m512i) -> __m512i {
        _mm512_and_si512(a, b)
    }
    #[inline(always)]
    unsafe fn mul_lo(a: __m512i, b: __m512i) -> __m512i {
        _mm512_mullo_epi32(a, b)
    }
    #[inline(always)]
    unsafe fn shr(a: __m512i, k: i32) -> __m512i {
        _mm512_srl_epi32(a, _mm_cvtsi32_si128(k))
    }
    #[inline(always)]
    unsafe fn cell(self) -> (__m512i, Self) {
        let i = _mm512_add_epi32(
            _mm512_cvttps_epi32(self),
            _mm512_srai_epi32::<31>(_mm512_castps_si512(self)),
        );
        (i, _mm512_sub_ps(self, _mm512_cvtepi32_ps(i)))
    }
    #[inline(always)]
    unsafe fn flip_sign(self, bits: __m512i, bit: u32) -> Self {
        let set = _mm512_test_epi32_mask(bits, _mm512_set1_epi32((1u32 << bit) as i32));
        let v = _mm512_castps_si512(self);
        _mm512_castsi512_ps(_mm512_mask_xor_epi32(
            v,
            set,
            v,
            _mm512_set1_epi32(i32::MIN),
        ))
    }
    #[inline(always)]
    unsafe fn zero_where_eq(self, a: __m512i, b: u32) -> Self {
        _mm512_maskz_mov_ps(
            _mm512_cmpneq_epi32_mask(a, _mm512_set1_epi32(b as i32)),
            self,
        )
    }
}

#[cfg(target_arch = "x86_64")]
/// Component `C` of 16 points packed as 48 floats in `m0 ‖ m1 ‖ m2` (see `load_xyz`).
#[inline(always)]
unsafe fn component<const C: i32>(m0: __m512, m1: __m512, m2: __m512) -> __m512 {
    let (mut lo, mut hi) = ([0i32; 16], [0i32; 16]);
    for i in 0..16 {
        let at = 3 * i as i32 + C;
        // First pass: float `at` of m0 ‖ m1 (valid where at < 32). Second: lane i of the first
        // pass (0..16), or float at − 32 of m2 (16 + …).
        lo[i] = at & 31;
        hi[i] = if at < 32 { i as i32 } else { 16 + at - 32 };
    }
    let lo = _mm512_loadu_si512(lo.as_ptr() as *const __m512i);
    let hi = _mm512_loadu_si512(hi.as_ptr() as *const __m512i);
    _mm512_permutex2var_ps(_mm512_permutex2var_ps(m0, lo, m1), hi, m2)
}
