//! Shadow rays: the occlusion test of next-event estimation, culled by the objects' world boxes
//! where a scene has few objects (a segment that misses every box needs no BVH traversal).

use super::geometry::{slab_misses, Accel, Ray, Slab};
use super::light::LightSamples;
use super::shading::{offset_origin, ShadingPoint};
use glam::{Vec3, Vec3A};

/// Shadow queries, optionally culled: with the world boxes of a scene's few objects, a shadow
/// segment that misses every box is unoccluded without traversing the BVH; any other segment
/// asks the BVH. Exact: the BVH reports an occluder only where the segment meets a triangle, a
/// triangle lies inside its object's box, and the boxes are widened by a margin
/// ([`ShadowTest::MARGIN`] of the scene scale, a quarter of the ray-origin offset) hundreds of
/// times larger than the rounding of a hit point (≲ 1e-7 of the scene scale), so a segment the
/// slab test finds outside every box cannot be one the BVH finds blocked.
#[derive(Clone)]
pub struct ShadowTest<'a> {
    pub(super) accel: &'a Accel,
    /// Widened world boxes of the objects, one lane each; `None`: always ask the BVH.
    boxes: Option<BoxLanes>,
}

/// Up to [`ShadowTest::MAX_BOXES`] world boxes as structure-of-arrays lanes (lower and upper
/// corner by axis, one lane per box), so that one segment's slab tests against all of them run
/// as one loop in SIMD lanes ([`BoxLanes::all_missed`]) instead of one box after the other.
#[derive(Clone, Debug)]
struct BoxLanes {
    lo: [[f32; ShadowTest::MAX_BOXES]; 3],
    hi: [[f32; ShadowTest::MAX_BOXES]; 3],
    /// How many lanes hold a box (the rest are not read).
    n: usize,
}

impl BoxLanes {
    /// The boxes (min, max), at most [`ShadowTest::MAX_BOXES`] of them.
    fn new(boxes: &[(Vec3A, Vec3A)]) -> BoxLanes {
        assert!(boxes.len() <= ShadowTest::MAX_BOXES);
        let mut b = BoxLanes {
            lo: [[0.0; ShadowTest::MAX_BOXES]; 3],
            hi: [[0.0; ShadowTest::MAX_BOXES]; 3],
            n: boxes.len(),
        };
        for (k, (lo, hi)) in boxes.iter().enumerate() {
            for a in 0..3 {
                (b.lo[a][k], b.hi[a][k]) = (lo[a], hi[a]);
            }
        }
        b
    }

    /// Box `k` as (min, max) arrays.
    #[inline(always)]
    fn get(&self, k: usize) -> ([f32; 3], [f32; 3]) {
        (self.lo.map(|c| c[k]), self.hi.map(|c| c[k]))
    }

    /// Whether the segment `o + t·d`, t in [0, t_max] (`inv` = 1/d), surely misses every box:
    /// the slab test ([`slab_misses`]) of every lane at once, axis by axis, the lanes past `n`
    /// counted as missed.
    #[inline(always)]
    fn all_missed(&self, o: [f32; 3], inv: [f32; 3], t_max: f32) -> bool {
        let mut slab = [Slab::new(t_max); ShadowTest::MAX_BOXES];
        for a in 0..3 {
            let (lo, hi) = (&self.lo[a], &self.hi[a]);
            for (k, s) in slab.iter_mut().enumerate() {
                s.clip(o[a], inv[a], lo[k], hi[k]);
            }
        }
        let mut all = true;
        for (k, s) in slab.iter().enumerate() {
            all &= s.missed() | (k >= self.n);
        }
        all
    }
}

impl<'a> ShadowTest<'a> {
    /// Box margin as a fraction of [`Accel::scale`] (ray origins are offset by 2e-5 of it).
    pub const MARGIN: f32 = 5e-6;
    /// Above this many objects the boxes cost more than the BVH they would skip.
    pub const MAX_BOXES: usize = 8;

    /// No culling: every query goes to the BVH.
    pub fn bvh(accel: &'a Accel) -> Self {
        ShadowTest { accel, boxes: None }
    }

    /// Culling by the objects' world boxes (none when the scene has more than
    /// [`ShadowTest::MAX_BOXES`] objects or a non-finite vertex).
    pub fn culled(accel: &'a Accel) -> Self {
        let margin = Vec3::splat(Self::MARGIN * accel.scale());
        let boxes: Option<Vec<(Vec3A, Vec3A)>> = (accel.instances.len() <= Self::MAX_BOXES)
            .then(|| {
                accel
                    .instances
                    .iter()
                    .filter(|inst| !inst.mesh.positions.is_empty())
                    .map(|inst| {
                        let (lo, hi) = inst.mesh.positions.iter().fold(
                            (Vec3::INFINITY, Vec3::NEG_INFINITY),
                            |(lo, hi), &p| {
                                let w = inst.transform.point_to_world(p);
                                (lo.min(w), hi.max(w))
                            },
                        );
                        ((lo - margin).into(), (hi + margin).into())
                    })
                    .collect()
            })
            .filter(|b: &Vec<(Vec3A, Vec3A)>| {
                b.iter().all(|(lo, hi)| lo.is_finite() && hi.is_finite())
            });
        ShadowTest {
            accel,
            boxes: boxes.as_deref().map(BoxLanes::new),
        }
    }

