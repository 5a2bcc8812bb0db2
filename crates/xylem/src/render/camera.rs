//! Cameras: perspective with an optional thin lens, and orthographic. Film coordinates are in
//! pixels, (0, 0) at the top-left corner of the image.

use super::geometry::Ray;
use crate::math::{concentric_disk, Frame};
use glam::{Vec2, Vec3};

/// How film points become rays.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Projection {
    /// Pinhole or thin lens (pbrt-v4 §5.2.3): `fov_y` vertical field of view (radians),
    /// `lens_radius` (mm, 0 = pinhole) and `focus_distance` (mm, along the view axis).
    Perspective {
        /// Vertical field of view (radians).
        fov_y: f32,
        /// Thin-lens aperture radius (mm); 0 = pinhole.
        lens_radius: f32,
        /// Distance of the plane in focus, along the view axis (mm).
        focus_distance: f32,
    },
    /// Parallel rays; `width` is the film width in world millimetres.
    Orthographic {
        /// Film width (world mm).
        width: f32,
    },
}

/// A camera at `eye` looking along `frame.n` with `frame.t` the image-up direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position (world, mm).
    pub eye: Vec3,
    /// s = image right, t = image up, n = view direction.
    pub frame: Frame,
    /// How film points become rays.
    pub projection: Projection,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

impl Camera {
    /// A camera at `eye` looking at `target`, with `up` giving image-up (need not be orthogonal).
    pub fn look_at(
        eye: Vec3,
        target: Vec3,
        up: Vec3,
        projection: Projection,
        width: u32,
        height: u32,
    ) -> Self {
        let n = (target - eye).normalize();
        let s = n.cross(up).normalize();
        let t = s.cross(n);
        Camera {
            eye,
            frame: Frame { s, t, n },
            projection,
            width,
            height,
        }
    }

    /// Same camera with another image size (field of view and ortho width are kept).
    pub fn with_resolution(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }

    /// The ray through film point `film` (pixels); `lens` in [0,1)² picks the lens point.
    pub fn ray(&self, film: Vec2, lens: Vec2) -> Ray {
        self.rays().ray(film, lens)
    }

    /// Width (mm) of one pixel's footprint across `ray` at distance `t`: the pixel spacing on the
    /// film, 2 tan(fov/2)/height per unit distance for a pinhole (× cos of the angle off the view
    /// axis, the film's foreshortening seen along the ray), film width / pixels for orthographic.
    /// The lens blur of a thin lens is not included. Used to band-limit textures.
    pub fn pixel_footprint(&self, ray: &Ray, t: f32) -> f32 {
        self.rays().pixel_footprint(ray, t)
    }

    /// The camera with its per-ray constants worked out once ([`CameraRays`]), for a tile's
    /// many rays.
    pub fn rays(&self) -> CameraRays<'_> {
        CameraRays {
            camera: self,
            tan_half_fov: match self.projection {
                Projection::Perspective { fov_y, .. } => (0.5 * fov_y).tan(),
                Projection::Orthographic { .. } => 1.0,
            },
        }
    }
}

/// A camera with tan(fov_y/2) worked out once: [`Camera::ray`] and [`Camera::pixel_footprint`]
/// are these methods, so both give the same bits (the tangent was 2 % of a Cornell-box
/// render's time when taken per ray).
#[derive(Clone, Copy, Debug)]
pub struct CameraRays<'a> {
    camera: &'a Camera,
    /// tan(fov_y / 2) for a perspective camera (the film's half-height at unit distance).
    tan_half_fov: f32,
}

