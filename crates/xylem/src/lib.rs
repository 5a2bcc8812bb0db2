#![deny(missing_docs)]
//! xylem: a wood-appearance simulator.
//!
//! The finished-wood fibre BSDF of Marschner et al. 2005, driven by the procedural
//! solid-wood frame fields of Liu, Dong, Hašan and Marschner 2016, rendered by a BVH
//! path tracer. This is the engine crate; the validation lab (`xylem-lab`) and the command line
//! (`xylem-cli`) are crates of their own that depend on it, never the reverse. Module layout and
//! the dependency direction between modules: `notes/design.md`.

pub mod bake;
pub mod bsdf;
pub mod builtin;
pub mod field;
pub mod fit;
pub mod jsonpath;
pub mod material;
pub mod math;
pub mod noise;
pub mod output;
pub mod picture;
pub mod progress;
pub mod render;
pub mod resources;
pub mod scene;
pub mod simd;
pub mod sweep;
pub mod texture;
pub mod wood;
