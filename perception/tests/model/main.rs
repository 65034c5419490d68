//! Perception's integration tests that need no ONNX Runtime, in one binary
//! (one link instead of one per file): Argoverse 2 logs, KITTI labels, relative-position
//! facts, the simulator against its own truth, and the ego's facts against
//! the simulated ego path.

mod av2;
mod ego;
mod kitti;
mod relative;
mod sim;
