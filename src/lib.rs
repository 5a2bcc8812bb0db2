#![warn(missing_docs)]
//! xylem: a wood-appearance simulator.
//!
//! The finished-wood fibre BSDF of Marschner et al. 2005, driven by the procedural
//! solid-wood frame fields of Liu, Dong, Hašan and Marschner 2016, rendered by a BVH
//! path tracer. Module layout and dependency direction: `notes/design.md`
//! (arrows point down the list below; only `cli` may use everything).

pub mod bake;
pub mod bench;
pub mod bsdf;
pub mod builtin;
#[cfg(feature = "cli")]
pub mod cli;
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
pub mod scene;
pub mod simd;
pub mod sweep;
pub mod texture;
pub mod validate;
pub mod wood;
