//! Pictures made from numbers: contact sheets with a bitmap font for their labels, and line plots
//! for reports and trade-off curves (8-bit sRGB images, written as PNG by the callers).

pub mod contact;
pub mod plot;
