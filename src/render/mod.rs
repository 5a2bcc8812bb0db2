//! The BVH path tracer: camera, lights, meshes on an obvhs BVH, integrator, film with AOVs,
//! EXR / PNG output and progress.

pub mod image_io;