impl CameraRays<'_> {
    /// [`Camera::ray`].
    #[inline(always)]
    pub fn ray(&self, film: Vec2, lens: Vec2) -> Ray {
        let cam = self.camera;
        let (w, h) = (cam.width as f32, cam.height as f32);
        // Normalised device coordinates: x in [-aspect, aspect], y in [-1, 1], y up.
        let ndc = Vec2::new((2.0 * film.x - w) / h, (h - 2.0 * film.y) / h);
        let f = &cam.frame;
        match cam.projection {
            Projection::Perspective {
                lens_radius,
                focus_distance,
                ..
            } => {
                let k = self.tan_half_fov;
                let dir = (f.n + f.s * (ndc.x * k) + f.t * (ndc.y * k)).normalize();
                if lens_radius <= 0.0 {
                    return Ray { o: cam.eye, d: dir };
                }
                // Thin lens: every ray through the lens point reaches the pinhole ray's point on
                // the plane of focus (pbrt-v4 eq. 5.2).
                let focus = cam.eye + dir * (focus_distance / dir.dot(f.n));
                let l = concentric_disk(lens) * lens_radius;
                let o = cam.eye + f.s * l.x + f.t * l.y;
                Ray {
                    o,
                    d: (focus - o).normalize(),
                }
            }
            Projection::Orthographic { width } => {
                let half = 0.5 * width * h / w;
                Ray {
                    o: cam.eye + f.s * (ndc.x * half) + f.t * (ndc.y * half),
                    d: f.n,
                }
            }
        }
    }

    /// The footprint a pixel of this camera would leave at depth d along the view axis, as
    /// (per unit depth, constant): 2 tan(fov/2)/height and 0 for a pinhole, 0 and film width /
    /// pixels for orthographic. pbrt-v4's `Camera::Approximate_dp_dxy` (Pharr, Jakob, Humphreys,
    /// "Physically Based Rendering" 4th ed., §10.1.1) takes this at points reached after a
    /// bounce: a lower bound on the true footprint there, since a path's length is at least the
    /// point's depth (flat mirrors; a diffuse bounce spreads it far wider).
    #[inline]
    pub fn depth_footprint(&self) -> (f32, f32) {
        let cam = self.camera;
        match cam.projection {
            Projection::Perspective { .. } => (2.0 * self.tan_half_fov / cam.height as f32, 0.0),
            Projection::Orthographic { width } => (0.0, width / cam.width as f32),
        }
    }

    /// [`Camera::pixel_footprint`].
    #[inline]
    pub fn pixel_footprint(&self, ray: &Ray, t: f32) -> f32 {
        let cam = self.camera;
        match cam.projection {
            Projection::Perspective { .. } => {
                2.0 * self.tan_half_fov / cam.height as f32 * t * ray.d.dot(cam.frame.n).abs()
            }
            Projection::Orthographic { width } => width / cam.width as f32,
        }
    }
}

#[cfg(test)]
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_ray_looks_at_target_and_ortho_is_parallel() {
        let persp = Projection::Perspective {
            fov_y: 0.7,
            lens_radius: 5.0,
            focus_distance: 100.0,
        };
        let c = Camera::look_at(
            Vec3::new(0.0, -100.0, 0.0),
            Vec3::ZERO,
            Vec3::Z,
            persp,
            64,
            32,
        );
        for lens in [Vec2::new(0.1, 0.9), Vec2::new(0.5, 0.5)] {
            let r = c.ray(Vec2::new(32.0, 16.0), lens);
            // Every lens ray of the centre pixel passes through the focus point (the target).
            let t = -r.o.y / r.d.y;
            assert!(r.at(t).length() < 1e-3);
        }
        let o = Camera::look_at(
            Vec3::new(0.0, 0.0, 50.0),
            Vec3::ZERO,
            Vec3::Y,
            Projection::Orthographic { width: 20.0 },
            40,
            20,
        );
        let a = o.ray(Vec2::new(0.0, 0.0), Vec2::ZERO);
        let b = o.ray(Vec2::new(40.0, 20.0), Vec2::ZERO);
        assert_eq!(a.d, b.d);
        assert!((a.o.x + 10.0).abs() < 1e-4 && (b.o.x - 10.0).abs() < 1e-4);
        assert!((a.o.y - 5.0).abs() < 1e-4, "image up is +y: {a:?}");
    }
}
