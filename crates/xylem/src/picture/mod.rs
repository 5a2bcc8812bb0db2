//! Pictures made from numbers and the files they go to: the sRGB transfer function and its exact
//! 8-bit encoding, PNG and animated-PNG files, the staging every image file is written through,
//! contact sheets with a bitmap font for their labels, and line plots for reports and trade-off
//! curves.

pub mod contact;
pub mod file;
pub mod plot;
pub mod png;
pub mod srgb;

pub use file::ImageError;
