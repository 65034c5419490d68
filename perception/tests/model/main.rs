//! Perception's integration tests that need no ONNX Runtime, in one binary
//! (one link instead of one per file): KITTI labels, relative-position
//! facts, and the simulator against its own truth.

mod kitti;
mod relative;
mod sim;
