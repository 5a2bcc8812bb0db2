//! Light-sweep sequences: the light path, the per-sweep cache of what does not change, contact
//! sheet and viewer.
//!
//! - [`cache`]: rendering the frames with the light-independent work done once;
//! - [`job`]: a whole `xylem sweep` run (render, write, assemble);
//! - [`manifest`]: the capture format (camera, board, lights per frame) a fit reads;
//! - [`path`]: the arc of light directions, frame angles and `--frames-range` slices;
//! - [`sequence`]: per-frame records and the assembly of a folder of frames into the contact
//!   sheet ([`contact`]), animated PNG, CSV and the HTML [`viewer`];
//! - [`plot`]: small line plots for the validation report and the trade-off curve;
//! - [`tradeoff`]: the speed/accuracy measurements behind `--quality`;
//! - [`highlight`]: where the fibre highlight of a flat finished board peaks along the arc.

pub mod cache;
pub mod contact;
pub mod highlight;
pub mod job;
pub mod manifest;
pub mod path;
pub mod plot;
pub mod sequence;
pub mod tradeoff;
pub mod viewer;

pub use crate::scene::MAX_ARCS;
pub use path::{parse_arc, parse_frames_range, ArcPlane, LightArc, PathError};
pub use sequence::{assemble, AssembleOptions, FrameRecord, Region, SequenceError};
