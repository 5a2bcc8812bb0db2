//! Frame fields and point fields of the wood model (Liu et al. 2016 §5–6): cylindrical coordinates
//! and their frame (r̂, θ̂, ẑ), the interlocked-grain rotation about r̂, and the distortion
//! `f(p) = p + m(p) a(p)` with its Jacobian for transporting fibre directions and gradients.

mod cylindrical;
mod distortion;
mod interlock;

pub(crate) use cylindrical::cylinder_cos_sin;
pub(crate) use cylindrical::cylinder_frame_from;
pub use cylindrical::{cylinder_frame, Cylindrical, PITH_EPSILON};
pub use distortion::{exact_jacobian, Displacement, Distortion, JacobianModel, Magnitude};
pub use interlock::rotate_about_radial;
pub(crate) use interlock::rotate_by;
