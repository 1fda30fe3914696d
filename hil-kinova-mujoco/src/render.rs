//! Offscreen rendering (see render docs).
