//! Integer hashes, value / gradient / cellular noise, fBm, domain warping and the sparse convolution noise of Liu et al. 2016 §4.
