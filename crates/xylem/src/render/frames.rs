//! The lights of the frames a render makes at once: fixed lights plus, optionally, one light that
//! takes another place in each frame (a light sweep). A plain render is one frame of fixed lights.
//!
//! Camera, geometry and materials are the same in every frame, so everything that does not
//! depend on the lights — the camera ray, the path's vertices, BSDF samples, Russian roulette —
//! is computed once per pixel sample and only light-dependent terms are worked out per frame
//! (`integrator::radiance_frames`). What lets a frame skip work is prepared here once: the
//! lights that do not move, the box the moving light stays in, and a sphere light's centres by
//! component for sampling all frames in SIMD lanes.

use super::geometry::segment_misses_box;
use super::light::{nearest_light, sphere_line_misses, Light, LightHit, SphereLight};
use super::Ray;
use glam::{Vec3, Vec3A};

/// Lights for a run of frames: frame k is `lights` with light `moving` (if any) replaced by
/// `places[k]`.
#[derive(Clone, Debug)]
pub struct LightFrames {
    /// Each frame's lights, in the scene's order.
    frames: Vec<Vec<Light>>,
    /// The index of the light that moves, if one does.
    moving: Option<usize>,
    /// The lights without the moving one, in their order.
    fixed: Vec<Light>,
    /// A box holding the moving light in every frame, widened by a margin far above the rounding
    /// of a ray–sphere test; `None` when rays cannot meet the light at all (a delta light).
    swept: Option<(Vec3A, Vec3A)>,
    /// The moving light's centres (by component), radius and radiance when it is a sphere in
    /// every frame: sampled for all frames at once.
    sphere: Option<MovingSphere>,
    /// Whether any light in any frame can be met by a ray (not every light is a delta light).
    hittable: bool,
}

/// A sphere light's places over the frames.
#[derive(Clone, Debug)]
pub(crate) struct MovingSphere {
    pub(crate) centers: [Vec<f32>; 3],
    pub(crate) radius: f32,
    pub(crate) radiance: Vec3,
}

impl LightFrames {
    /// One frame lit by `lights`.
    pub fn fixed(lights: &[Light]) -> Self {
        Self::build(vec![lights.to_vec()], None)
    }

    /// One frame per entry of `places`: `lights` with light `moving` replaced by that entry.
    ///
    /// # Panics
    /// If `moving` is not an index of `lights`.
    pub fn moving(lights: &[Light], moving: usize, places: Vec<Light>) -> Self {
        assert!(moving < lights.len(), "moving light {moving} out of range");
        let frames = places
            .into_iter()
            .map(|place| {
                let mut fl = lights.to_vec();
                fl[moving] = place;
                fl
            })
            .collect();
        Self::build(frames, Some(moving))
    }

    fn build(frames: Vec<Vec<Light>>, moving: Option<usize>) -> Self {
        let first = frames.first().cloned().unwrap_or_default();
        let fixed = first
            .iter()
            .enumerate()
            .filter(|&(i, _)| Some(i) != moving)
            .map(|(_, l)| l.clone())
            .collect();
        let hittable = frames.iter().flatten().any(|l| !l.is_delta());
        let (swept, sphere) = match moving {
            Some(m) => (swept_box(&frames, m), MovingSphere::new(&frames, m)),
            None => (None, None),
        };
        LightFrames {
            frames,
            moving,
            fixed,
            swept,
            sphere,
            hittable,
        }
    }

    /// Number of frames.
    pub fn len(&self) -> usize {
        self.frames.len()
    }

    /// True when there are no frames.
    pub fn is_empty(&self) -> bool {
        self.frames.is_empty()
    }

    /// Frame `k`'s lights, in the scene's order.
    pub fn frame(&self, k: usize) -> &[Light] {
        &self.frames[k]
    }

    /// The lights of the first frame (their order and kinds are those of every frame).
    pub(crate) fn first(&self) -> &[Light] {
        self.frames.first().map_or(&[], |f| f.as_slice())
    }

    /// The index of the light that moves from frame to frame, if any.
    pub(crate) fn moving_index(&self) -> Option<usize> {
        self.moving
    }

    /// The moving light in every frame.
    pub(crate) fn moving_places(&self, moving: usize) -> impl ExactSizeIterator<Item = &Light> {
        self.frames.iter().map(move |fl| &fl[moving])
    }

    pub(crate) fn sphere(&self) -> Option<&MovingSphere> {
        self.sphere.as_ref()
    }

    /// Whether a ray can meet any light in any frame.
    pub(crate) fn hittable(&self) -> bool {
        self.hittable
    }

