//! The TOML scene format, built-in procedural shapes, mesh loading and preset lookup.
