//! The raw-frames path (feature `raw`) in one binary: the dense maps end to
//! end, the monocular depth methods on KITTI's labelled boxes, the six real
//! KITTI frames through the NanoDet detector, and every decoder and error
//! path on tiny generated models. (Loading failures of the runtime itself
//! are `raw_runtime_missing`, a binary of their own: the runtime's API table
//! is process-global.)

mod common;
mod dense;
mod depth_labels;
mod kitti;
mod models;
