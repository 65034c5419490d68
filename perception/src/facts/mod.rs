//! Window facts: the one place every source's [`Sequence`] becomes positive
//! facts with provenance.
//!
//! [`Analysis::new`] does the per-sequence work once: ego-motion
//! ([`crate::ego`]), world-frame trajectories per track with Hampel outlier
//! rejection and Savitzky–Golay smoothing, per-frame speeds. Each window then
//! measures, per object and per pair, the quantities behind the vocabulary
//! and compares them with the named [`FactConfig`] thresholds; every fact's
//! [`Provenance`](crate::model::Provenance) carries the measured value and
//! the threshold's field name.
//! Pair relations come in two kinds: symmetric ones (`TooClose`, distance
//! trends) emitted both ways, and the relative positions `LeftOf`/`RightOf`
//! and `InFrontOf`/`Behind`, each emitted together with its converse from
//! one vote over the frames the pair shares (`FactConfig::relative`).
//! The ego (the constant [`EGO`]) has facts of its own — `Ego(ego)`, its
//! motion from the estimated camera trajectory tested like a vehicle's,
//! `TurnLeft`/`TurnRight` — and relations to every object (relative
//! positions, distance trends, `Near`); objects are compared by distance to
//! the ego (`Closer`) and by speed (`Faster`, the ego included).
//!
//! Closed world: only positive facts are emitted; `¬Moving(x)` is the
//! absence of `Moving(x)`.

use crate::config::FactConfig;
use crate::coords::CameraBev;
use crate::ego::EgoMotion;
use crate::error::PerceptionError;
use crate::model::{Fact, ObjectClass, Sequence, WindowFacts, WindowSpec};
use crate::signal::CaSmoothed;

mod analysis;
mod compare;
mod distance;
mod ego_facts;
mod emit;
mod location;
mod motion;
mod objects;
mod pairs;
mod relative;

/// `TypeOf` values the vocabulary declares; other types become `Other`.
/// The Argoverse 2 categories' values (`RegularVehicle` … ,
/// `perception::av2::categories`) follow KITTI's and the simulator's.
pub const TYPE_VALUES: [&str; 44] = [
    "Car",
    "Van",
    "Truck",
    "Tram",
    "Bus",
    "Motorcycle",
    "Bicycle",
    "SUV",
    "Sedan",
    "Coupe",
    "Hatchback",
    "Wagon",
    "Minivan",
    "Cab",
    "Convertible",
    "PoliceCar",
    "Pedestrian",
    "Cyclist",
    "RegularVehicle",
    "LargeVehicle",
    "SchoolBus",
    "ArticulatedBus",
    "BoxTruck",
    "TruckCab",
    "VehicularTrailer",
    "RailedVehicle",
    "OfficialSignaler",
    "Bicyclist",
    "Motorcyclist",
    "WheeledRider",
    "WheeledDevice",
    "Wheelchair",
    "Stroller",
    "Dog",
    "Animal",
    "MessageBoardTrailer",
    "TrafficLightTrailer",
    "Bollard",
    "ConstructionCone",
    "ConstructionBarrel",
    "Sign",
    "StopSign",
    "MobilePedestrianCrossingSign",
    "Other",
];

/// `ColorOf` values the vocabulary declares; other colours become `Other`.
pub const COLOR_VALUES: [&str; 13] = [
    "Black", "Blue", "Brown", "Cyan", "Green", "Grey", "Orange", "Red", "Violet", "White",
    "Yellow", "Silver", "Other",
];

/// Footprint side (m) assumed for objects without a labelled size.
const DEFAULT_FOOTPRINT_M: f64 = 0.6;

/// Facts for every window of `seq`: the entry point every source goes through.
pub fn window_facts(
    seq: &Sequence,
    windows: WindowSpec,
    config: &FactConfig,
) -> Result<Vec<WindowFacts>, PerceptionError> {
    // Validate first: the spans are one entry per window of `frame_count`,
    // which must be checked against MAX_FRAMES before it sizes anything.
    let analysis = Analysis::new(seq, config)?;
    let spans = windows.windows(seq.frame_count)?;
    Ok(spans
        .into_iter()
        .map(|(i, a, b)| analysis.window(i, a, b))
        .collect())
}

/// Facts for the single window `first..=last` (index 0), with look-back and
/// look-ahead into the rest of the sequence.
pub fn range_facts(
    seq: &Sequence,
    first: u32,
    last: u32,
    config: &FactConfig,
) -> Result<WindowFacts, PerceptionError> {
    if first > last || last >= seq.frame_count {
        return Err(PerceptionError::InvalidWindow(format!(
            "frames {first}-{last} are not a range inside the sequence's {} frames",
            seq.frame_count
        )));
    }
    Ok(Analysis::new(seq, config)?.window(0, first, last))
}

