//! Light-sweep sequences: the light path, the per-sweep cache of what does not change, contact sheet and viewer.
