//! The environment light: constant, or a lat-long map sampled by luminance (pbrt-v4 §12.5).

use super::{LightHit, LightSample};
use crate::math::{uniform_sphere, PI, UNIFORM_SPHERE_PDF};
use crate::render::geometry::Ray;
use glam::{Vec2, Vec3};
use std::sync::Arc;

/// A constant environment or a lat-long map (z up; u = φ/2π with φ = atan2(y, x), v = θ/π).
#[derive(Clone, Debug)]
pub struct Environment {
    /// Radiance (W/(sr·mm²), linear RGB) of the constant environment, or the factor the map's
    /// texels are scaled by.
    pub scale: Vec3,
    /// The lat-long map; `None` for a constant environment.
    pub map: Option<Arc<EnvMap>>,
}

/// A lat-long radiance map with its sampling distribution.
#[derive(Debug)]
pub struct EnvMap {
    /// Texels per row (φ from 0 to 2π).
    pub width: usize,
    /// Rows (θ from 0 at +z to π).
    pub height: usize,
    /// Radiance texels (linear RGB), row-major, top row = +z.
    pub texels: Vec<Vec3>,
    dist: Distribution2D,
    /// (cos, sin) of the map's rotation about z: a texel at azimuth φ is seen at φ + angle. Applied
    /// to the lookup direction, so any angle is exact (rounding the angle to whole texel columns
    /// moved a 4-column map by up to 45°).
    rotation: (f32, f32),
}

impl Environment {
    /// Radiance arriving from direction `-d`, i.e. seen looking along `d`.
    #[inline]
    pub fn radiance(&self, d: Vec3) -> Vec3 {
        match &self.map {
            None => self.scale,
            Some(m) => self.scale * m.lookup(d),
        }
    }

    /// A direction from the map's luminance distribution (uniform on the sphere for a constant
    /// environment), with its radiance and solid-angle density.
    #[inline]
    pub fn sample(&self, u: Vec2) -> Option<LightSample> {
        let (wi, pdf) = match &self.map {
            None => (uniform_sphere(u), UNIFORM_SPHERE_PDF),
            Some(map) => map.sample(u)?,
        };
        Some(LightSample {
            wi,
            dist: f32::INFINITY,
            li: self.radiance(wi),
            pdf,
            is_delta: false,
        })
    }

    /// What a ray that meets nothing sees, at infinity, with the density of
    /// [`Environment::sample`].
    #[inline]
    pub fn hit(&self, ray: &Ray) -> LightHit {
        let pdf = match &self.map {
            None => UNIFORM_SPHERE_PDF,
            Some(map) => map.pdf(ray.d),
        };
        LightHit {
            distance: f32::INFINITY,
            radiance: self.radiance(ray.d),
            pdf,
        }
    }
}

impl EnvMap {
    /// A map from row-major texels (top row = +z); sampling is proportional to luminance·sin θ.
    pub fn new(width: usize, height: usize, texels: Vec<Vec3>) -> Self {
        let weights: Vec<f32> = (0..height)
            .flat_map(|y| {
                let sin = ((y as f32 + 0.5) / height as f32 * PI).sin();
                let texels = &texels;
                (0..width).map(move |x| {
                    let c = texels[y * width + x];
                    (crate::math::luminance(c).max(0.0) * sin).max(1e-8)
                })
            })
            .collect();
        EnvMap {
            width,
            height,
            dist: Distribution2D::new(&weights, width, height),
            texels,
            rotation: (1.0, 0.0),
        }
    }

    /// The map turned by `degrees` about z (positive: counter-clockwise seen from +z).
    pub fn rotated(mut self, degrees: f32) -> Self {
        let (s, c) = degrees.to_radians().sin_cos();
        self.rotation = (c, s);
        self
    }

    /// `d` turned by the map's rotation, backwards (`inverse`: world → map) or forwards.
    fn turn(&self, d: Vec3, inverse: bool) -> Vec3 {
        let (c, s) = self.rotation;
        if s == 0.0 && c == 1.0 {
            return d;
        }
        let s = if inverse { -s } else { s };
        Vec3::new(c * d.x - s * d.y, s * d.x + c * d.y, d.z)
    }

    pub(super) fn uv(d: Vec3) -> Vec2 {
        let phi = d.y.atan2(d.x);
        let phi = if phi < 0.0 { phi + 2.0 * PI } else { phi };
        Vec2::new(phi / (2.0 * PI), crate::math::safe_acos(d.z) / PI)
    }