    /// True when nothing blocks the segment `o + t·d`, t in (0, t_max) ([`Accel::unoccluded`]).
    #[inline(always)]
    pub fn unoccluded(&self, ray: &Ray, t_max: f32) -> bool {
        if let Some(boxes) = &self.boxes {
            let inv = Vec3A::ONE / Vec3A::from(ray.d);
            if boxes.all_missed(ray.o.to_array(), inv.to_array(), t_max) {
                return true;
            }
        }
        self.accel.unoccluded(ray, t_max)
    }

    /// For the shadow segment from `sp` towards each sample of `ls` (as `light_term` builds
    /// it), whether the boxes alone show it unoccluded (`culled[k]`; all false without boxes).
    /// The segments are set up in one loop and tested in one loop per box, so the slab tests
    /// run in SIMD lanes.
    #[inline(always)]
    pub fn culled_many(
        &self,
        sp: &ShadingPoint,
        ls: &LightSamples,
        seg: &mut Segments,
        culled: &mut Vec<bool>,
    ) {
        let n = ls.len();
        culled.clear();
        culled.resize(n, self.boxes.is_some());
        let Some(boxes) = &self.boxes else {
            return;
        };
        for c in seg.o.iter_mut().chain(&mut seg.inv).chain([&mut seg.t_max]) {
            c.resize(n, 0.0);
        }
        let [wx, wy, wz] = &ls.wi;
        let (wx, wy, wz, dist) = (&wx[..n], &wy[..n], &wz[..n], &ls.dist[..n]);
        let ([ox, oy, oz], [ix, iy, iz]) = (&mut seg.o, &mut seg.inv);
        let (ox, oy, oz) = (&mut ox[..n], &mut oy[..n], &mut oz[..n]);
        let (ix, iy, iz, t_max) = (
            &mut ix[..n],
            &mut iy[..n],
            &mut iz[..n],
            &mut seg.t_max[..n],
        );
        for k in 0..n {
            let d = Vec3::new(wx[k], wy[k], wz[k]);
            [ox[k], oy[k], oz[k]] = offset_origin(sp, d).to_array();
            [ix[k], iy[k], iz[k]] = (Vec3::ONE / d).to_array();
            t_max[k] = shadow_t_max(dist[k]);
        }
        let culled = &mut culled[..n];
        for b in 0..boxes.n {
            let (lo, hi) = boxes.get(b);
            for k in 0..n {
                let (o, inv) = ([ox[k], oy[k], oz[k]], [ix[k], iy[k], iz[k]]);
                culled[k] &= slab_misses(o, inv, t_max[k], lo, hi);
            }
        }
    }
}

/// Shadow segments by component (origin, 1/direction, length), scratch of
/// [`ShadowTest::culled_many`].
#[derive(Clone, Debug, Default)]
pub struct Segments {
    o: [Vec<f32>; 3],
    inv: [Vec<f32>; 3],
    t_max: Vec<f32>,
}

/// How far a shadow ray towards a light sample at distance `dist` looks: just short of the
/// light (so the light's own surface never counts), or without end for lights at infinity.
#[inline(always)]
pub(super) fn shadow_t_max(dist: f32) -> f32 {
    if dist.is_finite() {
        dist * (1.0 - 1e-4)
    } else {
        f32::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Pcg32;

    /// One segment against the box lanes ([`BoxLanes::all_missed`]) says what the slab test of
    /// every box one by one says ([`slab_misses`]), for any number of boxes up to the lanes,
    /// segments that start inside, graze or run parallel to a face included.
    #[test]
    fn box_lanes_equal_one_box_at_a_time() {
        let mut rng = Pcg32::new(29, 7);
        let mut v = |s: f32| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * s;
        let mut checked = [0usize; 2];
        for trial in 0..4000 {
            let n = trial % (ShadowTest::MAX_BOXES + 1);
            let boxes: Vec<(Vec3A, Vec3A)> = (0..n)
                .map(|_| {
                    let lo = v(10.0) - Vec3::splat(5.0);
                    (lo.into(), (lo + v(6.0)).into())
                })
                .collect();
            let lanes = BoxLanes::new(&boxes);
            let o = v(12.0) - Vec3::splat(6.0);
            let mut d = v(2.0) - Vec3::ONE;
            if trial % 5 == 0 {
                d.x = 0.0; // parallel to the x slabs
            }
            let inv = (Vec3A::ONE / Vec3A::from(d)).to_array();
            let t_max = v(20.0).x;
            let one_by_one = boxes.iter().all(|(lo, hi)| {
                slab_misses(o.to_array(), inv, t_max, lo.to_array(), hi.to_array())
            });
            assert_eq!(
                lanes.all_missed(o.to_array(), inv, t_max),
                one_by_one,
                "trial {trial}"
            );
            checked[one_by_one as usize] += 1;
        }
        assert!(checked.iter().all(|&c| c > 200), "{checked:?}");
    }
}
