//! The ray–box slab test (Kay & Kajiya 1986), scalar and per axis for SIMD loops.

use glam::Vec3A;

/// Slab test (Kay & Kajiya 1986) of the segment `o + t·d`, t in [0, t_max], against a box, with
/// `inv` = 1/d per axis (±∞ for d = 0): true only when the segment surely misses. A NaN (an
/// origin exactly on a slab plane of an axis the ray runs parallel to) answers "may hit".
#[inline]
pub(crate) fn segment_misses_box(o: Vec3A, inv: Vec3A, t_max: f32, lo: Vec3A, hi: Vec3A) -> bool {
    slab_misses(
        o.to_array(),
        inv.to_array(),
        t_max,
        lo.to_array(),
        hi.to_array(),
    )
}

/// [`segment_misses_box`] on plain arrays, written with comparisons and selects only so that a
/// loop of it over many segments vectorises.
#[inline(always)]
pub(crate) fn slab_misses(
    o: [f32; 3],
    inv: [f32; 3],
    t_max: f32,
    lo: [f32; 3],
    hi: [f32; 3],
) -> bool {
    let mut slab = Slab::new(t_max);
    for a in 0..3 {
        slab.clip(o[a], inv[a], lo[a], hi[a]);
    }
    slab.missed()
}

/// The state of [`slab_misses`] after some axes: the parameter interval [t0, t1] left, and
/// whether a NaN was met. One axis at a time ([`Slab::clip`]), so that a loop over many boxes
/// or segments keeps one of these per lane.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Slab {
    t0: f32,
    t1: f32,
    nan: bool,
}

impl Slab {
    /// The whole segment, t in [0, t_max].
    #[inline(always)]
    pub(crate) fn new(t_max: f32) -> Slab {
        Slab {
            t0: 0.0,
            t1: t_max,
            nan: false,
        }
    }

    /// Clipped to the slab [lo, hi] of one axis (origin `o`, 1/direction `inv` on that axis).
    #[inline(always)]
    pub(crate) fn clip(&mut self, o: f32, inv: f32, lo: f32, hi: f32) {
        let (ta, tb) = ((lo - o) * inv, (hi - o) * inv);
        self.nan |= ta.is_nan() | tb.is_nan();
        let (near, far) = if ta < tb { (ta, tb) } else { (tb, ta) };
        self.t0 = if near > self.t0 { near } else { self.t0 };
        self.t1 = if far < self.t1 { far } else { self.t1 };
    }

    /// Whether the segment surely misses the box (an empty interval, no NaN).
    #[inline(always)]
    pub(crate) fn missed(&self) -> bool {
        !self.nan & (self.t0 > self.t1)
    }
}
