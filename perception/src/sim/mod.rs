//! A seeded, deterministic scene simulator with exactly known events.
//!
//! A [`Scenario`] (YAML/JSON, or one of [`BUILTIN_NAMES`]) describes flat
//! ground with roads, sidewalks and props, an ego vehicle carrying a
//! KITTI-like pinhole camera, and agents with commanded motion phases
//! (accelerate, brake, turn, merge, walk into a vehicle) or parked.
//! [`simulate`] integrates the motion at the scenario's frame rate, resolves
//! contacts (vehicles that touch collide and stop; a pedestrian reaching the
//! vehicle it enters vanishes), projects every object into the camera (boxes
//! clipped to the image; objects behind, too far or too small are not
//! observed), optionally applies a seeded noise model, and returns a
//! [`SimRun`]: the observed [`crate::Sequence`], the ground-truth event log
//! ([`Event`]) and the per-frame [`crate::SceneState`] for renderers.
//! [`truth`] compares window facts with the log.
//!
//! Not modelled: occlusion between objects (every object in the frustum is
//! observed; the noise model's `miss_per_occlusion` drops boxes covered by
//! nearer ones), slopes, lighting. [`NoisePreset`] names the noise study's
//! levels.

mod noise;
mod run;
mod scenario;
pub mod truth;

pub use run::{
    ENTER_CONTACT_M, EVENT_ACCEL_MPS2, EVENT_GAP_RATE_MPS, EVENT_STAND_MPS, Event, EventKind,
    ID_SWITCH_BASE, SimRun, scene_states, simulate,
};
pub use scenario::{
    AgentSpec, BUILTIN_NAMES, MAX_SCENARIO_OBJECT_FRAMES, MAX_SCENARIO_OBJECTS, MotionSpec,
    NoiseLevel, NoiseLevelError, NoisePreset, NoiseSpec, Phase, PropSpec, RoadSpec, Scenario,
    ViewSpec, WorldSpec, builtin_text, default_camera, default_size,
};
