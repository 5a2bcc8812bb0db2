//! Frame fields and point fields of the wood model (Liu et al. 2016 §5): cylindrical coordinates, interlocked grain, distortion with its Jacobian.
