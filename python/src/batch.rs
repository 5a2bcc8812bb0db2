//! numpy-style broadcasting of the bindings' array arguments over their leading dimensions.
//!
//! A 3-vector argument has shape `(..., 3)`, a 2-vector one `(..., 2)`, a scalar one `(...)`;
//! what comes before the vector axis is the argument's *leading shape*. The leading shapes of a
//! call's arguments broadcast as numpy broadcasts (aligned on the right, each dimension equal or
//! 1), and the results have the broadcast shape followed by their own trailing axes: an `(H, W,
//! 3)` grid of directions gives an `(H, W, 3)` grid of values, a `(0, 3)` batch an empty result.
//! Every input value must be finite: a NaN or an infinity is a `ValueError` naming the argument
//! and the element's index, never a plausible-looking number.

use glam::{Vec2, Vec3};
use numpy::{PyArrayDyn, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// One argument: its leading shape and its values, row-major.
pub struct Arg<T> {
    pub lead: Vec<usize>,
    pub data: Vec<T>,
}

impl<T: Copy> Arg<T> {
    /// An argument of one value and leading shape `()` (a default).
    pub fn one(v: T) -> Self {
        Arg {
            lead: Vec::new(),
            data: vec![v],
        }
    }
}

/// `(2, 3)` as numpy prints a shape.
pub fn shape_str(s: &[usize]) -> String {
    match s {
        [] => "()".into(),
        [a] => format!("({a},)"),
        _ => format!(
            "({})",
            s.iter()
                .map(|x| x.to_string())
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// The multi-index of flat row-major position `i` in `shape`, as numpy prints an index.
pub fn index_str(shape: &[usize], mut i: usize) -> String {
    let mut idx = vec![0; shape.len()];
    for (k, &d) in shape.iter().enumerate().rev() {
        if d > 0 {
            idx[k] = i % d;
            i /= d;
        }
    }
    match idx.as_slice() {
        [a] => a.to_string(),
        _ => shape_str(&idx).replace(",)", ")"),
    }
}

/// The values of `a` (anything `numpy.asarray(a, "float32")` takes) with its leading shape; the
/// last axis must have length `width` (0: no vector axis, a scalar argument). Non-finite values
/// are refused. (rust-numpy's `PyArrayLike` is not used: it reads a (0, 3) array as shape (0,).)
fn extract(name: &str, a: &Bound<'_, PyAny>, width: usize) -> PyResult<(Vec<usize>, Vec<f32>)> {
    let np = a.py().import("numpy")?;
    let arr = np
        .call_method1("asarray", (a, "float32"))
        .map_err(|e| PyValueError::new_err(format!("{name}: not an array of numbers ({e})")))?;
    let arr = arr.downcast::<PyArrayDyn<f32>>()?.readonly();
    let v = arr.as_array();
    let shape = v.shape().to_vec();
    let lead = if width == 0 {
        shape.clone()
    } else {
        match shape.split_last() {
            Some((&last, lead)) if last == width => lead.to_vec(),
            _ => {
                return Err(PyValueError::new_err(format!(
                    "{name}: shape {}, expected (..., {width}) ({width}-vectors over any leading dimensions)",
                    shape_str(&shape)
                )))
            }
        }
    };
    let flat: Vec<f32> = v.iter().copied().collect();
    if let Some(i) = flat.iter().position(|x| !x.is_finite()) {
        return Err(PyValueError::new_err(format!(
            "{name}: element {} is {}; every input must be finite",
            index_str(&shape, i),
            flat[i]
        )));
    }
    Ok((lead, flat))
}

/// A 3-vector argument of shape (..., 3).
pub fn vec3(name: &str, a: &Bound<'_, PyAny>) -> PyResult<Arg<Vec3>> {
    let (lead, flat) = extract(name, a, 3)?;
    let data = flat.chunks_exact(3).map(Vec3::from_slice).collect();
    Ok(Arg { lead, data })
}

/// A 2-vector argument of shape (..., 2).
pub fn vec2(name: &str, a: &Bound<'_, PyAny>) -> PyResult<Arg<Vec2>> {
    let (lead, flat) = extract(name, a, 2)?;
    let data = flat.chunks_exact(2).map(Vec2::from_slice).collect();
    Ok(Arg { lead, data })
}

/// A 3×3-matrix argument of shape (..., 3, 3) (rows last), as rows.
pub fn mat3(name: &str, a: &Bound<'_, PyAny>) -> PyResult<Arg<[Vec3; 3]>> {
    let (rows, flat) = extract(name, a, 3)?;
    let lead = match rows.split_last() {
        Some((&3, lead)) => lead.to_vec(),
        _ => {
            let mut shape = rows;
            shape.push(3);
            return Err(PyValueError::new_err(format!(
                "{name}: shape {}, expected (..., 3, 3) (3x3 matrices over any leading dimensions)",
                shape_str(&shape)
            )));
        }
    };
    let data = flat
        .chunks_exact(9)
        .map(|m| {
            [
                Vec3::from_slice(&m[0..3]),
                Vec3::from_slice(&m[3..6]),
                Vec3::from_slice(&m[6..9]),
            ]
        })
        .collect();
    Ok(Arg { lead, data })
}

/// A scalar argument of any shape.
pub fn scalar(name: &str, a: &Bound<'_, PyAny>) -> PyResult<Arg<f32>> {
    let (lead, data) = extract(name, a, 0)?;
    Ok(Arg { lead, data })
}

/// Where element `i` of the broadcast shape is in one argument.
pub enum Map {
    /// The argument has the broadcast shape.
    Same,
    /// The argument has one value.
    One,
    /// Any other broadcast: position of each element.
    Table(Vec<usize>),
}

impl Map {
    #[inline]
    pub fn get(&self, i: usize) -> usize {
        match self {
            Map::Same => i,
            Map::One => 0,
            Map::Table(t) => t[i],
        }
    }
}

/// The broadcast of a call's arguments: the result's leading shape, its element count and how
/// to find each argument's element.
pub struct Broadcast {
    pub shape: Vec<usize>,
    pub len: usize,
    pub maps: Vec<Map>,
}

impl Broadcast {
    /// numpy's broadcast of the leading shapes `args` (name, shape), or a `ValueError` naming
    /// the argument that does not fit and every shape.
    pub fn new(args: &[(&str, &[usize])]) -> PyResult<Self> {
        let ndim = args.iter().map(|a| a.1.len()).max().unwrap_or(0);
        let mut shape = vec![1usize; ndim];
        for (name, s) in args {
            let off = ndim - s.len();
            for (k, &d) in s.iter().enumerate() {
                let out = &mut shape[off + k];
                if *out == 1 {
                    *out = d;
                } else if d != 1 && d != *out {
                    let all: Vec<String> = args
                        .iter()
                        .map(|(n, s)| format!("{n}: {}", shape_str(s)))
                        .collect();
                    return Err(PyValueError::new_err(format!(
                        "{name}: leading shape {} does not broadcast with the other arguments' ({}); \
                         each leading dimension must be equal or 1, as in numpy",
                        shape_str(s),
                        all.join(", ")
                    )));
                }
            }
        }
        let len = shape.iter().product();
        let maps = args.iter().map(|(_, s)| map(s, &shape, len)).collect();
        Ok(Broadcast { shape, len, maps })
    }

    /// The result shape with trailing axes `tail`.
    pub fn with(&self, tail: &[usize]) -> Vec<usize> {
        let mut s = self.shape.clone();
        s.extend_from_slice(tail);
        s
    }
}

fn map(s: &[usize], shape: &[usize], len: usize) -> Map {
    let size: usize = s.iter().product();
    if s.len() == shape.len() && s == shape {
        return Map::Same;
    }
    if size == 1 {
        return Map::One;
    }
    // Row-major strides of `s`, 0 along the dimensions it broadcasts, aligned on the right.
    let off = shape.len() - s.len();
    let mut strides = vec![0usize; shape.len()];
    let mut step = 1;
    for k in (0..s.len()).rev() {
        if s[k] != 1 {
            strides[off + k] = step;
        }
        step *= s[k];
    }
    let mut table = Vec::with_capacity(len);
    let mut idx = vec![0usize; shape.len()];
    let mut pos = 0usize;
    for _ in 0..len {
        table.push(pos);
        // Advance the multi-index (row-major) and the position with it.
        for k in (0..shape.len()).rev() {
            idx[k] += 1;
            pos += strides[k];
            if idx[k] < shape[k] {
                break;
            }
            pos -= strides[k] * shape[k];
            idx[k] = 0;
        }
    }
    Map::Table(table)
}
