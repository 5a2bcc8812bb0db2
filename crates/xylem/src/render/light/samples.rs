//! Samples of one light at many places (a light sweep's frames) as structure-of-arrays columns.

use super::sphere::ConeSample;
use super::{Light, LightSample, LightU};
use glam::Vec3;

/// Samples of one light from one point at many places of the light (the frames of a light
/// sweep) with the same numbers, as columns (structure of arrays), for the batch next-event
/// terms of `render::integrator::light_terms`. A sphere light is sampled by one loop over
/// the frames' centres ([`LightSamples::sample_sphere`]): no frame depends on another, so the
/// loop runs in SIMD lanes instead of one latency-bound chain of square roots and divisions per
/// frame. Values bit-identical to [`Light::sample_at`] (tested).
#[derive(Clone, Debug, Default)]
pub struct LightSamples {
    /// Unit directions towards the light (world), by component.
    pub wi: [Vec<f32>; 3],
    /// Distance to each light sample (infinite for distant and environment lights).
    pub dist: Vec<f32>,
    /// Solid-angle density (1 for delta lights); 0 where there is no sample.
    pub pdf: Vec<f32>,
    /// Incident radiance of each sample (irradiance at normal incidence for delta lights), by
    /// channel.
    pub li: [Vec<f32>; 3],
    /// Whether the light is a delta light (the same in every place).
    pub is_delta: bool,
}

impl LightSamples {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.pdf.len()
    }

    /// True when there are no samples.
    pub fn is_empty(&self) -> bool {
        self.pdf.is_empty()
    }

    fn resize(&mut self, n: usize) {
        for c in self.wi.iter_mut().chain(&mut self.li) {
            c.resize(n, 0.0);
        }
        self.dist.resize(n, 0.0);
        self.pdf.resize(n, 0.0);
    }

    /// Samples the sphere of radius `radius` and radiance `radiance` centred at `centers[k]` (by
    /// component) from `p`, for every k, with numbers `u`.
    #[inline(always)]
    pub fn sample_sphere(
        &mut self,
        p: Vec3,
        centers: &[Vec<f32>; 3],
        radius: f32,
        radiance: Vec3,
        u: &LightU,
    ) {
        let n = centers[0].len();
        self.resize(n);
        self.is_delta = false;
        for (c, v) in self.li.iter_mut().zip(radiance.to_array()) {
            c.fill(v);
        }
        let [cx, cy, cz] = centers;
        let (cx, cy, cz) = (&cx[..n], &cy[..n], &cz[..n]);
        let [wx, wy, wz] = &mut self.wi;
        let (wx, wy, wz) = (&mut wx[..n], &mut wy[..n], &mut wz[..n]);
        let (dist, pdf) = (&mut self.dist[..n], &mut self.pdf[..n]);
        let r2 = radius * radius;
        for k in 0..n {
            let to = Vec3::new(cx[k], cy[k], cz[k]) - p;
            let c = ConeSample::new(to, r2, u.u.x, u.azimuth);
            [wx[k], wy[k], wz[k]] = c.wi;
            dist[k] = c.dist;
            pdf[k] = if c.valid { c.pdf } else { 0.0 };
        }
    }

    /// Samples from `p` of `lights` — one light's place in each frame, any kind of light — one
    /// at a time ([`Light::sample_at`]); a failed sample is stored with density 0.
    pub(crate) fn sample_each<'a>(
        &mut self,
        p: Vec3,
        lights: impl ExactSizeIterator<Item = &'a Light>,
        u: &LightU,
    ) {
        self.resize(lights.len());
        self.is_delta = false;
        for (k, light) in lights.enumerate() {
            self.is_delta = light.is_delta();
            let s = light.sample_at(p, u);
            let s = s.unwrap_or(LightSample {
                wi: Vec3::ZERO,
                dist: 0.0,
                li: Vec3::ZERO,
                pdf: 0.0,
                is_delta: self.is_delta,
            });
            for (c, v) in self.wi.iter_mut().zip(s.wi.to_array()) {
                c[k] = v;
            }
            for (c, v) in self.li.iter_mut().zip(s.li.to_array()) {
                c[k] = v;
            }
            (self.dist[k], self.pdf[k]) = (s.dist, s.pdf);
        }
    }

    /// Place `k`'s sample as [`Light::sample_at`] returns it (`None` where it returns `None`).
    #[inline]
    pub fn get(&self, k: usize) -> Option<LightSample> {
        (self.pdf[k] != 0.0).then(|| LightSample {
            wi: Vec3::new(self.wi[0][k], self.wi[1][k], self.wi[2][k]),
            dist: self.dist[k],
            li: Vec3::new(self.li[0][k], self.li[1][k], self.li[2][k]),
            pdf: self.pdf[k],
            is_delta: self.is_delta,
        })
    }
}
