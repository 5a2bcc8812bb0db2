//! Helpers shared by integration tests (each test binary includes this module with `mod common;`).

pub mod python;