    /// Calls `f(k, hit)` for every frame k where `nearest_light(frame k's lights, ray, t_max)`
    /// is `Some(hit)` (frames whose ray meets no light are skipped; the index is the light's
    /// place in the frame's lights). When the ray surely misses the moving light's box (or
    /// nothing moves), the answer is that of the fixed lights alone, found once.
    #[inline(always)]
    pub(crate) fn nearest_per_frame(
        &self,
        ray: &Ray,
        t_max: f32,
        mut f: impl FnMut(usize, (usize, LightHit)),
    ) {
        let misses = self.moving.is_none()
            || self.swept.is_none_or(|(lo, hi)| {
                let inv = Vec3A::ONE / Vec3A::from(ray.d);
                segment_misses_box(ray.o.into(), inv, f32::INFINITY, lo, hi)
            });
        // An index among the fixed lights as one among the frame's lights.
        let moving = self.moving;
        let fixed_place = move |(i, hit): (usize, LightHit)| {
            (
                if moving.is_some_and(|m| i >= m) {
                    i + 1
                } else {
                    i
                },
                hit,
            )
        };
        if misses {
            if let Some(hit) = nearest_light(&self.fixed, ray, t_max).map(fixed_place) {
                for k in 0..self.frames.len() {
                    f(k, hit);
                }
            }
        } else if let Some(s) = &self.sphere {
            // A frame whose sphere the ray's line misses (`sphere_line_misses`, the test that
            // `intersect_sphere` starts with) has the fixed lights' answer; only the others are
            // asked in full. The misses are found a block of frames at a time in SIMD lanes.
            const BLOCK: usize = 16;
            let fixed = nearest_light(&self.fixed, ray, t_max).map(fixed_place);
            let [cx, cy, cz] = &s.centers;
            for start in (0..self.frames.len()).step_by(BLOCK) {
                let n = BLOCK.min(self.frames.len() - start);
                let mut miss = [false; BLOCK];
                for j in 0..n {
                    let c = Vec3::new(cx[start + j], cy[start + j], cz[start + j]);
                    miss[j] = sphere_line_misses(ray, c, s.radius);
                }
                for (j, &missed) in miss.iter().enumerate().take(n) {
                    let k = start + j;
                    let hit = if missed {
                        fixed
                    } else {
                        nearest_light(&self.frames[k], ray, t_max)
                    };
                    if let Some(hit) = hit {
                        f(k, hit);
                    }
                }
            }
        } else {
            for (k, lights) in self.frames.iter().enumerate() {
                if let Some(hit) = nearest_light(lights, ray, t_max) {
                    f(k, hit);
                }
            }
        }
    }
}

/// A box holding light `moving` in every frame; `None` when every frame's light is a delta light
/// (no ray meets it); an unbounded box for a moving light of another kind.
fn swept_box(frames: &[Vec<Light>], moving: usize) -> Option<(Vec3A, Vec3A)> {
    let swept = frames
        .iter()
        .try_fold(None, |acc: Option<(Vec3, Vec3)>, fl| {
            let Light::Sphere(SphereLight { center, radius, .. }) = fl[moving] else {
                return if fl[moving].is_delta() {
                    Some(acc)
                } else {
                    None
                };
            };
            // Rounding of `intersect_sphere` is ~1e-7 of the coordinates; 1e-3 of them is safe.
            let r = Vec3::splat(radius + 1e-3 * (center.abs().max_element() + radius));
            let (lo, hi) = acc.unwrap_or((center, center));
            Some(Some((lo.min(center - r), hi.max(center + r))))
        });
    match swept {
        Some(Some((lo, hi))) => Some((lo.into(), hi.into())),
        Some(None) => None,
        None => Some((Vec3A::NEG_INFINITY, Vec3A::INFINITY)),
    }
}

impl MovingSphere {
    /// The moving light of `frames` if it is one sphere (radius, radiance) in every frame.
    fn new(frames: &[Vec<Light>], moving: usize) -> Option<Self> {
        let mut m = MovingSphere {
            centers: Default::default(),
            radius: 0.0,
            radiance: Vec3::ZERO,
        };
        for fl in frames {
            let Light::Sphere(SphereLight {
                center,
                radius,
                radiance,
            }) = fl[moving]
            else {
                return None;
            };
            if !m.centers[0].is_empty() && (radius, radiance) != (m.radius, m.radiance) {
                return None;
            }
            for (c, v) in m.centers.iter_mut().zip(center.to_array()) {
                c.push(v);
            }
            (m.radius, m.radiance) = (radius, radiance);
        }
        Some(m)
    }
}
