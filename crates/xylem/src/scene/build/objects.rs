//! The `[[objects]]` tables of a scene file: shapes, meshes, tree placements, instances.

use crate::scene::*;

impl Builder<'_> {
    pub(in crate::scene) fn objects(
        &mut self,
        tables: &[ObjectTable],
        materials: &HashMap<String, u32>,
        _mats: &[Material],
    ) -> Result<Vec<Instance>, SceneError> {
        if tables.is_empty() {
            return Err(self.invalid(
                "objects",
                "the scene has no objects (give at least one [[objects]] table)",
            ));
        }
        let mut cache: HashMap<(PathBuf, bool), Arc<TriMesh>> = HashMap::new();
        let mut out = Vec::new();
        for (i, o) in tables.iter().enumerate() {
            let f = |s: &str| format!("objects[{i}].{s}");
            let material = *materials.get(&o.material).ok_or_else(|| {
                let mut names: Vec<&String> = materials.keys().collect();
                names.sort();
                self.invalid(
                    f("material"),
                    format!("no material named `{}` (defined: {names:?})", o.material),
                )
            })?;
            let mesh = self.shape(o, i, &mut cache)?;
            let scale = match o.scale {
                Scale::Uniform(s) => Vec3::splat(s),
                Scale::Axes(a) => v3(a),
            };
            for s in scale.to_array() {
                if !(s.is_finite() && s.abs() > 1e-9) {
                    return Err(self.invalid(f("scale"), "must be finite and non-zero"));
                }
            }
            let r = self.finite3(&f("rotate_deg"), o.rotate_deg)?;
            let rot = Quat::from_euler(
                EulerRot::ZYX,
                r.z.to_radians(),
                r.y.to_radians(),
                r.x.to_radians(),
            );
            let transform = Transform::new(Affine3A::from_scale_rotation_translation(
                scale,
                rot,
                self.finite3(&f("translate"), o.translate)?,
            ));
            if !transform.is_valid() {
                return Err(self.invalid(f("scale"), "the transform is not invertible"));
            }
            let reach = mesh
                .positions
                .iter()
                .map(|&v| transform.point_to_world(v).abs().max_element())
                .fold(
                    0.0f32,
                    |a, b| if b.is_nan() { f32::INFINITY } else { a.max(b) },
                );
            if reach > MAX_EXTENT_MM {
                return Err(self.invalid(
                    f("translate"),
                    format!(
                        "with its scale and translation the object reaches {reach:e} mm from the origin (allowed within {MAX_EXTENT_MM:e} mm)"
                    ),
                ));
            }
            let placement = match &o.tree {
                None => Placement::default(),
                Some(t) => self.placement(t, i)?,
            };
            out.push(Instance {
                mesh,
                transform,
                material,
                placement,
            });
        }
        Ok(out)
    }

    fn placement(&self, t: &TreeTable, i: usize) -> Result<Placement, SceneError> {
        let f = |s: &str| format!("objects[{i}].tree.{s}");
        let region = t.region.unwrap_or_default();
        if t.region.is_some() {
            self.range(&f("region.r_min"), region.r_min, 0.0, 1e6)?;
            self.range(&f("region.r_max"), region.r_max, region.r_min, 1e6)?;
            self.range(&f("region.z_span"), region.z_span, 0.0, 1e7)?;
        }
        let cutting = match t.cut {
            CutName::Solid => {
                if t.layout.is_some() || t.region.is_some() {
                    return Err(self.invalid(
                        f("layout"),
                        "`layout` and `region` are for cut = \"boards\" / \"veneer\"",
                    ));
                }
                Cutting::Solid
            }
            CutName::Veneer => Cutting::Veneer {
                region,
                seed: t.seed,
            },
            CutName::Boards => {
                let layout = t.layout.ok_or_else(|| {
                    self.invalid(f("layout"), "required for cut = \"boards\", e.g. { kind = \"planks\", width = 90.0, length = 900.0, stagger = 0.3 } or { kind = \"parquet\", tile = 400.0, strip = 50.0 }")
                })?;
                match layout {
                    BoardLayout::Planks {
                        width,
                        length,
                        stagger,
                    } => {
                        self.range(&f("layout.width"), width, 1e-3, 1e6)?;
                        self.range(&f("layout.length"), length, 1e-3, 1e6)?;
                        self.range(&f("layout.stagger"), stagger, 0.0, 1.0)?;
                    }
                    BoardLayout::Parquet { tile, strip } => {
                        self.range(&f("layout.tile"), tile, 1e-3, 1e6)?;
                        self.range(&f("layout.strip"), strip, 1e-3, tile / 2.0)?;
                    }
                }
                Cutting::Boards {
                    layout,
                    region,
                    seed: t.seed,
                }
            }
        };
        let axis = self.unit3(&f("axis"), t.axis)?;
        let scale = self.range(&f("scale"), t.scale, 1e-6, 1e6)?;
        if let Some(sawn) = &t.sawn {
            if t.cut != CutName::Solid || t.origin != [0.0; 3] || t.rotation_deg != 0.0 {
                return Err(self.invalid(
                    f("sawn"),
                    "`sawn` places a solid cut by itself: give it or `origin`/`rotation_deg`, not both",
                ));
            }
            let mut p = Placement::sawn(axis, scale, sawn)
                .map_err(|e| self.invalid(f(&format!("sawn.{}", e.field)), e.message))?;
            p.world_space = t.space == SpaceName::World;
            return Ok(p);
        }
        Ok(Placement {
            // Beyond the scene's extent the growth time loses all precision (NaN at 1e12).
            origin: self.point(&f("origin"), t.origin, MAX_EXTENT_MM)?,
            axis,
            rotation: self
                .range(&f("rotation_deg"), t.rotation_deg, -360.0, 360.0)?
                .to_radians(),
            scale,
            cutting,
            world_space: t.space == SpaceName::World,
            tilt: glam::Mat3::IDENTITY,
        })
    }

    /// Builds (or loads) the mesh of one object, rejecting fields its shape does not use.
    fn shape(
        &mut self,
        o: &ObjectTable,
        i: usize,
        cache: &mut HashMap<(PathBuf, bool), Arc<TriMesh>>,
    ) -> Result<Arc<TriMesh>, SceneError> {
        let f = |s: &str| format!("objects[{i}].{s}");
        let kind = self.shape_fields(o, i)?;
        let need = |name: &str| self.invalid(f(name), format!("required by shape `{kind}`"));
        let segments = match o.segments {
            None => 64,
            Some(s) => self.range(&f("segments"), s as f32, 3.0, 4096.0)? as u32,
        };
        let positive = |name: &str, x: f32| self.range(&f(name), x, 1e-6, 1e9);
        let mut mesh = match o.shape {
            ShapeKind::Box | ShapeKind::Quad => {
                let s = o.size.as_ref().ok_or_else(|| need("size"))?;
                let want = if o.shape == ShapeKind::Box { 3 } else { 2 };
                if s.len() != want {
                    return Err(self.invalid(
                        f("size"),
                        format!("shape `{kind}` takes {want} numbers (mm)"),
                    ));
                }
                for x in s {
                    positive("size", *x)?;
                }
                if want == 3 {
                    shapes::make_box(Vec3::new(s[0], s[1], s[2]))
                } else {
                    shapes::make_quad(Vec2::new(s[0], s[1]))
                }
            }
            ShapeKind::Sphere => shapes::make_sphere(
                positive("radius", o.radius.ok_or_else(|| need("radius"))?)?,
                segments,
            ),
            ShapeKind::Cylinder => shapes::make_cylinder(
                positive("radius", o.radius.ok_or_else(|| need("radius"))?)?,
                positive("height", o.height.ok_or_else(|| need("height"))?)?,
                segments,
            ),
            ShapeKind::Lathe => {
                let p = o.profile.as_ref().ok_or_else(|| need("profile"))?;
                self.lathe(p, i, segments)?
            }
            ShapeKind::Teapot => {
                let s = o.size.as_ref().map_or(Ok(30.0), |s| match s.as_slice() {
                    [x] => positive("size", *x),
                    _ => Err(self.invalid(
                        f("size"),
                        "shape `teapot` takes 1 number (mm per teapot unit)",
                    )),
                })?;
                let res = match o.resolution {
                    None => 8,
                    Some(r) => self.range(&f("resolution"), r as f32, 1.0, 256.0)? as u32,
                };
                teapot::make_teapot(s, res)
            }
            ShapeKind::Mesh => return self.mesh_file(o, i, cache),
        };
        if !o.smooth {
            mesh.normals = None;
        }
        Ok(Arc::new(mesh))
    }

    /// The shape's name, once every field the object gives is one its shape takes.
    fn shape_fields(&self, o: &ObjectTable, i: usize) -> Result<&'static str, SceneError> {
        let (kind, used): (&str, &[&str]) = match o.shape {
            ShapeKind::Box => ("box", &["size"]),
            ShapeKind::Quad => ("quad", &["size"]),
            ShapeKind::Sphere => ("sphere", &["radius", "segments"]),
            ShapeKind::Cylinder => ("cylinder", &["radius", "height", "segments"]),
            ShapeKind::Lathe => ("lathe", &["profile", "segments"]),
            ShapeKind::Teapot => ("teapot", &["size", "resolution"]),
            ShapeKind::Mesh => ("mesh", &["file"]),
        };
        let present = [
            ("size", o.size.is_some()),
            ("radius", o.radius.is_some()),
            ("height", o.height.is_some()),
            ("segments", o.segments.is_some()),
            ("profile", o.profile.is_some()),
            ("resolution", o.resolution.is_some()),
            ("file", o.file.is_some()),
        ];
        for (name, is) in present {
            if is && !used.contains(&name) {
                return Err(self.invalid(
                    format!("objects[{i}].{name}"),
                    format!("not used by shape `{kind}` (it takes: {})", used.join(", ")),
                ));
            }
        }
        Ok(kind)
    }

    /// A lathe (turned) mesh from its (radius, z) profile; its triangle count is checked against
    /// the machine before a vertex is allocated.
    fn lathe(&self, p: &[[f32; 2]], i: usize, segments: u32) -> Result<TriMesh, SceneError> {
        let f = |s: &str| format!("objects[{i}].{s}");
        if p.len() < 2 {
            return Err(self.invalid(f("profile"), "needs at least 2 (radius, z) points"));
        }
        for q in p {
            self.range(&f("profile"), q[0], 0.0, 1e9)?;
            self.range(&f("profile"), q[1], -1e9, 1e9)?;
        }
        // Its triangle count is known before it is built: a long profile at 4096
        // segments is billions of triangles, refused before a vertex is allocated.
        let triangles = 2 * (p.len() as u64 - 1) * segments as u64;
        let bytes = crate::render::resources::BUILD_BYTES_PER_TRIANGLE;
        crate::render::resources::Resources {
            what: format!(
                "{} ({} profile points × {segments} segments = {triangles} triangles)",
                f("profile"),
                p.len()
            ),
            memory: triangles * bytes,
            disk: 0,
            remedy: crate::render::resources::LOWER_TRIANGLES,
        }
        .check(self.base, self.ignore_limits)
        .map_err(|source| SceneError::Resources {
            path: self.path.to_string(),
            source,
        })?;
        let pts: Vec<Vec2> = p.iter().map(|q| Vec2::new(q[0], q[1])).collect();
        Ok(shapes::make_lathe(&pts, segments))
    }

    /// A mesh file's triangles, shared between the objects that load the same file with the
    /// same `smooth`.
    fn mesh_file(
        &mut self,
        o: &ObjectTable,
        i: usize,
        cache: &mut HashMap<(PathBuf, bool), Arc<TriMesh>>,
    ) -> Result<Arc<TriMesh>, SceneError> {
        let f = |s: &str| format!("objects[{i}].{s}");
        let file = o
            .file
            .as_ref()
            .ok_or_else(|| self.invalid(f("file"), "required by shape `mesh`"))?;
        let p = self.base.join(file);
        // Keyed by file and `smooth`: the second object using a file may want the
        // other normals.
        let key = (p.clone(), o.smooth);
        if let Some(m) = cache.get(&key) {
            return Ok(m.clone());
        }
        let mut m = mesh_io::load_mesh(&p).map_err(|source| SceneError::Mesh {
            path: self.path.to_string(),
            field: f("file"),
            source,
        })?;
        let dropped = m.drop_degenerate();
        if dropped > 0 {
            self.warnings.push(format!(
                "{}: {}: dropped {dropped} degenerate triangles",
                self.path,
                f("file")
            ));
        }
        if m.indices.is_empty() {
            return Err(self.invalid(f("file"), format!("{} has no valid triangles", p.display())));
        }
        if !o.smooth {
            m.normals = None;
        }
        let m = Arc::new(m);
        cache.insert(key, m.clone());
        Ok(m)
    }
}
