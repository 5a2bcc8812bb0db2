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
                        format!("lights[{i}].{}", crate::scene::fields::LIGHT_NAME.name),
                        format!("light name `{n}` is used twice"),
                    ));
                }
            }
            lights.push(light);
            names.push(t.name().map(str::to_string));
        }
        Ok((lights, names))
    }

    /// The light of table `lights[i]`; ranges and names from [`fields`](crate::scene::fields).
    fn light(&self, t: &LightTable, i: usize) -> Result<Light, SceneError> {
        use crate::scene::fields::*;
        let at = format!("lights[{i}]");
        let f = |spec: &Field| format!("{at}.{}", spec.name);
        // Colour times strength, the form every light's power takes.
        let power = |strength: &Field, value: f32, color: [f32; 3]| -> Result<Vec3, SceneError> {
            Ok(self.color(&at, &LIGHT_COLOR, color)? * self.number(&at, strength, value)?)
        };
        Ok(match t {
            LightTable::Point {
                position,
                intensity,
                color,
                ..
            } => Light::Point(PointLight {
                position: self.finite3(&f(&POSITION), *position)?,
                intensity: power(&INTENSITY, *intensity, *color)?,
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
                let p = self.finite3(&f(&POSITION), *position)?;
                let d = self.finite3(&f(&SPOT_TARGET), *target)? - p;
                if d.length_squared() < 1e-12 {
                    return Err(self.invalid(f(&SPOT_TARGET), "must differ from position"));
                }
                let outer = self.number(&at, &CONE, *cone_deg)?;
                let falloff = self.range(&f(&FALLOFF), *falloff_deg, 0.0, outer)?;
                Light::Spot(SpotLight {
                    position: p,
                    direction: d.normalize(),
                    intensity: power(&INTENSITY, *intensity, *color)?,
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
                direction: self.unit3(&f(&DISTANT_DIRECTION), *direction)?,
                irradiance: power(&IRRADIANCE, *irradiance, *color)?,
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
                    self.finite3(&f(&EDGE_U), *edge_u)?,
                    self.finite3(&f(&EDGE_V), *edge_v)?,
                );
                if u.cross(v).length_squared() < 1e-12 {
                    return Err(self.invalid(f(&EDGE_V), "edges must span a non-zero area"));
                }
                Light::Rect(RectLight::new(
                    self.finite3(&f(&CORNER), *corner)?,
                    u,
                    v,
                    power(&RADIANCE, *radiance, *color)?,
                ))
            }
            LightTable::Sphere {
                center,
                radius,
                radiance,
                color,
                ..
            } => Light::Sphere(SphereLight {
                center: self.finite3(&f(&CENTER), *center)?,
                radius: self.number(&at, &SPHERE_RADIUS, *radius)?,
                radiance: power(&RADIANCE, *radiance, *color)?,
            }),
            LightTable::Environment {
                radiance,
                color,
                map,
                rotate_deg,
                ..
            } => {
                let scale = power(&ENV_RADIANCE, *radiance, *color)?;
                let rot = self.number(&at, &ENV_ROTATE, *rotate_deg)?;
                let map = map.as_ref().map(|m| self.env_map(&f(&ENV_MAP), m, rot));
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
