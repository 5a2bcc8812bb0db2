//! Python bindings of xylem (PyO3 + numpy), the native module `xylem._xylem` behind the `xylem`
//! package (distributed as `xylem-wood`): the finished-wood BSDF, the wood volume, a wood surface
//! (volume + finish + tree placement, shaded in world space as the renderer shades a hit), and
//! scenes (from files or Python dicts) rendered and light-swept into numpy arrays. Every number
//! comes from the xylem library; these functions only move arrays in and out (broadcasting over
//! leading dimensions as numpy does, `batch`), release the GIL while computing, and turn the
//! library's typed errors into Python exceptions (`ValueError` for values out of range or not
//! finite, `OSError` for files).

mod batch;
mod bsdf;
mod jobs;
mod scene;
mod surface;
mod volume;

use batch::{Arg, Broadcast};
use bsdf::*;
use glam::{Mat3, Vec2, Vec3};
use jobs::*;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use scene::*;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use surface::*;
use volume::*;
use xylem::bsdf::{Bsdf, BsdfSample, WoodBsdfParams};
use xylem::material::{Cutting, Material, MaterialHit, Placement, ShadingSwitches, WoodMaterial};
use xylem::scene::Overrides;
use xylem::wood::{Needs, WoodError, WoodTexel};

/// Below this many items a call runs on the calling thread (rayon's start-up is not worth it).
const PARALLEL_FROM: usize = 4096;

/// An array argument: anything `numpy.asarray` turns into numbers (`batch`).
type ArrayIn<'py> = Bound<'py, PyAny>;

fn value_error(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

fn wood_error(e: WoodError) -> PyErr {
    match e {
        WoodError::Io { .. } => PyOSError::new_err(format!("{e}: {}", io_source(&e))),
        other => value_error(other),
    }
}

fn io_source(e: &WoodError) -> String {
    std::error::Error::source(e).map_or(String::new(), |s| s.to_string())
}

/// `f(i)` for i in 0..n, in parallel for large n; the results are in index order either way.
fn map_indices<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync + Send) -> Vec<T> {
    if n >= PARALLEL_FROM {
        (0..n).into_par_iter().map(f).collect()
    } else {
        (0..n).map(f).collect()
    }
}

/// An array of 3-vectors with leading shape `shape`, as shape (*shape, 3).
fn vec3_out<'py>(py: Python<'py>, v: &[Vec3], shape: &[usize]) -> PyResult<Bound<'py, PyAny>> {
    let flat: Vec<f32> = v.iter().flat_map(|c| c.to_array()).collect();
    let mut s = shape.to_vec();
    s.push(3);
    Ok(PyArray1::from_vec(py, flat).reshape(s)?.into_any())
}

/// An array of scalars (f32 or bool) with shape `shape`.
fn out<'py, T: numpy::Element>(
    py: Python<'py>,
    v: Vec<T>,
    shape: &[usize],
) -> PyResult<Bound<'py, PyAny>> {
    Ok(PyArray1::from_vec(py, v)
        .reshape(shape.to_vec())?
        .into_any())
}

/// `(a, b, c)` with each number as Python reads it back exactly (f32's shortest round trip).
fn tuple3(v: Vec3) -> String {
    format!("({:?}, {:?}, {:?})", v.x, v.y, v.z)
}

#[pymodule]
fn _xylem(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyWoodBsdf>()?;
    m.add_class::<PyWoodVolume>()?;
    m.add_class::<PyWoodSurface>()?;
    m.add_class::<PyWoodHits>()?;
    m.add_class::<PyScene>()?;
    m.add_function(wrap_pyfunction!(load_file, m)?)?;
    m.add_function(wrap_pyfunction!(load_dict, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(render, m)?)?;
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(fit, m)?)?;
    m.add_function(wrap_pyfunction!(max_lobe_albedo, m)?)?;
    m.add_function(wrap_pyfunction!(rough_finish_nodes, m)?)?;
    m.add("PRESETS", xylem::wood::PRESET_NAMES.to_vec())?;
    Ok(())
}
