//! A directory of camera frames (or of dense maps) into a
//! [`Sequence`](crate::model::Sequence):
//! detection (or dense instances) → tracker → 3D → colour, ready for the same
//! [`crate::window_facts`] as every other source.
//!
//! The models file given to [`FramesSource::open`] is either one detector
//! config (see [`super::config`]) or a set:
//!
//! ```yaml
//! detector: nanodet-m-416-coco.yaml   # relative to this file
//! depth: my-depth.yaml                # optional: metric depth replaces the monocular estimate;
//!                                     # relative depth is fitted onto it per frame
//! flow: my-flow.yaml                  # optional: flow-guided tracking
//! ```
//!
//! One file per stage: the run's settings ([`FramesOptions`], [`Progress`],
//! [`assumed_camera`]), the models file ([`ModelSet`]), the frames of a
//! directory ([`list_frames`]), the model pipeline ([`FramesSource`],
//! [`FramesPipeline`]), the dense-map source ([`sequence_from_dense`],
//! [`read_dense_dir`]), and the assembler both sources end in (tracker, 3D,
//! colour); everything public is re-exported here.

mod assemble;
mod dense_source;
mod input;
mod modelset;
mod options;
mod pipeline;

pub use dense_source::{read_dense_dir, sequence_from_dense};
pub use input::{MAX_IMAGE_PIXELS, list_frames, open_image};
pub use modelset::ModelSet;
pub use options::{DEFAULT_CAMERA_HEIGHT_M, FramesOptions, Progress, assumed_camera};
pub use pipeline::{FramesPipeline, FramesSource};
