//! Turns a surface hit into a BSDF by evaluating a solid texture or the wood volume.
