//! `Scene`: a scene loaded once from a file or a Python dict, for many renders.

use crate::*;

pub(crate) fn scene_error(e: xylem::scene::SceneError) -> PyErr {
    match e {
        xylem::scene::SceneError::Io { .. } | xylem::scene::SceneError::Input(_) => {
            PyOSError::new_err(e.to_string())
        }
        other => value_error(other),
    }
}

/// A Python value as a TOML value: dict → table, list / tuple / numpy array → array, bool, int,
/// float, str, numpy scalars and `os.PathLike` (a path string); `at` names the key for errors.
pub(crate) fn toml_value(v: &Bound<'_, PyAny>, at: &str) -> PyResult<toml::Value> {
    use pyo3::types::{PyBool, PyFloat, PyInt, PyList, PyString, PyTuple};
    if let Ok(d) = v.downcast::<PyDict>() {
        let mut t = toml::Table::new();
        for (k, x) in d.iter() {
            let key: String = k.extract().map_err(|_| {
                value_error(format!("scene dict: a key in `{at}` is not a string: {k}"))
            })?;
            let here = if at.is_empty() {
                key.clone()
            } else {
                format!("{at}.{key}")
            };
            t.insert(key, toml_value(&x, &here)?);
        }
        return Ok(toml::Value::Table(t));
    }
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(v.extract().map_err(|_| {
            value_error(format!("scene dict: `{at}` = {v}: out of the 64-bit range"))
        })?));
    }
    if v.is_instance_of::<PyFloat>() {
        let x: f64 = v.extract()?;
        if !x.is_finite() {
            return Err(value_error(format!(
                "scene dict: `{at}` = {x}: must be finite"
            )));
        }
        return Ok(toml::Value::Float(x));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        let items = v
            .try_iter()?
            .enumerate()
            .map(|(i, x)| toml_value(&x?, &format!("{at}[{i}]")))
            .collect::<PyResult<Vec<_>>>()?;
        return Ok(toml::Value::Array(items));
    }
    if v.hasattr("__fspath__")? {
        let p: PathBuf = v.extract()?;
        return Ok(toml::Value::String(p.display().to_string()));
    }
    // numpy arrays and scalars: their Python equivalents.
    if v.hasattr("tolist")? {
        return toml_value(&v.call_method0("tolist")?, at);
    }
    Err(value_error(format!(
        "scene dict: `{at}` = {}: a {} is not a scene value (use dicts, lists, numbers, \
         strings and booleans, as in a scene file)",
        v.repr()?,
        v.get_type().name()?
    )))
}

/// A loaded scene, ready to render many times (as `mitsuba.load_dict` gives). Made by
/// `xylem.load_file(path)` or `xylem.load_dict(dict)`; `render` and `sweep` take it in place
/// of a file. Renders of one Scene from several threads run one after the other.
#[pyclass(module = "xylem", name = "Scene", frozen)]
pub(crate) struct PyScene {
    loaded: Mutex<xylem::scene::LoadedScene>,
    /// The file, or `<dict>`.
    origin: String,
}

impl PyScene {
    fn new(loaded: xylem::scene::LoadedScene, origin: String) -> Self {
        PyScene {
            loaded: Mutex::new(loaded),
            origin,
        }
    }

    /// The scene locked for this thread; other threads' renders of it are waited for with the
    /// GIL released.
    fn lock(
        &self,
        py: Python<'_>,
    ) -> PyResult<std::sync::MutexGuard<'_, xylem::scene::LoadedScene>> {
        loop {
            match self.loaded.try_lock() {
                Ok(g) => return Ok(g),
                Err(std::sync::TryLockError::WouldBlock) => {
                    py.allow_threads(|| std::thread::sleep(std::time::Duration::from_millis(5)));
                    py.check_signals()?;
                }
                Err(std::sync::TryLockError::Poisoned(p)) => return Ok(p.into_inner()),
            }
        }
    }
}

#[pymethods]
impl PyScene {
    /// The scene's name (the file stem, or `name` of `load_dict`).
    #[getter]
    fn name(&self, py: Python<'_>) -> PyResult<String> {
        Ok(self.lock(py)?.name.clone())
    }

    /// (width, height) of the camera's image.
    #[getter]
    fn res(&self, py: Python<'_>) -> PyResult<(u32, u32)> {
        let s = self.lock(py)?;
        Ok((s.scene.camera.width, s.scene.camera.height))
    }

