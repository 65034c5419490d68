//! Perception front-end of logicrag: turns what a camera saw into window
//! facts with provenance.
//!
//! - [`model`]: the shared data model — [`Sequence`] (one camera, frames of
//!   [`Observation`]s sorted by `(frame, track_id)`), [`Track`],
//!   [`WindowSpec`], [`Fact`] with [`Provenance`], [`WindowFacts`], and the
//!   simulator's per-frame [`SceneState`].
//! - [`error`]: [`PerceptionError`], the crate's one error type.
#![forbid(unsafe_code)]

pub mod config;
pub mod ego;
pub mod error;
pub mod facts;
pub mod geometry;
pub mod kitti;
pub mod model;
pub mod signal;
pub mod sim;
pub mod source;
pub mod json;
pub mod raw;

pub use config::{EgoConfig, FactConfig};
pub use error::PerceptionError;
pub use facts::{Analysis, range_facts, window_facts};
pub use source::Source;
pub use model::{
    BBox2D, Box3D, CameraConfig, CameraIntrinsics, CameraPose, Fact, ObjectClass, Observation,
    Provenance, SceneObject, SceneState, Sequence, StaticElement, StaticShape, Track, WindowFacts,
    WindowSpec,
};