/// Per-track state prepared once per sequence.
#[derive(Debug, Clone)]
pub(crate) struct TrackState {
    pub(crate) name: String,
    /// The sequence's track id (`u32::MAX` for the ego's own track).
    track_id: u32,
    pub(crate) class: ObjectClass,
    type_value: Option<String>,
    color_value: Option<String>,
    /// Indices into the sequence's observations, ascending frame.
    pub(crate) obs: Vec<usize>,
    /// Frames of `obs`.
    pub(crate) frames: Vec<u32>,
    /// Camera bird's-eye ground point per observation.
    pub(crate) cam: Vec<Option<CameraBev>>,
    /// Surface polygon per observation (ground-surface classes), camera
    /// frame.
    footprints: Vec<Option<Vec<CameraBev>>>,
    /// Whether this track is a ground surface (has footprints).
    pub(crate) surface: bool,
    /// Frames with a world position, and the Savitzky–Golay speeds (m/s) there.
    w_frames: Vec<f64>,
    /// World positions after outlier rejection, before smoothing (slopes
    /// and their standard errors are measured on these).
    raw_x: Vec<f64>,
    raw_z: Vec<f64>,
    /// Kalman/RTS smoother: smoothed world speed (m/s) and its posterior
    /// standard deviation at each of `w_frames`, and the sightings its gate
    /// rejected. Computed for every track: speed changes always use it.
    kal_speed: Vec<f64>,
    kal_speed_sd: Vec<f64>,
    /// Constant-acceleration RTS smoothing of the ground positions (x, z),
    /// which measures speed changes.
    ca: [CaSmoothed; 2],
    kal_rejected: usize,
    /// Hampel replacements over the track (Savitzky–Golay path).
    hampel_replaced: usize,
    /// Whether this is the ego's own trajectory (the estimated camera
    /// path), not a tracked object.
    ego: bool,
}

/// A sequence prepared for window fact extraction.
#[derive(Debug, Clone)]
pub struct Analysis<'a> {
    seq: &'a Sequence,
    config: &'a FactConfig,
    /// The estimated camera trajectory.
    pub ego: EgoMotion,
    tracks: Vec<TrackState>,
    source: std::sync::Arc<str>,
    /// The ego's own trajectory (the estimated camera path, [`Self::ego`])
    /// as a track named [`EGO`], smoothed like an object's, so that its
    /// `Moving`/`SpeedUp`/`SpeedDown` pass the same tests as a vehicle's.
    ego_track: TrackState,
    /// The ego's heading per frame (radians, unwrapped along the sequence,
    /// KITTI sense: growing as it turns right) and the standard deviation
    /// of one frame's heading, measured on its second differences.
    ego_yaw: Vec<f64>,
    ego_yaw_sd: f64,
    /// The standard deviation (m) of the ego's estimated positions in world
    /// X and Z that its smoothing assumed.
    ego_pos_sd: [f64; 2],
    /// The 360° relations and map facts' per-sequence state (surround
    /// sequences only, [`crate::around`]).
    around: Option<crate::around::Around>,
}

/// The constant that names the ego (the recording vehicle, the camera's
/// carrier) in facts: `Ego(ego)`, `Moving(ego)`, `InFrontOf(car_3, ego)`.
pub const EGO: &str = "ego";

/// The `TypeOf` value a source's type name becomes: its [`TYPE_VALUES`]
/// spelling (case-insensitive), else `Other`. What a source *can* assign
/// is this over its label set: KITTI's `Misc` and `Person_sitting` are
/// `Other`, so no KITTI object is ever a `Sedan` or a `Bus`.
pub fn type_value(type_name: &str) -> String {
    vocab_value(type_name, &TYPE_VALUES)
}

fn vocab_value(value: &str, list: &[&str]) -> String {
    list.iter()
        .find(|v| v.eq_ignore_ascii_case(value))
        .map_or_else(|| "Other".to_string(), |v| (*v).to_string())
}

struct WindowCtx<'w, 'a> {
    a: &'w Analysis<'a>,
    index: u32,
    first: u32,
    last: u32,
    facts: Vec<Fact>,
    /// Measured and not asserted, with the probability that they hold.
    doubts: Vec<Fact>,
    /// The window speed (m/s) and its standard error of every mover whose
    /// `Moving` was measured (the ego included), by name, for `Faster`.
    speeds: Vec<(String, f64, f64)>,
}

#[cfg(test)]
mod tests;
