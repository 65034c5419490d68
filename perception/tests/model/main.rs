//! Perception's integration tests that need no ONNX Runtime, in one binary
//! (one link instead of one per file): KITTI labels, relative-position
//! facts, the simulator against its own truth, and the ego's facts against
//! the simulated ego path.

mod ego;
mod kitti;
mod relative;
mod sim;
