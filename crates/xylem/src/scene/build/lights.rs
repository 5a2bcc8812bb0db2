//! The `[[lights]]` tables of a scene file, checked and built.

use crate::scene::*;

impl Builder<'_> {
    pub(in crate::scene) fn lights(
        &self,
        tables: &[LightTable],
    ) -> Result<(Vec<Light>, Vec<Option<String>>), SceneError> {
        let mut lights = Vec::new();
        let mut names = Vec::new();
        for (i, t) in tables.iter().enumerate() {
            let light = self.light(t, i)?;
            if let Some(n) = t.name() {
                if names
                    .iter()
                    .any(|o: &Option<String>| o.as_deref() == Some(n))
                {
                    return Err(self.invalid(
                        format!("lights[{i}].name"),
                        format!("light name `{n}` is used twice"),
                    ));
                }
            }
            lights.push(light);
            names.push(t.name().map(str::to_string));
        }
        Ok((lights, names))
    }

    /// The light of table `lights[i]`.
    fn light(&self, t: &LightTable, i: usize) -> Result<Light, SceneError> {
        let f = |s: &str| format!("lights[{i}].{s}");
        // Colour times strength, the form every light's power takes.
        let power =
            |strength: &str, value: f32, color: [f32; 3]| -> Result<Vec3, SceneError> {
                Ok(self.color(&f("color"), color, 1e3)?
                    * self.range(&f(strength), value, 0.0, 1e12)?)
            };
        Ok(match t {
            LightTable::Point {
                position,
                intensity,
                color,
                ..
            } => Light::Point(PointLight {
                position: self.finite3(&f("position"), *position)?,
                intensity: power("intensity", *intensity, *color)?,
            }),
            LightTable::Spot {
                position,
                target,
                intensity,
                color,
                cone_deg,
                falloff_deg,
                ..
            } => {
                let p = self.finite3(&f("position"), *position)?;
                let d = self.finite3(&f("target"), *target)? - p;
                if d.length_squared() < 1e-12 {
                    return Err(self.invalid(f("target"), "must differ from position"));
                }
                let outer = self.range(&f("cone_deg"), *cone_deg, 0.01, 180.0)?;
                let falloff = self.range(&f("falloff_deg"), *falloff_deg, 0.0, outer)?;
                Light::Spot(SpotLight {
                    position: p,
                    direction: d.normalize(),
                    intensity: power("intensity", *intensity, *color)?,
                    cos_inner: (outer - falloff).to_radians().cos(),
                    cos_outer: outer.to_radians().cos(),
                })
            }
            LightTable::Distant {
                direction,
                irradiance,
                color,
                ..
            } => Light::Distant(DistantLight {
                direction: self.unit3(&f("direction"), *direction)?,
                irradiance: power("irradiance", *irradiance, *color)?,
            }),
            LightTable::Rect {
                corner,
                edge_u,
                edge_v,
                radiance,
                color,
                ..
            } => {
                let (u, v) = (
                    self.finite3(&f("edge_u"), *edge_u)?,
                    self.finite3(&f("edge_v"), *edge_v)?,
                );
                if u.cross(v).length_squared() < 1e-12 {
                    return Err(self.invalid(f("edge_v"), "edges must span a non-zero area"));
                }
                Light::Rect(RectLight::new(
                    self.finite3(&f("corner"), *corner)?,
                    u,
                    v,
                    power("radiance", *radiance, *color)?,
                ))
            }
            LightTable::Sphere {
                center,
                radius,
                radiance,
                color,
                ..
            } => Light::Sphere(SphereLight {
                center: self.finite3(&f("center"), *center)?,
                radius: self.range(&f("radius"), *radius, 1e-4, 1e9)?,
                radiance: power("radiance", *radiance, *color)?,
            }),
            LightTable::Environment {
                radiance,
                color,
                map,
                rotate_deg,
                ..
            } => {
                let scale = power("radiance", *radiance, *color)?;
                let rot = self.range(&f("rotate_deg"), *rotate_deg, -360.0, 360.0)?;
                let map = map.as_ref().map(|m| self.env_map(&f("map"), m, rot));
                let map = map.transpose()?.map(Arc::new);
                Light::Environment(Environment { scale, map })
            }
        })
    }

    fn env_map(&self, field: &str, file: &str, rotate_deg: f32) -> Result<EnvMap, SceneError> {
        let p = self.base.join(file);
        let img = crate::picture::exr::read_exr_rgb(&p)
            .map_err(|e| self.invalid(field, e.to_string()))?;
        let (w, h, texels) = (img.width as usize, img.height as usize, img.pixels);
        if w < 2 || h < 1 {
            return Err(self.invalid(field, format!("{} is too small ({w}x{h})", p.display())));
        }
        if texels
            .iter()
            .any(|t| !t.is_finite() || t.min_element() < 0.0)
        {
            return Err(self.invalid(
                field,
                format!("{} holds negative or non-finite texels", p.display()),
            ));
        }
        Ok(EnvMap::new(w, h, texels).rotated(rotate_deg))
    }
}