    fn dir(uv: Vec2) -> Vec3 {
        let (phi, theta) = (uv.x * 2.0 * PI, uv.y * PI);
        Vec3::new(
            theta.sin() * phi.cos(),
            theta.sin() * phi.sin(),
            theta.cos(),
        )
    }

    /// The texel (nearest, no filtering) seen looking along the world direction `d`, the map's
    /// rotation applied.
    pub fn lookup(&self, d: Vec3) -> Vec3 {
        let uv = Self::uv(self.turn(d, true));
        let x = ((uv.x * self.width as f32) as usize).min(self.width - 1);
        let y = ((uv.y * self.height as f32) as usize).min(self.height - 1);
        self.texels[y * self.width + x]
    }

    /// Direction and solid-angle pdf: p(ω) = p(u, v) / (2π² sin θ) (pbrt-v4 §12.5.2).
    pub(super) fn sample(&self, u: Vec2) -> Option<(Vec3, f32)> {
        let (uv, pdf_uv) = self.dist.sample(u);
        let sin = (uv.y * PI).sin();
        if sin <= 0.0 || pdf_uv <= 0.0 {
            return None;
        }
        Some((
            self.turn(Self::dir(uv), false),
            pdf_uv / (2.0 * PI * PI * sin),
        ))
    }

    pub(super) fn pdf(&self, d: Vec3) -> f32 {
        let uv = Self::uv(self.turn(d, true));
        let sin = (uv.y * PI).sin();
        if sin <= 0.0 {
            return 0.0;
        }
        self.dist.pdf(uv) / (2.0 * PI * PI * sin)
    }
}

/// Piecewise-constant 1D density on [0, 1) (pbrt-v4 §A.4.1).
#[derive(Debug, Clone)]
struct Distribution1D {
    func: Vec<f32>,
    cdf: Vec<f32>,
    integral: f32,
}

impl Distribution1D {
    fn new(func: &[f32]) -> Self {
        let n = func.len();
        let mut cdf = vec![0.0f32; n + 1];
        for i in 0..n {
            cdf[i + 1] = cdf[i] + func[i] / n as f32;
        }
        let integral = cdf[n];
        for c in &mut cdf[1..] {
            *c /= integral;
        }
        Distribution1D {
            func: func.to_vec(),
            cdf,
            integral,
        }
    }

    /// Continuous sample in [0, 1), its density and its cell.
    fn sample(&self, u: f32) -> (f32, f32, usize) {
        let n = self.func.len();
        let i = (self.cdf.partition_point(|&c| c <= u).max(1) - 1).min(n - 1);
        let width = self.cdf[i + 1] - self.cdf[i];
        let du = if width > 0.0 {
            (u - self.cdf[i]) / width
        } else {
            0.5
        };
        let x = ((i as f32 + du.clamp(0.0, 1.0)) / n as f32).min(1.0 - f32::EPSILON);
        (x, self.func[i] / self.integral, i)
    }

    fn pdf_cell(&self, i: usize) -> f32 {
        self.func[i] / self.integral
    }
}

/// Piecewise-constant 2D density: a marginal over rows and a conditional per row.
#[derive(Debug, Clone)]
struct Distribution2D {
    rows: Vec<Distribution1D>,
    marginal: Distribution1D,
    width: usize,
    height: usize,
}

impl Distribution2D {
    fn new(f: &[f32], width: usize, height: usize) -> Self {
        let rows: Vec<Distribution1D> = (0..height)
            .map(|y| Distribution1D::new(&f[y * width..(y + 1) * width]))
            .collect();
        let marg: Vec<f32> = rows.iter().map(|r| r.integral).collect();
        Distribution2D {
            marginal: Distribution1D::new(&marg),
            rows,
            width,
            height,
        }
    }

    fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (v, pv, row) = self.marginal.sample(u.y);
        let (x, px, _) = self.rows[row].sample(u.x);
        (Vec2::new(x, v), pv * px)
    }

    fn pdf(&self, uv: Vec2) -> f32 {
        let x = ((uv.x * self.width as f32) as usize).min(self.width - 1);
        let y = ((uv.y * self.height as f32) as usize).min(self.height - 1);
        self.marginal.pdf_cell(y) * self.rows[y].pdf_cell(x)
    }
}
