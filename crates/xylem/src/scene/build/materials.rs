//! The `[materials]` tables of a scene file, checked and built (measured maps read here).

use crate::bsdf::Finish;
use crate::scene::fields::*;
use crate::scene::*;

impl Builder<'_> {
    pub(in crate::scene) fn materials(
        &mut self,
        tables: &BTreeMap<String, MaterialTable>,
    ) -> Result<(Vec<Material>, HashMap<String, u32>), SceneError> {
        let mut out = Vec::new();
        let mut index = HashMap::new();
        for (name, t) in tables {
            let at = format!("materials.{name}");
            let f = |spec: &Field| format!("{at}.{}", spec.name);
            let m = match t {
                MaterialTable::Lambertian { albedo } => Material::Lambertian {
                    albedo: self.color(&at, &ALBEDO, *albedo)?,
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
                        diffuse: self.color(&at, &FIBER_DIFFUSE, *diffuse)?,
                        fiber_color: self.color(&at, &FIBER_COLOR, *fiber_color)?,
                        fiber_dir: self.unit3(&f(&FIBER_DIR), *fiber_dir)?,
                        ray_dir: self.unit3(&f(&RAY_DIR), *ray_dir)?,
                        ray_mask: self.number(&at, &RAY_MASK, *ray_mask)?,
                        highlight_width: self
                            .number(&at, &FIBER_WIDTH, *highlight_width_deg)?
                            .to_radians(),
                        eta: self.number(&at, &ETA, *eta)?,
                        roughness: self.number(&at, &ROUGHNESS, *roughness)?,
                    };
                    // Let the BSDF itself check the combination once, here, with a clear message.
                    WoodBsdf::new(params)
                        .map_err(|e| self.invalid(format!("{at}.type"), e.to_string()))?;
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
                            .map_err(|e| self.invalid(f(&PRESET), e.to_string()))?,
                        (None, Some(file)) => read_preset_file(&self.base.join(file))
                            .map_err(|e| self.invalid(f(&PRESET_FILE), e.to_string()))?,
                        _ => {
                            return Err(self.invalid(
                                f(&PRESET),
                                format!(
                                    "give exactly one of `preset` (one of: {}) or `preset_file`",
                                    crate::wood::PRESET_NAMES.join(", ")
                                ),
                            ))
                        }
                    };
                    let bump = match bump {
                        Some(b) => self.number(&at, &BUMP, *b)?,
                        None => params.default_bump(),
                    };
                    let volume = crate::wood::WoodVolume::new(params, *seed)
                        .map_err(|e| self.invalid(f(&PRESET), e.to_string()))?;
                    Material::Wood(Box::new(WoodMaterial {
                        volume: Arc::new(volume),
                        finish: Finish::new(
                            self.number(&at, &ETA, *eta)?,
                            self.number(&at, &ROUGHNESS, *roughness)?,
                        ),
                        bump,
                        switches: Default::default(),
                    }))
                }
                MaterialTable::Measured { .. } => self.measured(t, name)?,
                MaterialTable::Texture { texture, params } => {
                    let t = crate::texture::by_name(texture, params)
                        .map_err(|e| self.invalid(f(&TEXTURE), e.to_string()))?;
                    Material::Texture(TextureMaterial {
                        name: texture.clone(),
                        texture: Arc::from(t),
                    })
                }
                MaterialTable::Mirror { reflectance } => Material::Mirror {
                    reflectance: self.color(&at, &MIRROR_REFLECTANCE, *reflectance)?,
                },
                MaterialTable::Glass { eta, tint } => Material::Glass {
                    eta: self.number(&at, &GLASS_ETA, *eta)?,
                    tint: self.color(&at, &GLASS_TINT, *tint)?,
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
        let at = format!("materials.{name}");
        let f = |spec: &Field| format!("{at}.{}", spec.name);
        if highlight_width.is_some() && highlight_width_deg.is_some() {
            return Err(self.invalid(
                f(&MEASURED_WIDTH),
                "give either a β map `highlight_width` or a constant `highlight_width_deg`, not both",
            ));
        }
        let beta = self.number(
            &at,
            &MEASURED_WIDTH,
            highlight_width_deg.unwrap_or(MEASURED_WIDTH.default_number()),
        )?;
        let scale = self.number(&at, &FIBER_COLOR_SCALE, *fiber_color_scale)?;
        let size = Vec2::new(
            self.number(&at, &SIZE_MM, size_mm[0])?,
            self.number(&at, &SIZE_MM, size_mm[1])?,
        );
        let face = match face
            .as_deref()
            .map_or(Some(BoardFace::PosZ), BoardFace::from_name)
        {
            Some(face) => face,
            None => return Err(self.invalid(f(&FACE), format!("allowed {}", FACE.value.range()))),
        };
        let colors = match color_space.as_deref() {
            None | Some("linear") => ColorSpace::Linear,
            Some("srgb") => ColorSpace::Srgb,
            Some(other) => {
                return Err(self.invalid(
                    f(&COLOR_SPACE),
                    format!("`{other}` (allowed {})", COLOR_SPACE.value.range()),
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
            .map_err(|e| self.invalid(format!("{at}.{}", e.field()), e.to_string()))?;
        let m = MeasuredMaterial::new(
            Arc::new(board),
            face.rect(size),
            scale,
            beta.to_radians(),
            self.number(&at, &ETA, *eta)?,
            self.number(&at, &ROUGHNESS, *roughness)?,
        );
        if m.clamped > 0 {
            self.warnings.push(format!(
                "{}: {}: {} of {} texels have 2π · fiber_color_scale · fiber_color above 1 and were scaled down to 1 (hue kept)",
                self.path,
                f(&FIBER_COLOR_SCALE),
                m.clamped,
                m.board.fiber_color.len()
            ));
        }
        Ok(Material::Measured(Box::new(m)))
    }
}