    /// Samples per pixel of the scene's `[render]` table.
    #[getter]
    fn spp(&self, py: Python<'_>) -> PyResult<u32> {
        Ok(self.lock(py)?.settings.spp)
    }

    /// Non-fatal problems found while loading (e.g. degenerate triangles dropped).
    #[getter]
    fn warnings(&self, py: Python<'_>) -> PyResult<Vec<String>> {
        Ok(self.lock(py)?.warnings.clone())
    }

    fn __repr__(&self, py: Python<'_>) -> PyResult<String> {
        let s = self.lock(py)?;
        Ok(format!(
            "<xylem.Scene '{}' from {}: {}x{}, {} spp, {} lights, {} materials{}>",
            s.name,
            self.origin,
            s.scene.camera.width,
            s.scene.camera.height,
            s.settings.spp,
            s.scene.lights.len(),
            s.scene.materials.len(),
            if s.sweep.is_some() { ", [sweep]" } else { "" }
        ))
    }
}

/// `load_file(path)`: reads and builds a scene file (or a built-in scene by name) once, for
/// many renders.
#[pyfunction]
pub(crate) fn load_file(scene: PathBuf) -> PyResult<PyScene> {
    let loaded = xylem::scene::load(&scene).map_err(scene_error)?;
    Ok(PyScene::new(loaded, scene.display().to_string()))
}

/// `load_dict(scene, *, name="scene", base=None)`: builds a scene from a dict with the keys and
/// values of a scene file (scenes/README.md: `camera`, `render`, `materials`, `objects`,
/// `lights`, `sweep`, ...); relative files (meshes, maps) resolve against `base` (default: the
/// current folder). Errors name
/// the field as for a file, with `<dict>` as the file.
#[pyfunction]
#[pyo3(signature = (scene, *, name="scene", base=None))]
pub(crate) fn load_dict(
    scene: &Bound<'_, PyDict>,
    name: &str,
    base: Option<PathBuf>,
) -> PyResult<PyScene> {
    let base = base.unwrap_or_else(|| PathBuf::from("."));
    let value = toml_value(scene.as_any(), "")?;
    let text = toml::to_string(&value).map_err(|e| value_error(format!("scene dict: {e}")))?;
    let loaded = xylem::scene::from_str(&text, "<dict>", &base, name).map_err(scene_error)?;
    Ok(PyScene::new(loaded, "<dict>".into()))
}

/// Runs `f` on the scene `scene` (a `Scene`, a dict or a file path) with the overrides
/// applied; a `Scene`'s own settings are restored afterwards.
pub(crate) fn with_scene<T>(
    py: Python<'_>,
    scene: &Bound<'_, PyAny>,
    o: &Overrides,
    f: impl FnOnce(&xylem::scene::LoadedScene) -> PyResult<T>,
) -> PyResult<T> {
    o.check().map_err(value_error)?;
    let apply = |loaded: &mut xylem::scene::LoadedScene| -> PyResult<T> {
        // Overrides change the settings and camera, and a quality preset or footprint switch
        // the materials (wood volumes rebuilt with the knobs): all three are restored after.
        let (settings, camera) = (loaded.settings, loaded.scene.camera);
        let materials = (o.quality.is_some() || o.footprint_filter.is_some())
            .then(|| loaded.scene.materials.clone());
        let r = o
            .apply(loaded)
            .map_err(value_error)
            .and_then(|()| f(loaded));
        (loaded.settings, loaded.scene.camera) = (settings, camera);
        if let Some(m) = materials {
            loaded.scene.materials = m;
        }
        r
    };
    if let Ok(s) = scene.downcast::<PyScene>() {
        let mut guard = s.get().lock(py)?;
        return apply(&mut guard);
    }
    let mut loaded = if let Ok(d) = scene.downcast::<PyDict>() {
        load_dict(d, "scene", None)?
            .loaded
            .into_inner()
            .map_err(|_| value_error("scene dict: unusable"))?
    } else {
        let path: PathBuf = scene.extract().map_err(|_| {
            pyo3::exceptions::PyTypeError::new_err(format!(
                "scene: expected a file path, a built-in scene name, a dict or an xylem.Scene, not {}",
                scene.get_type().name().map_or("?".into(), |n| n.to_string())
            ))
        })?;
        xylem::scene::load(&path).map_err(scene_error)?
    };
    apply(&mut loaded)
}
