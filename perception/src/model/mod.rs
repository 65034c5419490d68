//! The perception data model shared by every source (KITTI labels, JSON
//! tracks, the simulator, the raw-frames pipeline): a [`Sequence`] of
//! per-frame [`Observation`]s seen by one calibrated camera, cut into windows
//! by a [`WindowSpec`], each window yielding [`WindowFacts`] — positive facts
//! with [`Provenance`].
//!
//! Coordinates follow KITTI's rectified camera: X right, Y down, Z forward,
//! metres. The simulator's world frame shares the Y axis (down) with the
//! camera, the ground plane is `Y = 0` and the camera sits at `Y = -height_m`.
//!
//! One file per concept: the camera ([`CameraIntrinsics`], [`CameraConfig`],
//! the simulator's [`CameraPose`]), boxes ([`BBox2D`], [`Box3D`]), [`ObjectClass`],
//! [`Observation`], [`Sequence`] and [`Track`], [`Fact`] with
//! [`Provenance`], [`WindowSpec`] with [`WindowFacts`], and the simulator's
//! [`SceneState`]; everything is re-exported here.

mod bbox;
mod camera;
mod class;
mod fact;
mod map;
mod observation;
mod scene;
mod sequence;
mod window;

pub use bbox::{BBox2D, Box3D};
pub use camera::{CameraConfig, CameraIntrinsics, CameraPose};
pub use class::ObjectClass;
pub use fact::{Fact, Provenance};
pub use map::{LaneKind, MapArea, MapLane, SceneMap, Skipped, WorldPose, fps_from_timestamps};
pub use observation::{DepthSource, Observation};
pub use scene::{SceneObject, SceneState, StaticElement, StaticShape};
pub use sequence::{
    DEFAULT_FPS, MAX_FRAMES, MAX_OBJECTS_PER_FRAME, SHORT_KEY_LEN, Sequence, Track,
    check_frame_count, check_objects_per_frame, object_name_for, short_key,
};
pub use window::{WindowFacts, WindowSpec};
