//! Pictures made from numbers and the files they go to: the in-memory images (`Image`, linear
//! RGB; `Rgb8`, 8-bit sRGB), the sRGB transfer function and its exact 8-bit encoding, EXR and
//! PNG files (read and written by extension through `Image`), animated PNGs, the staging every
//! image file is written through, contact sheets with a bitmap font for their labels, and line
//! plots for reports and trade-off curves.

pub mod contact;
pub mod exr;
pub mod file;
pub(crate) mod image;
pub mod plot;
pub mod png;
pub mod srgb;

pub use file::ImageError;
pub use image::{Image, Rgb8};
