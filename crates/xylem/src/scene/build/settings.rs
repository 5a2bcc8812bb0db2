//! The `[quality]`, `[camera]` and `[sweep]` tables of a scene file, checked.

use crate::scene::*;

impl Builder<'_> {
    /// The knobs of a `[quality]` table: its preset's (or the full model's), its own knobs
    /// over them, then `[render] spp` and `footprint_filter`.
    pub(in crate::scene) fn quality_knobs(
        &self,
        q: &QualityTable,
        r: &RenderTable,
    ) -> Result<Knobs, SceneError> {
        let mut k = q
            .preset
            .map_or(Knobs::full(DEFAULT_SPP), |preset| preset.knobs());
        if let Some(j) = q.jacobian {
            k.jacobian = match j {
                JacobianName::Simplified => JacobianModel::Simplified,
                JacobianName::Exact => JacobianModel::Exact,
            };
        }
        if let Some(keep) = q.pores_and_rays {
            k.pores_and_rays = keep;
        }
        if let Some(bands) = q.max_noise_bands {
            self.range("quality.max_noise_bands", bands as f32, 1.0, 16.0)?;
            k.max_bands = Some(bands);
        }
        if let Some(spp) = r.spp {
            k.spp = spp;
        }
        k.footprint_filter = r.footprint_filter;
        Ok(k)
    }

    pub(in crate::scene) fn camera(
        &self,
        c: &CameraTable,
        width: u32,
        height: u32,
    ) -> Result<Camera, SceneError> {
        // Bounded so that `target − eye` and its square stay finite (a far eye was blamed on `up`).
        let eye = self.point("camera.eye", c.eye, 1e9)?;
        let target = self.point("camera.target", c.target, 1e9)?;
        let up = self.unit3("camera.up", c.up)?;
        let dir = target - eye;
        if dir.length_squared() < 1e-12 {
            return Err(self.invalid("camera.target", "must differ from camera.eye"));
        }
        if dir.normalize().cross(up).length_squared() < 1e-8 {
            return Err(self.invalid("camera.up", "must not be parallel to the view direction"));
        }
        let projection = match c.projection {
            ProjectionName::Perspective => {
                if c.width.is_some() {
                    return Err(
                        self.invalid("camera.width", "only for projection = \"orthographic\"")
                    );
                }
                Projection::Perspective {
                    fov_y: self
                        .range(
                            "camera.fov_deg",
                            c.fov_deg.unwrap_or(DEFAULT_FOV_DEG),
                            0.01,
                            179.0,
                        )?
                        .to_radians(),
                    lens_radius: self.range("camera.lens_radius", c.lens_radius, 0.0, 1e6)?,
                    focus_distance: self.range(
                        "camera.focus_distance",
                        c.focus_distance.unwrap_or(dir.length()),
                        1e-3,
                        1e9,
                    )?,
                }
            }
            ProjectionName::Orthographic => {
                if c.fov_deg.is_some() {
                    return Err(self.invalid(
                        "camera.fov_deg",
                        "only for projection = \"perspective\" (an orthographic camera's view is `width` mm wide)",
                    ));
                }
                if c.lens_radius != 0.0 {
                    return Err(self.invalid(
                        "camera.lens_radius",
                        "only for projection = \"perspective\" (an orthographic camera has no lens)",
                    ));
                }
                if c.focus_distance.is_some() {
                    return Err(self.invalid(
                        "camera.focus_distance",
                        "only for projection = \"perspective\"",
                    ));
                }
                let w = c.width.ok_or_else(|| {
                    self.invalid(
                        "camera.width",
                        "required for projection = \"orthographic\" (film width in mm)",
                    )
                })?;
                Projection::Orthographic {
                    width: self.range("camera.width", w, 1e-3, 1e9)?,
                }
            }
        };
        Ok(Camera::look_at(eye, target, up, projection, width, height))
    }

    pub(in crate::scene) fn check_sweep(
        &self,
        s: &SweepTable,
        names: &[Option<String>],
        width: u32,
        height: u32,
    ) -> Result<(), SceneError> {
        self.range("sweep.frames", s.frames as f32, 1.0, 100_000.0)?;
        for a in s.arc_deg {
            self.range("sweep.arc_deg", a, -90.0, 90.0)?;
        }
        self.range("sweep.radius", s.radius, 1e-3, 1e9)?;
        self.finite3("sweep.pivot", s.pivot)?;
        self.unit3("sweep.axis", s.axis)?;
        if s.azimuths_deg.is_empty() || s.azimuths_deg.len() > format::MAX_ARCS {
            return Err(self.invalid(
                "sweep.azimuths_deg",
                format!(
                    "{} azimuths (allowed 1 to {})",
                    s.azimuths_deg.len(),
                    format::MAX_ARCS
                ),
            ));
        }
        for a in &s.azimuths_deg {
            self.range("sweep.azimuths_deg", *a, -360.0, 360.0)?;
        }
        self.range(
            "sweep.frames",
            (s.frames as usize * s.azimuths_deg.len()) as f32,
            1.0,
            100_000.0,
        )?;
        if let Some(b) = &s.board {
            self.finite3("sweep.board.origin", b.origin)?;
            let x = self.unit3("sweep.board.x_axis", b.x_axis)?;
            let y = self.unit3("sweep.board.y_axis", b.y_axis)?;
            if x.dot(y).abs() > 1e-3 {
                return Err(self.invalid(
                    "sweep.board.y_axis",
                    "must be perpendicular to x_axis (|x·y| ≤ 1e-3)".to_string(),
                ));
            }
            for v in b.size_mm {
                self.range("sweep.board.size_mm", v, 1e-3, 1e6)?;
            }
            self.number("sweep.board", &crate::scene::fields::ETA, b.eta)?;
        }
        if !names.iter().any(|n| n.as_deref() == Some(s.light.as_str())) {
            let known: Vec<&str> = names.iter().flatten().map(String::as_str).collect();
            return Err(self.invalid(
                "sweep.light",
                format!("no light named `{}` (named lights: {known:?})", s.light),
            ));
        }
        for (k, r) in s.regions.iter().enumerate() {
            if !(r.x0 < r.x1 && r.y0 < r.y1 && r.x1 <= width && r.y1 <= height) {
                return Err(self.invalid(
                    format!("sweep.regions[{k}]"),
                    format!(
                        "region `{}` must satisfy x0 < x1 <= {width}, y0 < y1 <= {height}",
                        r.name
                    ),
                ));
            }
        }
        Ok(())
    }
}
