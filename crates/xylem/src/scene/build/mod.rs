//! Building a scene from its parsed file, one table kind per module: each adds methods to
//! [`Builder`](super::Builder), whose checks name the field and the allowed range.

mod lights;
mod materials;
mod objects;
mod settings;
