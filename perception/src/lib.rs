//! Perception front-end of logicrag: turns what a camera saw into window
//! facts with provenance.
//!
//! - [`model`]: the shared data model — [`Sequence`] (one camera, frames of
//!   [`Observation`]s sorted by `(frame, track_id)`), [`Track`],
//!   [`WindowSpec`], [`Fact`] with [`Provenance`], [`WindowFacts`], and the
//!   simulator's per-frame [`SceneState`].
//! - [`coords`]: points whose type names their frame — [`CameraBev`] and
//!   [`WorldBev`] on the bird's-eye ground plane, [`CameraPoint`] and
//!   [`WorldPoint`] in 3D — and [`EgoPose`] ([`ego`]), the estimated
//!   camera pose that maps a frame's camera ground points into the world.
//! - [`error`]: [`PerceptionError`], the crate's one error type.
//! - Sources, all producing a [`Sequence`]: [`kitti`] (tracking labels +
//!   calib `P2`), [`json`] (the `logicrag-tracks/1` and `/2` formats), [`sim`] (a
//!   seeded scene simulator with a ground-truth event log and per-frame
//!   scene states), and `raw` (detector → tracker → 3D from raw frames,
//!   behind the default-on cargo feature `raw`);
//!   [`source::Source`] parses `kitti:DIR`, `sim:NAME[@SEED]`, `json:FILE`.
//! - [`facts`]: [`window_facts`], the one entry point every source goes
//!   through — ego-motion ([`ego`]), outlier rejection and Savitzky–Golay
//!   smoothing ([`signal`]), bird's-eye geometry ([`geometry`]), then
//!   positive facts per window compared with the thresholds of one typed
//!   [`FactConfig`] ([`config`]); each measured fact with its probability,
//!   and the facts measured and not asserted as doubts ([`belief`]).
//!
//! ```no_run
//! use perception::{FactConfig, Source, WindowSpec, window_facts};
//! let seq = Source::parse("sim:urban_crossing")?.load(None)?;
//! for w in window_facts(&seq, WindowSpec::PAPER, &FactConfig::default())? {
//!     print!("{}", w.to_kb());
//! }
//! # Ok::<(), perception::PerceptionError>(())
//! ```
#![forbid(unsafe_code)]
#![warn(missing_docs, unreachable_pub)]

pub mod around;
pub mod av2;
pub mod belief;
pub mod config;
pub mod coords;
pub mod ego;
pub mod error;
pub mod facts;
pub mod geometry;
pub mod json;
pub mod kitti;
pub mod mapfacts;
pub mod model;
#[cfg(feature = "raw")]
pub mod raw;
pub mod signal;
pub mod sim;
pub mod source;
pub mod textfile;

pub use config::{AroundConfig, EgoConfig, FactConfig, RelativeConfig, Smoother};
pub use coords::{BevPoint, CameraBev, CameraPoint, WorldAnchor, WorldBev, WorldPoint};
pub use ego::EgoPose;
pub use error::PerceptionError;
pub use facts::{Analysis, range_facts, window_facts};
pub use model::{
    BBox2D, Box3D, CameraConfig, CameraIntrinsics, CameraPose, DepthSource, Fact, LaneKind,
    MAX_FRAMES, MAX_OBJECTS_PER_FRAME, MapArea, MapLane, ObjectClass, Observation, Provenance,
    SceneMap, SceneObject, SceneState, Sequence, Skipped, StaticElement, StaticShape, Track,
    WindowFacts, WindowSpec, WorldPose,
};
pub use source::Source;
