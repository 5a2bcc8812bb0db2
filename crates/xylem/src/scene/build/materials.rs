//! The `[materials]` tables of a scene file, checked and built (measured maps read here).

use crate::scene::*;

impl Builder<'_> {
    /// `x` checked against the range of the wood BSDF's scalar field `name`
    /// ([`WOOD_BSDF_PARAMS`](crate::bsdf::WOOD_BSDF_PARAMS)), reported as the scene's `field`.
    pub(crate) fn bsdf_range(&self, field: &str, x: f32, name: &str) -> Result<f32, SceneError> {
        match WoodBsdfParams::spec(name).map(|p| p.kind) {
            Some(crate::bsdf::ParamKind::Scalar { min, max }) => self.range(field, x, min, max),
            _ => unreachable!("`{name}` is a scalar field of WOOD_BSDF_PARAMS"),
        }
    }

    pub(in crate::scene) fn materials(
        &mut self,
        tables: &BTreeMap<String, MaterialTable>,
    ) -> Result<(Vec<Material>, HashMap<String, u32>), SceneError> {
        let mut out = Vec::new();
        let mut index = HashMap::new();
        for (name, t) in tables {
            let f = |s: &str| format!("materials.{name}.{s}");
            let m = match t {
                MaterialTable::Lambertian { albedo } => Material::Lambertian {
                    albedo: self.color(&f("albedo"), *albedo, 1.0)?,
                },
                MaterialTable::Fiber {
                    diffuse,
                    fiber_color,
                    fiber_dir,
                    ray_dir,
                    ray_mask,
                    highlight_width_deg,
                    eta,
                    roughness,
                } => {
                    let params = WoodBsdfParams {
                        diffuse: self.color(&f("diffuse"), *diffuse, 1.0)?,
                        fiber_color: self.color(&f("fiber_color"), *fiber_color, 1.0)?,
                        fiber_dir: self.unit3(&f("fiber_dir"), *fiber_dir)?,
                        ray_dir: self.unit3(&f("ray_dir"), *ray_dir)?,
                        ray_mask: self.bsdf_range(&f("ray_mask"), *ray_mask, "ray_mask")?,
                        highlight_width: self
                            .range(&f("highlight_width_deg"), *highlight_width_deg, 0.06, 90.0)?
                            .to_radians(),
                        eta: self.bsdf_range(&f("eta"), *eta, "eta")?,
                        roughness: self.bsdf_range(&f("roughness"), *roughness, "roughness")?,
                    };
                    // Let the BSDF itself check the combination once, here, with a clear message.
                    WoodBsdf::new(params).map_err(|e| self.invalid(f("type"), e.to_string()))?;
                    Material::Fiber { params }
                }
                MaterialTable::Wood {
                    preset,
                    preset_file,
                    seed,
                    eta,
                    roughness,
                    bump,
                } => {
                    let params = match (preset, preset_file) {
                        (Some(name), None) => crate::wood::preset(name)
                            .map_err(|e| self.invalid(f("preset"), e.to_string()))?,
                        (None, Some(file)) => read_preset_file(&self.base.join(file))
                            .map_err(|e| self.invalid(f("preset_file"), e.to_string()))?,
                        _ => {
                            return Err(self.invalid(
                                f("preset"),
                                format!(
                                    "give exactly one of `preset` (one of: {}) or `preset_file`",
                                    crate::wood::PRESET_NAMES.join(", ")
                                ),
                            ))
                        }
                    };
                    let bump = match bump {
                        Some(b) => self.range(&f("bump"), *b, 0.0, 100.0)?,
                        None => params.default_bump(),
                    };
                    let volume = crate::wood::WoodVolume::new(params, *seed)
                        .map_err(|e| self.invalid(f("preset"), e.to_string()))?;
                    Material::Wood(Box::new(WoodMaterial {
                        volume: Arc::new(volume),
                        eta: self.bsdf_range(&f("eta"), *eta, "eta")?,
                        roughness: self.bsdf_range(&f("roughness"), *roughness, "roughness")?,
                        bump,
                        switches: Default::default(),
                    }))
                }
                MaterialTable::Measured { .. } => self.measured(t, name)?,
                MaterialTable::Texture { texture, params } => {
                    let t = crate::texture::by_name(texture, params)
                        .map_err(|e| self.invalid(f("texture"), e.to_string()))?;
                    Material::Texture(TextureMaterial {
                        name: texture.clone(),
                        texture: Arc::from(t),
                    })
                }
                MaterialTable::Mirror { reflectance } => Material::Mirror {
                    reflectance: self.color(&f("reflectance"), *reflectance, 1.0)?,
                },
                MaterialTable::Glass { eta, tint } => Material::Glass {
                    eta: self.range(&f("eta"), *eta, 1.0, 4.0)?,
                    tint: self.color(&f("tint"), *tint, 1.0)?,
                },
            };
            index.insert(name.clone(), out.len() as u32);
            out.push(m);
        }
        Ok((out, index))
    }

    /// A `measured` material: reads and checks the maps (errors name the field and the range) and
    /// warns when fibre colours had to be clamped into the BSDF's range (notes/measured.md).
    fn measured(&mut self, t: &MaterialTable, name: &str) -> Result<Material, SceneError> {
        let MaterialTable::Measured {
            diffuse,
            fiber_color,
            fiber_axis,
            highlight_width,
            highlight_width_deg,
            fiber_color_scale,
            color_space,
            size_mm,
            face,
            eta,
            roughness,
        } = t
        else {
            unreachable!("called for measured materials only")
        };
        let f = |s: &str| format!("materials.{name}.{s}");
        if highlight_width.is_some() && highlight_width_deg.is_some() {
            return Err(self.invalid(
                f("highlight_width_deg"),
                "give either a β map `highlight_width` or a constant `highlight_width_deg`, not both",
            ));
        }
        let beta = self.range(
            &f("highlight_width_deg"),
            highlight_width_deg.unwrap_or(crate::material::DEFAULT_HIGHLIGHT_WIDTH_DEG),
            0.06,
            90.0,
        )?;
        let scale = self.range(&f("fiber_color_scale"), *fiber_color_scale, 0.0, 1000.0)?;
        let size = Vec2::new(
            self.range(&f("size_mm"), size_mm[0], 1e-3, 1e6)?,
            self.range(&f("size_mm"), size_mm[1], 1e-3, 1e6)?,
        );
        let face = match face
            .as_deref()
            .map_or(Some(BoardFace::PosZ), BoardFace::from_name)
        {
            Some(face) => face,
            None => {
                return Err(self.invalid(
                    f("face"),
                    "allowed \"+z\", \"-z\", \"+x\", \"-x\", \"+y\", \"-y\"",
                ))
            }
        };
        let colors = match color_space.as_deref() {
            None | Some("linear") => ColorSpace::Linear,
            Some("srgb") => ColorSpace::Srgb,
            Some(other) => {
                return Err(self.invalid(
                    f("color_space"),
                    format!("`{other}` (allowed \"linear\" or \"srgb\")"),
                ))
            }
        };
        let files = MeasuredFiles {
            diffuse: self.base.join(diffuse),
            fiber_color: self.base.join(fiber_color),
            fiber_axis: self.base.join(fiber_axis),
            highlight_width: highlight_width.as_ref().map(|p| self.base.join(p)),
        };
        let board = MeasuredBoard::from_files(&files, colors)
            .map_err(|e| self.invalid(f(e.field()), e.to_string()))?;
        let m = MeasuredMaterial::new(
            Arc::new(board),
            face.rect(size),
            scale,
            beta.to_radians(),
            self.bsdf_range(&f("eta"), *eta, "eta")?,
            self.bsdf_range(&f("roughness"), *roughness, "roughness")?,
        );
        if m.clamped > 0 {
            self.warnings.push(format!(
                "{}: {}: {} of {} texels have 2π · fiber_color_scale · fiber_color above 1 and were scaled down to 1 (hue kept)",
                self.path,
                f("fiber_color_scale"),
                m.clamped,
                m.board.fiber_color.len()
            ));
        }
        Ok(Material::Measured(Box::new(m)))
    }
}
