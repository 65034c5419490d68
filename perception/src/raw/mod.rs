//! Perception from raw camera frames: ONNX models run through `ort`, their
//! outputs decoded into detections or dense maps, tracked across frames, lifted
//! to 3D and handed to the same [`crate::window_facts`] as every other source.
//!
//! The pipeline, one module per stage:
//! - [`runtime`]: finds the ONNX Runtime shared library (from `ORT_DYLIB_PATH`
//!   or the `onnxruntime` Python wheel), loads it with `ort::init_from`, and
//!   runs models ([`runtime::ModelRunner`]) with checked input shapes and
//!   checked (finite, non-empty) outputs.
//! - [`config`]: the model YAML file ([`config::ModelConfig`]): model path,
//!   input size/layout/colour order/normalisation, what the output means
//!   (detector with a named decoder, segmentation, depth, flow) and the label
//!   map onto LogicPad classes and `TypeOf` values.
//! - [`preprocess`]: letterbox / stretch / tiling of wide frames into the
//!   model's input tensor and the inverse mapping of boxes.
//! - [`decode`]: output decoders (`nanodet_gfl`, segmentation argmax, depth,
//!   flow) and per-class NMS.
//! - [`detect`]: [`detect::Detector`], frame in, mapped detections out.
//! - [`dense`]: dense maps (semantic / instance / depth / flow), from a model or
//!   PNG files, into per-class connected-component instances.
//! - [`tracker`]: Hungarian IoU tracker with constant-velocity (or flow)
//!   prediction and stable ids.
//! - [`camera`]: calibration files (KITTI `calib` or YAML) for the frames'
//!   intrinsics and mounting height.
//! - [`color`]: names the colour of the pixels inside a box with the LogicPad
//!   colour values.
//! - [`ground`]: flat-ground 3D from the box bottom edge.
//! - [`mono`]: monocular depth without a depth model: flat ground, a
//!   per-class size prior, or their inverse-variance fusion (the default),
//!   with the nearest-face → centre correction; each estimate names its method.
//! - [`relative`]: a relative depth map (`mode: relative`) made metric per
//!   frame by a robust fit onto the monocular near-face depths (scale for
//!   depth, scale and shift for inverse depth).
//! - [`frames`]: [`frames::FramesSource`], a directory of frames to a
//!   [`crate::model::Sequence`].
//! - [`render`]: dense maps rendered from the simulator's per-frame scene state
//!   (so the dense path is tested against truth).
//! - [`view`]: the simulator's camera view, a scene state rendered to an RGB
//!   picture (sky, ground by class, shaded boxes in their colours).

pub mod camera;
pub mod color;
pub mod config;
pub mod decode;

pub mod dense;
pub mod detect;
pub mod error;
pub mod eval;
pub mod frames;
pub mod ground;
pub mod mono;

pub mod preprocess;
pub mod relative;
pub mod render;

pub mod runtime;
pub mod tracker;
pub mod view;

pub use error::RawError;
