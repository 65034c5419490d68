//! Perception front-end of logicrag: turns what a camera saw into window
//! facts with provenance.
//!
//! - [`model`]: the shared data model — [`Sequence`] (one camera, frames of
//!   [`Observation`]s sorted by `(frame, track_id)`), [`Track`],
//!   [`WindowSpec`], [`Fact`] with [`Provenance`], [`WindowFacts`], and the
//!   simulator's per-frame [`SceneState`].
//! - [`error`]: [`PerceptionError`], the crate's one error type.
#![forbid(unsafe_code)]

pub mod error;
pub mod model;

pub use error::PerceptionError;
pub use model::{
    BBox2D, Box3D, CameraConfig, CameraIntrinsics, CameraPose, Fact, ObjectClass, Observation,
    Provenance, SceneObject, SceneState, Sequence, StaticElement, StaticShape, Track, WindowFacts,
    WindowSpec,
};
