//! Window facts: the one place every source's [`Sequence`] becomes positive
//! facts with provenance.
//!
//! [`Analysis::new`] does the per-sequence work once: ego-motion
//! ([`crate::ego`]), world-frame trajectories per track with Hampel outlier
//! rejection and Savitzky–Golay smoothing, per-frame speeds. Each window then
//! measures, per object and per pair, the quantities behind the vocabulary
//! and compares them with the named [`FactConfig`] thresholds; every fact's
//! [`Provenance`] carries the measured value and the threshold's field name.
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

use std::collections::BTreeMap;

use crate::config::{FactConfig, Smoother};
use crate::coords::CameraBev;
use crate::ego::{self, EgoMotion};
use crate::error::PerceptionError;
use crate::geometry::{
    convex_gap, covered_fraction, ground_point, observation_footprint, point_in_polygon,
};
use crate::model::{Fact, ObjectClass, Observation, Provenance, Sequence, WindowFacts, WindowSpec};
use crate::signal::{
    CaSmoothed, ca_rts, cv_rts, hampel, slope_noise_var, slope_with_error, theil_sen_at,
};

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

/// A window's change of speed as `WindowCtx::speed_change` measures it.
struct Change {
    /// Smoothed speed at the window's first and last sightings (m/s).
    v0: f64,
    v1: f64,
    /// Highest smoothed speed in the window (m/s).
    peak: f64,
    /// The change of speed (m/s) and its standard deviation.
    change: f64,
    sd: f64,
    /// How the speeds were smoothed, for provenance.
    smoothing: String,
}

/// What the smoothers make of one trajectory of world positions (a
/// track's, or the ego's own).
struct Smoothed {
    kal_speed: Vec<f64>,
    kal_speed_sd: Vec<f64>,
    ca: [CaSmoothed; 2],
    kal_rejected: usize,
    hampel_replaced: usize,
}

impl Smoothed {
    /// Smooths the world positions `(w_x, w_z)` at frames `w_frames` with
    /// measurement variances `(r_x, r_z)`: the constant-velocity and
    /// constant-acceleration Kalman/RTS smoothers on the positions as
    /// given, then the Hampel filter replaces outliers in `w_x`, `w_z` in
    /// place (for the least-squares slopes).
    fn of(
        config: &FactConfig,
        fps: f64,
        w_frames: &[f64],
        w_x: &mut [f64],
        w_z: &mut [f64],
        r_x: &[f64],
        r_z: &[f64],
    ) -> Smoothed {
        let (mut kal_speed, mut kal_speed_sd, mut kal_rejected) = (Vec::new(), Vec::new(), 0);
        let mut ca = [CaSmoothed::default(), CaSmoothed::default()];
        if !w_frames.is_empty() {
            let secs: Vec<f64> = w_frames.iter().map(|f| f / fps).collect();
            let kx = cv_rts(
                &secs,
                w_x,
                r_x,
                config.kalman_accel_psd,
                config.kalman_gate_sd,
            );
            let kz = cv_rts(
                &secs,
                w_z,
                r_z,
                config.kalman_accel_psd,
                config.kalman_gate_sd,
            );
            kal_rejected = kx.rejected.max(kz.rejected);
            // A sighting is an outlier when either axis's gate says so.
            let outliers: Vec<bool> = kx
                .outliers
                .iter()
                .zip(&kz.outliers)
                .map(|(a, b)| *a || *b)
                .collect();
            let q = config.kalman_jerk_psd;
            ca = [
                ca_rts(&secs, w_x, r_x, q, &outliers),
                ca_rts(&secs, w_z, r_z, q, &outliers),
            ];
            for i in 0..secs.len() {
                let (vx, vz) = (kx.velocity[i], kz.velocity[i]);
                let (ax, az) = (kx.velocity_var[i], kz.velocity_var[i]);
                let sp = (vx * vx + vz * vz).sqrt();
                // Delta method on |v|; at rest, the larger axis.
                let var = if sp > 1e-9 {
                    (vx * vx * ax + vz * vz * az) / (sp * sp)
                } else {
                    ax.max(az)
                };
                kal_speed.push(sp);
                kal_speed_sd.push(var.sqrt());
            }
        }
        // Outliers out before the least-squares slopes (a single bad
        // box would bend them).
        let hw = config.savgol_window as usize / 2 + 1;
        let hampel_replaced =
            hampel(w_x, hw, config.outlier_mad_k, 0.2) + hampel(w_z, hw, config.outlier_mad_k, 0.2);
        Smoothed {
            kal_speed,
            kal_speed_sd,
            ca,
            kal_rejected,
            hampel_replaced,
        }
    }
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

/// Median absolute value → standard deviation of a normal variable.
const MAD_TO_SD: f64 = 1.0 / 0.674_489_75;

/// The standard deviation of per-sample noise on a smooth series, from the
/// median absolute second difference (`y(t−1) − 2y(t) + y(t+1)` is about
/// `√6·σ` for independent noise σ on a smooth curve, as
/// [`crate::ego::MeasuredNoise`] measures object positions); 0 for fewer
/// than three samples.
fn second_difference_sd(y: &[f64]) -> f64 {
    let mut d: Vec<f64> = y
        .windows(3)
        .map(|w| (w[0] - 2.0 * w[1] + w[2]).abs())
        .collect();
    crate::signal::median_in_place(&mut d).map_or(0.0, |m| m * MAD_TO_SD / 6f64.sqrt())
}

/// The ego as a track: the estimated camera positions of every frame,
/// smoothed as an object's world positions are, with their measurement
/// noise measured on their own second differences (floored at
/// `kalman_min_sigma_m`); and its unwrapped heading per frame with that
/// heading's noise.
fn ego_track(
    fps: f64,
    config: &FactConfig,
    ego: &EgoMotion,
) -> (TrackState, Vec<f64>, f64, [f64; 2]) {
    let w_frames: Vec<f64> = (0..ego.poses.len()).map(|f| f as f64).collect();
    let mut w_x: Vec<f64> = ego.poses.iter().map(|p| p.position.x()).collect();
    let mut w_z: Vec<f64> = ego.poses.iter().map(|p| p.position.z()).collect();
    let floor = config.kalman_min_sigma_m;
    let sd = [
        second_difference_sd(&w_x).max(floor),
        second_difference_sd(&w_z).max(floor),
    ];
    let r_x = vec![sd[0] * sd[0]; w_x.len()];
    let r_z = vec![sd[1] * sd[1]; w_z.len()];
    let sm = Smoothed::of(config, fps, &w_frames, &mut w_x, &mut w_z, &r_x, &r_z);
    let mut yaw: Vec<f64> = Vec::with_capacity(ego.poses.len());
    for p in &ego.poses {
        let next = match yaw.last() {
            // Each step's wrapped turn added on: a heading that passes ±π
            // keeps counting instead of jumping by 2π.
            Some(&prev) => prev + crate::geometry::wrap_angle(p.yaw - prev),
            None => p.yaw,
        };
        yaw.push(next);
    }
    let yaw_sd = second_difference_sd(&yaw);
    let track = TrackState {
        name: EGO.to_string(),
        track_id: u32::MAX,
        class: ObjectClass::Vehicle,
        type_value: None,
        color_value: None,
        obs: Vec::new(),
        frames: Vec::new(),
        cam: Vec::new(),
        footprints: Vec::new(),
        surface: false,
        w_frames,
        raw_x: w_x,
        raw_z: w_z,
        kal_speed: sm.kal_speed,
        kal_speed_sd: sm.kal_speed_sd,
        ca: sm.ca,
        kal_rejected: sm.kal_rejected,
        hampel_replaced: sm.hampel_replaced,
        ego: true,
    };
    (track, yaw, yaw_sd, sd)
}

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

impl<'a> Analysis<'a> {
    /// Validates the inputs, estimates ego-motion and smooths trajectories.
    pub fn new(seq: &'a Sequence, config: &'a FactConfig) -> Result<Analysis<'a>, PerceptionError> {
        seq.validate()?;
        config.validate()?;
        let ego = ego::estimate(seq, &config.ego);
        let mut by_id: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
        for (i, o) in seq.observations.iter().enumerate() {
            by_id.entry(o.track_id).or_default().push(i);
        }
        let mut tracks = Vec::with_capacity(by_id.len());
        for (id, obs) in by_id {
            let Some(&first) = obs.first() else { continue };
            let o0 = &seq.observations[first];
            let type_name = obs
                .iter()
                .find_map(|&i| seq.observations[i].type_name.as_deref());
            let color = obs
                .iter()
                .find_map(|&i| seq.observations[i].color.as_deref());
            let frames: Vec<u32> = obs.iter().map(|&i| seq.observations[i].frame).collect();
            let cam: Vec<Option<CameraBev>> = obs
                .iter()
                .map(|&i| ground_point(&seq.observations[i], &seq.camera))
                .collect();
            let footprints: Vec<Option<Vec<CameraBev>>> = obs
                .iter()
                .map(|&i| seq.observations[i].camera_footprint())
                .collect();
            let surface = footprints.iter().any(Option::is_some);
            let (mut w_frames, mut w_x, mut w_z) = (Vec::new(), Vec::new(), Vec::new());
            // Measurement variances in world X and Z: the measured camera
            // lateral and depth noise, turned by the camera's heading.
            let (mut r_x, mut r_z) = (Vec::new(), Vec::new());
            let floor = config.kalman_min_sigma_m;
            if !surface {
                for (f, c) in frames.iter().zip(&cam) {
                    if let Some((c, w)) = c.and_then(|c| Some((c, ego.to_world(*f, c)?))) {
                        w_frames.push(f64::from(*f));
                        w_x.push(w.x());
                        w_z.push(w.z());
                        let lat = ego.noise.lateral_m.max(floor).powi(2);
                        let dep = ego.noise.depth_sd(c.z().abs()).max(floor).powi(2);
                        let yaw = ego.poses.get(*f as usize).map_or(0.0, |p| p.yaw);
                        let (sn, cs) = yaw.sin_cos();
                        r_x.push(cs * cs * lat + sn * sn * dep);
                        r_z.push(sn * sn * lat + cs * cs * dep);
                    }
                }
            }
            let sm = Smoothed::of(config, seq.fps, &w_frames, &mut w_x, &mut w_z, &r_x, &r_z);
            tracks.push(TrackState {
                name: seq.name_for(type_name, o0.class, id),
                class: o0.class,
                track_id: id,
                type_value: type_name.map(type_value),
                color_value: color.map(|c| vocab_value(c, &COLOR_VALUES)),
                obs,
                frames,
                cam,
                footprints,
                surface,
                w_frames,
                raw_x: w_x,
                raw_z: w_z,
                kal_speed: sm.kal_speed,
                kal_speed_sd: sm.kal_speed_sd,
                ca: sm.ca,
                kal_rejected: sm.kal_rejected,
                hampel_replaced: sm.hampel_replaced,
                ego: false,
            });
        }
        let (ego_track, ego_yaw, ego_yaw_sd, ego_pos_sd) = ego_track(seq.fps, config, &ego);
        let source: std::sync::Arc<str> = seq.source_label().into();
        let around = crate::around::Around::prepare(seq, config, &ego, &tracks, source.clone());
        Ok(Analysis {
            seq,
            config,
            ego,
            tracks,
            source,
            ego_track,
            ego_yaw,
            ego_yaw_sd,
            ego_pos_sd,
            around,
        })
    }

    /// Facts of the window `first..=last` with index `index`.
    pub fn window(&self, index: u32, first: u32, last: u32) -> WindowFacts {
        let mut w = WindowCtx {
            a: self,
            index,
            first,
            last,
            facts: Vec::new(),
            doubts: Vec::new(),
            speeds: Vec::new(),
        };
        let mut present: Vec<(usize, std::ops::Range<usize>)> = Vec::new();
        for (ti, t) in self.tracks.iter().enumerate() {
            let lo = t.frames.partition_point(|f| *f < first);
            let hi = t.frames.partition_point(|f| *f <= last);
            if lo < hi {
                present.push((ti, lo..hi));
            }
        }
        for (ti, r) in &present {
            w.object_facts(&self.tracks[*ti], r.clone());
        }
        w.ego_facts(&present);
        // A surround log relates objects near the ego only
        // (`around.pair_range_m`); a camera's objects are all in view.
        // The names in range, for the 360° relations of `around` too: one
        // rule, decided here once.
        let mut in_range: std::collections::HashSet<&str> = Default::default();
        let paired: Vec<(usize, std::ops::Range<usize>)> = if self.around.is_some() {
            let range = self.config.around.pair_range_m;
            let near = |(ti, r): &&(usize, std::ops::Range<usize>)| {
                self.tracks[*ti].cam[r.clone()]
                    .iter()
                    .flatten()
                    .any(|g| g.0.coords.norm() <= range)
            };
            let paired: Vec<_> = present.iter().filter(near).cloned().collect();
            in_range = paired
                .iter()
                .map(|(ti, _)| self.tracks[*ti].name.as_str())
                .collect();
            w.speeds
                .retain(|(n, _, _)| n == EGO || in_range.contains(n.as_str()));
            paired
        } else {
            present
        };
        w.pair_facts(&paired);
        w.faster_facts();
        if let Some(around) = &self.around {
            w.facts
                .extend(around.window_facts(index, first, last, &in_range));
        }
        let mut out = WindowFacts {
            index,
            first_frame: first,
            last_frame: last,
            facts: w.facts,
            doubts: w.doubts,
        };
        out.normalize();
        out
    }
}

/// Per-frame offsets of one pair, reused across the pairs of a window.
/// Signs: positive when the pair's first object is left of (ahead of) the
/// second.
#[derive(Debug, Default)]
struct RelativeScratch {
    /// `X_y − X_x` (m) per common frame with both ground points.
    lateral: Vec<f64>,
    /// `Z_x − Z_y` (m), same frames as `lateral`.
    forward: Vec<f64>,
    /// Box-centre offset as a fraction of the image width, every common
    /// frame (filled only for the image fallback).
    image: Vec<f64>,
    /// Frame numbers of the common frames with both ground points, for the
    /// distance facts (cleared by `distance_facts` itself).
    times: Vec<f64>,
    /// Gap (m) between the two footprints, same frames as `times`.
    gaps: Vec<f64>,
    /// Variance (m²) of each gap from the measured position noise, same
    /// frames as `times`.
    gap_vars: Vec<f64>,
}

impl RelativeScratch {
    fn clear(&mut self) {
        self.lateral.clear();
        self.forward.clear();
        self.image.clear();
    }
}

/// Frames with ground points voting for each direction of each relation of
/// one pair.
#[derive(Debug, Default)]
struct RelativeVotes {
    x_left: usize,
    y_left: usize,
    x_ahead: usize,
    y_ahead: usize,
    /// `y` is the ego (at the camera): "in front of" by bearing too.
    ego: bool,
}

impl RelativeVotes {
    /// Counts one frame with `x` at ground point `pa` and `y` at `pb`, both
    /// in that frame's camera, and keeps its offsets in `s`.
    fn add(
        &mut self,
        s: &mut RelativeScratch,
        rel: &crate::config::RelativeConfig,
        pa: CameraBev,
        pb: CameraBev,
    ) {
        let beyond = |d: f64, min: f64| d > 0.0 && d >= min;
        // Positive: x is left of y / x is ahead of y.
        let lateral = pb.x() - pa.x();
        let forward = pa.z() - pb.z();
        s.lateral.push(lateral);
        s.forward.push(forward);
        self.x_left += usize::from(beyond(lateral, rel.lateral_min_m));
        self.y_left += usize::from(beyond(-lateral, rel.lateral_min_m));
        // Between two objects, "in front of" is in the other's path (the
        // corridor); relative to the ego (`pb` at the camera) it is ahead
        // as a person looking out says it: within the corridor, or within
        // 45° of straight ahead (the truck overtaking in the next lane is
        // in front of us once it is ahead).
        let corridor =
            lateral.abs() <= rel.corridor_m || (self.ego && lateral.abs() <= forward.abs());
        self.x_ahead += usize::from(corridor && beyond(forward, rel.forward_min_m));
        self.y_ahead += usize::from(corridor && beyond(-forward, rel.forward_min_m));
    }
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

impl WindowCtx<'_, '_> {
    /// Asserts a fact that is certain (read, or not measured with noise).
    fn push(
        &mut self,
        predicate: &str,
        args: &[&str],
        measured: Option<f64>,
        threshold: Option<(&str, f64)>,
        note: String,
    ) {
        self.push_p(predicate, args, measured, threshold, note, 1.0);
    }

    /// Whether the sequence's positions were measured without noise (the
    /// labels of a dataset, a noise-free simulation): then every test is
    /// decided exactly, its facts are certain and nothing is in doubt. A
    /// window's residuals or a frame vote short of unanimous describe the
    /// scene then (a car that accelerates, a pair that crosses), not the
    /// measurement.
    fn exact(&self) -> bool {
        let n = &self.a.ego.noise;
        let cfg = self.a.config;
        n.samples > 0
            && n.lateral_m <= cfg.exact_noise_m
            && n.depth_sd(cfg.near_far_m) <= cfg.exact_noise_m
    }

    /// Asserts a measured fact with the probability its evidence gives.
    fn push_p(
        &mut self,
        predicate: &str,
        args: &[&str],
        measured: Option<f64>,
        threshold: Option<(&str, f64)>,
        note: String,
        probability: f64,
    ) {
        let p = (probability < 1.0 && !self.exact()).then_some(probability);
        let fact = self.fact(predicate, args, measured, threshold, note, p);
        self.facts.push(fact);
    }

    /// Asserts the fact when `asserted`; else keeps it as a doubt when
    /// the probability that it holds all the same reaches
    /// `doubt_min_probability` (an exact sequence has no doubts).
    #[allow(clippy::too_many_arguments)]
    fn decide(
        &mut self,
        asserted: bool,
        predicate: &str,
        args: &[&str],
        measured: Option<f64>,
        threshold: Option<(&str, f64)>,
        note: impl FnOnce(bool) -> String,
        probability: f64,
    ) {
        let min = self.a.config.doubt_min_probability;
        if asserted {
            self.push_p(
                predicate,
                args,
                measured,
                threshold,
                note(true),
                probability,
            );
        } else if !self.exact() && probability > 0.0 && probability >= min {
            let p = Some(probability.min(1.0));
            let fact = self.fact(predicate, args, measured, threshold, note(false), p);
            self.doubts.push(fact);
        }
    }

    fn fact(
        &self,
        predicate: &str,
        args: &[&str],
        measured: Option<f64>,
        threshold: Option<(&str, f64)>,
        note: String,
        probability: Option<f64>,
    ) -> Fact {
        Fact {
            predicate: predicate.to_string(),
            args: args.iter().map(|s| (*s).to_string()).collect(),
            provenance: std::sync::Arc::new(Provenance {
                window: self.index,
                frames: (self.first, self.last),
                source: self.a.source.clone(),
                measured,
                threshold: threshold.map(|(n, v)| (n.to_string(), v)),
                note,
                probability,
            }),
        }
    }

    fn obs(&self, t: &TrackState, k: usize) -> &Observation {
        &self.a.seq.observations[t.obs[k]]
    }

    /// The box centre's share of the image width; `None` for an
    /// observation without a pixel box (a 360° log's cuboid).
    fn x_fraction(&self, o: &Observation) -> Option<f64> {
        o.bbox
            .map(|b| b.center_x() / f64::from(self.a.seq.camera.intrinsics.image_width))
    }

    /// The side of the ego an object is on by its bearing (the angle from
    /// the ego's forward axis, positive to the right): `Front` within
    /// `bearing_front_deg`, `Behind` beyond `bearing_behind_deg`, `Left` or
    /// `Right` between; with the threshold field and value in degrees.
    fn bearing_side(&self, bearing_deg: f64) -> (&'static str, &'static str, f64) {
        let c = &self.a.config.around;
        let b = bearing_deg.abs();
        if b <= c.bearing_front_deg {
            ("Front", "bearing_front_deg", c.bearing_front_deg)
        } else if b >= c.bearing_behind_deg {
            ("Behind", "bearing_behind_deg", c.bearing_behind_deg)
        } else if bearing_deg < 0.0 {
            ("Left", "bearing_front_deg", c.bearing_front_deg)
        } else {
            ("Right", "bearing_front_deg", c.bearing_front_deg)
        }
    }

    /// How far an object is for the `Near*`/`Far*` bands and `Near`: the
    /// camera depth for a boxed sighting (what the thresholds were tuned
    /// on), the ground range for one without a box (it may be beside or
    /// behind the ego, where depth is zero or negative).
    fn band_distance(&self, t: &TrackState, k: usize, g: CameraBev) -> f64 {
        if self.obs(t, k).bbox.is_some() {
            g.z()
        } else {
            g.0.coords.norm()
        }
    }

    /// `InitialLocation` / `LastLocation` of a sighting without a pixel
    /// box, by bearing and ground range (360° logs): `pred(x, Side)` and
    /// `pred(x, NearSide)` or `pred(x, FarSide)`; returns the range.
    fn bearing_location(&mut self, pred: &str, t: &TrackState, k: usize) -> Option<f64> {
        let cfg = self.a.config;
        let g = t.cam[k]?;
        let frame = t.frames[k];
        let bearing = g.x().atan2(g.z()).to_degrees();
        let (side, field, thr) = self.bearing_side(bearing);
        self.push(
            pred,
            &[&t.name, side],
            Some(bearing),
            Some((field, thr)),
            format!("bearing {bearing:.0}° from the ego's heading in frame {frame} (no camera box: 360° placement)"),
        );
        let range = g.0.coords.norm();
        let near = range < cfg.near_far_m;
        let value = format!("{}{side}", if near { "Near" } else { "Far" });
        let cmp = if near { "<" } else { ">=" };
        self.push(
            pred,
            &[&t.name, &value],
            Some(range),
            Some(("near_far_m", cfg.near_far_m)),
            format!(
                "ground range {range:.1} m {cmp} near_far_m {:.1} m in frame {frame}",
                cfg.near_far_m
            ),
        );
        Some(range)
    }

    fn side(&self, frac: f64) -> (&'static str, &'static str, f64) {
        let c = self.a.config;
        if frac < c.left_fraction {
            ("Left", "left_fraction", c.left_fraction)
        } else if frac > c.right_fraction {
            ("Right", "right_fraction", c.right_fraction)
        } else {
            ("Front", "left_fraction", c.left_fraction)
        }
    }

    /// `InitialLocation` / `LastLocation` at sighting `k`, the first or last
    /// of the window's sightings `r`. The box centre and depth of that
    /// sighting are checked against a Theil–Sen line through the
    /// `location_sightings` sightings at that end of the window: one that
    /// lies off the line by more than `location_outlier_fraction` of the
    /// image width (`location_outlier_depth_fraction` of the depth) — a bad
    /// box, a one-frame id switch — is replaced by the line's value there.
    fn location(
        &mut self,
        pred: &str,
        t: &TrackState,
        k: usize,
        r: std::ops::Range<usize>,
    ) -> Option<f64> {
        let cfg = self.a.config;
        let o = self.obs(t, k);
        let Some(observed) = self.x_fraction(o) else {
            return self.bearing_location(pred, t, k);
        };
        let frame = o.frame;
        let at = f64::from(frame);
        let n = (cfg.location_sightings as usize).min(r.len());
        let ends = if k == r.start {
            r.start..r.start + n
        } else {
            r.end - n..r.end
        };
        let times: Vec<f64> = ends.clone().map(|i| f64::from(t.frames[i])).collect();
        let (frac, frac_note) = {
            // Sightings without a box (mixed sources) sit out the line fit.
            let (times, ys): (Vec<f64>, Vec<f64>) = ends
                .clone()
                .zip(&times)
                .filter_map(|(i, at)| Some((*at, self.x_fraction(self.obs(t, i))?)))
                .unzip();
            robust_end(observed, theil_sen_at(&times, &ys, at), |_| {
                cfg.location_outlier_fraction
            })
        };
        let (side, field, thr) = self.side(frac);
        let note = match frac_note {
            None => format!("box centre at {frac:.2} of the image width in frame {frame}"),
            Some(fit) => format!(
                "box centre at {fit:.2} of the image width in frame {frame}: the sighting's {observed:.2} lies more than location_outlier_fraction {:.2} off the Theil–Sen line through the {n} sightings at this end of the window, so the line's value is used",
                cfg.location_outlier_fraction
            ),
        };
        self.push(pred, &[&t.name, side], Some(frac), Some((field, thr)), note);
        if let Some(g) = t.cam[k] {
            let zs: Vec<(f64, f64)> = ends
                .filter_map(|i| t.cam[i].map(|p| (f64::from(t.frames[i]), p.z())))
                .collect();
            let (zt, zy): (Vec<f64>, Vec<f64>) = zs.into_iter().unzip();
            let (z, z_note) = robust_end(g.z(), theil_sen_at(&zt, &zy, at), |fit| {
                cfg.location_outlier_depth_fraction * fit.abs()
            });
            let near = z < cfg.near_far_m;
            let value = format!("{}{side}", if near { "Near" } else { "Far" });
            let cmp = if near { "<" } else { ">=" };
            let note = match z_note {
                None => format!(
                    "depth {z:.1} m {cmp} near_far_m {:.1} m in frame {frame}",
                    cfg.near_far_m
                ),
                Some(fit) => format!(
                    "depth {fit:.1} m {cmp} near_far_m {:.1} m in frame {frame}: the sighting's {:.1} m lies more than location_outlier_depth_fraction {:.2} off the Theil–Sen line through the sightings at this end of the window, so the line's value is used",
                    cfg.near_far_m,
                    g.z(),
                    cfg.location_outlier_depth_fraction
                ),
            };
            self.push(
                pred,
                &[&t.name, &value],
                Some(z),
                Some(("near_far_m", cfg.near_far_m)),
                note,
            );
            return Some(z);
        }
        None
    }

    /// `Near(x, ego)` and `Near(ego, x)`: the object's depth (camera Z, the
    /// measure of the `Near*`/`Far*` locations) falls below `near_far_m`
    /// somewhere in the window. The ends are the depths the locations used
    /// (`z0`, `z1`, robust to a bad first or last sighting), so that
    /// `InitialLocation(x, NearLeft)` or `LastLocation(x, NearFront)`
    /// always comes with `Near(x, ego)`; in between, each sighting's depth
    /// is the median of it and its two neighbours (one bad box does not
    /// bring an object near).
    fn near_fact(
        &mut self,
        t: &TrackState,
        r: std::ops::Range<usize>,
        z0: Option<f64>,
        z1: Option<f64>,
    ) {
        let cfg = self.a.config;
        let mut best: Option<(f64, u32)> = None;
        let mut keep = |z: f64, frame: u32| {
            if best.is_none_or(|(b, _)| z < b) {
                best = Some((z, frame));
            }
        };
        if let Some(z) = z0 {
            keep(z, t.frames[r.start]);
        }
        if let Some(z) = z1 {
            keep(z, t.frames[r.end - 1]);
        }
        for k in r.start + 1..r.end.saturating_sub(1) {
            let Some(here) = t.cam[k] else {
                continue;
            };
            // Median of up to three depths, without allocating (this runs
            // for every sighting of every window).
            let d = |k: usize, g: CameraBev| self.band_distance(t, k, g);
            let z = match (t.cam[k - 1], t.cam[k + 1]) {
                (Some(a), Some(b)) => {
                    let (a, b, c) = (d(k - 1, a), d(k, here), d(k + 1, b));
                    a.max(b).min(a.min(b).max(c))
                }
                (Some(o), None) => 0.5 * (d(k - 1, o) + d(k, here)),
                (None, Some(o)) => 0.5 * (d(k + 1, o) + d(k, here)),
                (None, None) => d(k, here),
            };
            keep(z, t.frames[k]);
        }
        let Some((z, frame)) = best else {
            return;
        };
        if z < cfg.near_far_m {
            let note = format!(
                "depth {z:.1} m < near_far_m {:.1} m in frame {frame} (the depth that separates Near and Far locations)",
                cfg.near_far_m
            );
            let threshold = Some(("near_far_m", cfg.near_far_m));
            self.push("Near", &[&t.name, EGO], Some(z), threshold, note.clone());
            self.push("Near", &[EGO, &t.name], Some(z), threshold, note);
        }
    }

    fn object_facts(&mut self, t: &TrackState, r: std::ops::Range<usize>) {
        let cfg = self.a.config;
        let name = t.name.as_str();
        let class = t.class.predicate();
        // A detector's track is as sure as its detections: their mean
        // score over the window (the detector's own figure, not
        // calibrated); labels and the simulator score 1 and are certain.
        // Not subject to `exact`: it is about what, not where.
        let n = r.len().max(1) as f64;
        let score = r
            .clone()
            .map(|k| f64::from(self.obs(t, k).confidence))
            .sum::<f64>()
            / n;
        let detected = (score < 1.0).then(|| score.clamp(0.0, 1.0));
        let scored = |what: &str| match detected {
            Some(s) => format!(
                "{what} (mean detector score {s:.2} over {} sightings)",
                r.len()
            ),
            None => what.to_string(),
        };
        let fact = self.fact(
            class,
            &[name],
            None,
            None,
            scored(&match self.a.seq.track_keys.get(&t.track_id) {
                // The full source id (an AV2 track_uuid), which the name
                // shortens to 8 characters.
                Some(key) => format!("class of track {} (source track id {key})", t.name),
                None => format!("class of track {}", t.name),
            }),
            detected,
        );
        self.facts.push(fact);
        if let Some(v) = &t.type_value {
            let fact = self.fact(
                "TypeOf",
                &[name, v],
                None,
                None,
                scored("type from the source"),
                detected,
            );
            self.facts.push(fact);
        }
        if let Some(v) = &t.color_value {
            self.push(
                "ColorOf",
                &[name, v],
                None,
                None,
                "colour from the source".into(),
            );
        }
        // Appear / Disappear with look-back / look-ahead beyond the window.
        let k0 = r.start;
        let k1 = r.end - 1;
        let f_in = t.frames[k0];
        let seen_before = k0 > 0 && f_in - t.frames[k0 - 1] <= cfg.appear_lookback_frames;
        if f_in > 0 && !seen_before {
            self.push(
                "Appear",
                &[name],
                Some(f64::from(f_in)),
                Some((
                    "appear_lookback_frames",
                    f64::from(cfg.appear_lookback_frames),
                )),
                format!(
                    "first seen in frame {f_in}, not in the {} frames before",
                    cfg.appear_lookback_frames
                ),
            );
        }
        let f_out = t.frames[k1];
        let seen_after =
            k1 + 1 < t.frames.len() && t.frames[k1 + 1] - f_out <= cfg.disappear_lookahead_frames;
        if f_out + 1 < self.a.seq.frame_count && !seen_after {
            self.push(
                "Disappear",
                &[name],
                Some(f64::from(f_out)),
                Some((
                    "disappear_lookahead_frames",
                    f64::from(cfg.disappear_lookahead_frames),
                )),
                format!(
                    "last seen in frame {f_out}, not in the {} frames after",
                    cfg.disappear_lookahead_frames
                ),
            );
        }
        let z0 = self.location("InitialLocation", t, k0, r.clone());
        let z1 = self.location("LastLocation", t, k1, r.clone());
        if !t.surface && !t.class.is_ground_surface() {
            self.near_fact(t, r.clone(), z0, z1);
        }
        // AtLeft / AtRight / AtCenter from the median box centre.
        let fracs: Vec<f64> = (k0..=k1)
            .filter_map(|k| self.x_fraction(self.obs(t, k)))
            .collect();
        if let Some(m) = crate::signal::median(&fracs) {
            let (side, field, thr) = self.side(m);
            let pred = match side {
                "Left" => "AtLeft",
                "Right" => "AtRight",
                _ => "AtCenter",
            };
            self.push(
                pred,
                &[name],
                Some(m),
                Some((field, thr)),
                format!("median box centre at {m:.2} of the image width"),
            );
        }
        // CloseToCamera from the nearest ground distance.
        let nearest = (k0..=k1)
            .filter_map(|k| t.cam[k])
            .map(|g| g.0.coords.norm())
            .fold(f64::INFINITY, f64::min);
        // A surface reaches under the car whenever it is in view; nearness
        // says nothing about it.
        if nearest < cfg.close_to_camera_m && !t.surface {
            self.push(
                "CloseToCamera",
                &[name],
                Some(nearest),
                Some(("close_to_camera_m", cfg.close_to_camera_m)),
                format!(
                    "nearest ground distance {nearest:.1} m < close_to_camera_m {:.1} m",
                    cfg.close_to_camera_m
                ),
            );
        }
        if !t.class.is_static() && !t.surface {
            self.motion_facts(t);
        }
    }

    fn motion_facts(&mut self, t: &TrackState) {
        match self.a.config.smoother {
            Smoother::Savgol => self.motion_facts_savgol(t),
            Smoother::Kalman => self.motion_facts_kalman(t),
        }
    }

    /// `Moving`, `SpeedUp`, `SpeedDown` from the Kalman-smoothed speeds:
    /// the window's mean smoothed speed must clear the class threshold by
    /// `trend_significance` posterior standard deviations, and the change
    /// of smoothed speed across the window must clear `speed_change_*` by
    /// as many standard deviations of the difference.
    fn motion_facts_kalman(&mut self, t: &TrackState) {
        let cfg = self.a.config;
        let lo = t.w_frames.partition_point(|f| *f < f64::from(self.first));
        let hi = t.w_frames.partition_point(|f| *f <= f64::from(self.last));
        if hi < lo + cfg.min_observations as usize || hi < lo + 2 || t.kal_speed.len() < hi {
            return;
        }
        let k = cfg.trend_significance;
        let sp = &t.kal_speed[lo..hi];
        let sd = &t.kal_speed_sd[lo..hi];
        let n = sp.len() as f64;
        let speed = sp.iter().sum::<f64>() / n;
        let speed_sd = (sd.iter().map(|s| s * s).sum::<f64>() / n).sqrt();
        let smoothing = self.kalman_smoothing(t);
        let by = format!("{k:.1} sd; {smoothing}");
        let what = if t.ego {
            "smoothed world speed of the ego (its estimated camera trajectory)"
        } else {
            "smoothed world speed"
        };
        self.moving(t, what, speed, speed_sd, &by);
        self.speed_change(t, lo, hi);
    }

    /// `Moving` from a mean speed and its standard error: asserted when it
    /// clears the class threshold by `trend_significance` errors, else a
    /// doubt; one test and one probability for both smoothers. `what`
    /// names the speed, `by` how the margin was measured (for provenance).
    fn moving(&mut self, t: &TrackState, what: &str, speed: f64, se: f64, by: &str) {
        self.speeds.push((t.name.clone(), speed, se));
        let k = self.a.config.trend_significance;
        let (field, thr) = self.a.config.moving_threshold(t.class);
        self.decide(
            speed - k * se > thr,
            "Moving",
            &[t.name.as_str()],
            Some(speed),
            Some((field, thr)),
            |yes| {
                let verdict = if yes { ">" } else { "not >" };
                format!("{what} {speed:.2} ± {se:.2} m/s {verdict} {field} {thr:.2} m/s by {by}")
            },
            crate::belief::beyond(speed, thr + k * se, se),
        );
    }

    /// What the Kalman/RTS smoother did to a track, for provenance.
    fn kalman_smoothing(&self, t: &TrackState) -> String {
        let cfg = self.a.config;
        format!(
            "Kalman/RTS smoothed over the track's {} sightings (accel psd {:.1} m²/s³, {}), {} rejected as outliers",
            t.w_frames.len(),
            cfg.kalman_accel_psd,
            self.noise_text(t),
            t.kal_rejected
        )
    }

    /// `SpeedUp`, `SpeedDown` for frames `lo..hi` of the track, from its
    /// RTS-smoothed velocities whichever `smoother` is set: a change of
    /// speed compares the window's first and last velocities, and
    /// Savitzky–Golay derivatives are at their noisiest exactly there, at
    /// the window's edges. The velocities come from the
    /// constant-acceleration smoother where its model holds around the
    /// window ([`Self::ca_change`]), else from the constant-velocity one.
    fn speed_change(&mut self, t: &TrackState, lo: usize, hi: usize) {
        let cfg = self.a.config;
        let fps = self.a.seq.fps;
        if t.kal_speed.len() < hi || hi < lo + 2 {
            return;
        }
        let k = cfg.trend_significance;
        let (_, thr) = cfg.moving_threshold(t.class);
        let name = t.name.as_str();
        let ts = &t.w_frames[lo..hi];
        let span = (ts[ts.len() - 1] - ts[0]) / fps;
        if span <= 0.0 {
            return;
        }
        let Change {
            v0,
            v1,
            peak,
            change,
            sd: change_sd,
            smoothing,
        } = match self.ca_change(t, lo, hi) {
            Some(c) => c,
            None => {
                // Constant velocity: the two ends' speeds, taken as
                // independent (their covariance is not kept).
                let sp = &t.kal_speed[lo..hi];
                let sd = &t.kal_speed_sd[lo..hi];
                let (v0, v1) = (sp[0], sp[sp.len() - 1]);
                Change {
                    v0,
                    v1,
                    peak: sp.iter().copied().fold(0.0, f64::max),
                    change: v1 - v0,
                    sd: (sd[0] * sd[0] + sd[sd.len() - 1] * sd[sd.len() - 1]).sqrt(),
                    smoothing: self.kalman_smoothing(t),
                }
            }
        };
        if peak <= thr {
            return;
        }
        let accel = change / span;
        let margin = k * change_sd;
        // Both conditions must hold; the less certain one bounds the fact.
        let (min, mps2) = (cfg.speed_change_min_mps, cfg.speed_change_mps2);
        let p_up = crate::belief::beyond(change, min + margin, change_sd)
            .min(crate::belief::beyond(accel, mps2, change_sd / span));
        let p_down = crate::belief::beyond(-change, min + margin, change_sd)
            .min(crate::belief::beyond(-accel, mps2, change_sd / span));
        let threshold = Some(("speed_change_mps2", mps2));
        let up = change - margin > min && accel > mps2;
        let down = !up && change + margin < -min && accel < -mps2;
        self.decide(up, "SpeedUp", &[name], Some(accel), threshold, |yes| {
            let verdict = if yes { ">" } else { "does not clear" };
            format!("acceleration {accel:.2} m/s² {verdict} speed_change_mps2 {mps2:.2} (speed change {change:.2} ± {change_sd:.2} m/s, smoothed speed {v0:.1} → {v1:.1} m/s); {smoothing}")
        }, p_up);
        self.decide(down, "SpeedDown", &[name], Some(accel), threshold, |yes| {
            let verdict = if yes { "<" } else { "does not clear" };
            format!("acceleration {accel:.2} m/s² {verdict} -speed_change_mps2 {mps2:.2} (speed change {change:.2} ± {change_sd:.2} m/s, smoothed speed {v0:.1} → {v1:.1} m/s); {smoothing}")
        }, p_down);
    }

    /// The change of speed over frames `lo..hi` from the track's
    /// constant-acceleration RTS smoothing, or `None` where that model does
    /// not hold around the window.
    ///
    /// That smoother pools a sustained acceleration over the whole
    /// manoeuvre, where the constant-velocity one takes it for noise (a
    /// far car pulling away from rest read 0.9 → 1.2 m/s ± 0.85 where it
    /// went 0 → 1.8; docs/history.md). But it spreads an abrupt change
    /// (a crash, a hard stop) over seconds, into windows where the speed
    /// was steady. So it is used only when its forward innovations over
    /// the window and as many sightings either side (about the reach of
    /// its smoothing) pass a χ² test at `kalman_ca_min_p`; an abrupt
    /// change leaves it far behind its sightings and fails the test.
    ///
    /// The change's variance takes the two ends' covariance (delta method
    /// on the speeds): they share most of their data.
    fn ca_change(&self, t: &TrackState, lo: usize, hi: usize) -> Option<Change> {
        let cfg = self.a.config;
        let [cx, cz] = &t.ca;
        let reach = hi - lo;
        let around = lo.saturating_sub(reach)..(hi + reach).min(cx.nis.len());
        let (mut nis, mut dof) = (0.0, 0usize);
        for c in [cx, cz] {
            for v in c.nis.get(around.clone())?.iter().flatten() {
                nis += v;
                dof += 1;
            }
        }
        let p = crate::signal::chi2_tail(nis, dof);
        if p < cfg.kalman_ca_min_p {
            return None;
        }
        let (a, b) = (lo, hi - 1);
        let velocity = |i: usize| Some((cx.velocity(i)?, cz.velocity(i)?));
        let ((x0, z0), (x1, z1)) = (velocity(a)?, velocity(b)?);
        let (v0, v1) = (x0.hypot(z0), x1.hypot(z1));
        // d|v| = (v/|v|)·dv; at rest the direction is the noise's, and
        // either unit vector will do.
        let unit = |x: f64, z: f64, n: f64| if n > 0.0 { (x / n, z / n) } else { (1.0, 0.0) };
        let ((e0x, e0z), (e1x, e1z)) = (unit(x0, z0, v0), unit(x1, z1, v1));
        let (p0x, p1x, cxx) = cx.velocity_cov(a, b)?;
        let (p0z, p1z, czz) = cz.velocity_cov(a, b)?;
        let var = e1x * e1x * p1x + e0x * e0x * p0x - 2.0 * e1x * e0x * cxx
            + e1z * e1z * p1z
            + e0z * e0z * p0z
            - 2.0 * e1z * e0z * czz;
        let peak = (a..=b)
            .filter_map(velocity)
            .map(|(x, z)| x.hypot(z))
            .fold(0.0, f64::max);
        Some(Change {
            v0,
            v1,
            peak,
            change: v1 - v0,
            sd: var.max(0.0).sqrt(),
            smoothing: format!(
                "constant-acceleration Kalman/RTS smoothed over the track's {} sightings (jerk psd {:.1} m²/s⁵; its innovations around the window: χ² {nis:.1} on {dof} degrees of freedom, p {p:.2} ≥ kalman_ca_min_p {:.2}; {}), {} rejected as outliers",
                t.w_frames.len(),
                cfg.kalman_jerk_psd,
                cfg.kalman_ca_min_p,
                self.noise_text(t),
                cx.rejected.max(cz.rejected)
            ),
        })
    }

    /// What the least-squares path did to a track, for provenance.
    fn savgol_smoothing(&self, t: &TrackState) -> String {
        let cfg = self.a.config;
        format!(
            "Hampel (outlier_mad_k {:.1}, savgol_window {}) replaced {} of {} world coordinates, least-squares slope over the window; {}",
            cfg.outlier_mad_k,
            cfg.savgol_window,
            t.hampel_replaced,
            2 * t.w_frames.len(),
            self.noise_text(t)
        )
    }

    /// The position noise a track's smoothing assumed, for provenance: the
    /// sequence's measured sighting noise for an object, the noise of the
    /// estimated camera positions for the ego.
    fn noise_text(&self, t: &TrackState) -> String {
        if t.ego {
            let [x, z] = self.a.ego_pos_sd;
            return format!(
                "the ego's position noise σ {x:.2} m (X), {z:.2} m (Z), measured on its trajectory's second differences and floored at kalman_min_sigma_m {:.2} m",
                self.a.config.kalman_min_sigma_m
            );
        }
        let n = &self.a.ego.noise;
        format!(
            "measured noise σ {:.2} m lateral, {:.1} % depth + {:.2} %/m",
            n.lateral_m,
            100.0 * n.depth_fraction,
            100.0 * n.depth_fraction_per_m
        )
    }

    fn motion_facts_savgol(&mut self, t: &TrackState) {
        let cfg = self.a.config;
        let fps = self.a.seq.fps;
        let lo = t.w_frames.partition_point(|f| *f < f64::from(self.first));
        let hi = t.w_frames.partition_point(|f| *f <= f64::from(self.last));
        if hi < lo + cfg.min_observations as usize || hi < lo + 2 {
            return;
        }
        let ts = &t.w_frames[lo..hi];
        let (Some((vx, ex)), Some((vz, ez))) = (
            slope_with_error(ts, &t.raw_x[lo..hi]),
            slope_with_error(ts, &t.raw_z[lo..hi]),
        ) else {
            return;
        };
        let k = cfg.trend_significance;
        let speed = (vx * vx + vz * vz).sqrt() * fps;
        // Standard error of the speed (delta method on |v|).
        let speed_se = if speed > 0.0 {
            ((vx * ex).powi(2) + (vz * ez).powi(2)).sqrt() / (vx * vx + vz * vz).sqrt() * fps
        } else {
            ex.max(ez) * fps
        };
        let by = format!("trend_significance {k:.1} se; {}", self.savgol_smoothing(t));
        let what = if t.ego {
            "world speed of the ego (its estimated camera trajectory)"
        } else {
            "world speed"
        };
        self.moving(t, what, speed, speed_se, &by);
        self.speed_change(t, lo, hi);
    }

    /// The ego's own facts and its relations to every object of the
    /// window: `Ego(ego)`; `Moving`/`SpeedUp`/`SpeedDown` from its
    /// estimated trajectory by the tests and thresholds of a vehicle;
    /// `TurnLeft`/`TurnRight`; and per object the relative positions and
    /// distance trends to the ego (see [`Self::ego_relations`]). `Near` is
    /// measured with the locations ([`Self::near_fact`]). Never
    /// `DistanceZero*`, `DistanceDecreasesToZero` or `TooClose` with the
    /// ego: its footprint is not known, and the collision rules rest on them.
    fn ego_facts(&mut self, present: &[(usize, std::ops::Range<usize>)]) {
        let a = self.a;
        self.push("Ego", &[EGO], None, None, "the recording vehicle".into());
        self.motion_facts(&a.ego_track);
        self.turn_facts();
        let mut scratch = RelativeScratch::default();
        for (ti, r) in present {
            let t = &a.tracks[*ti];
            if t.surface || t.class.is_ground_surface() {
                continue;
            }
            self.ego_relations(&mut scratch, t, r.clone());
        }
    }

    /// `TurnRight(ego)` / `TurnLeft(ego)`: the ego's heading change from the
    /// window's first to its last frame, in degrees (positive: clockwise
    /// seen from above, towards camera +X, i.e. a right turn), beyond
    /// `turn_min_deg` by `trend_significance` standard deviations of the
    /// change (two headings' noise, measured on the trajectory).
    fn turn_facts(&mut self) {
        let cfg = self.a.config;
        let yaw = &self.a.ego_yaw;
        let (a, b) = (self.first as usize, self.last as usize);
        let (Some(&y0), Some(&y1)) = (yaw.get(a), yaw.get(b)) else {
            return;
        };
        if b <= a {
            return;
        }
        let change = (y1 - y0).to_degrees();
        let sd = (self.a.ego_yaw_sd * std::f64::consts::SQRT_2).to_degrees();
        let (k, thr) = (cfg.trend_significance, cfg.turn_min_deg);
        let margin = k * sd;
        let threshold = Some(("turn_min_deg", thr));
        let (first, last) = (self.first, self.last);
        let note = move |dir: &str, yes: bool| {
            let verdict = if yes { "beyond" } else { "not beyond" };
            format!(
                "the ego's heading turns {change:.1}° (positive: right) from frame {first} to {last}, {verdict} turn_min_deg {thr:.1}° to the {dir} by trend_significance {k:.1} sd of {sd:.2}° (heading noise measured on the estimated camera trajectory)"
            )
        };
        let right = change - margin > thr;
        let left = change + margin < -thr;
        let p_right = crate::belief::beyond(change, thr + margin, sd);
        let p_left = crate::belief::beyond(-change, thr + margin, sd);
        self.decide(
            right,
            "TurnRight",
            &[EGO],
            Some(change),
            threshold,
            |yes| note("right", yes),
            p_right,
        );
        self.decide(
            left,
            "TurnLeft",
            &[EGO],
            Some(change),
            threshold,
            |yes| note("left", yes),
            p_left,
        );
    }

    /// Relations between object `t` (sightings `r`) and the ego, which
    /// stands at the origin of every frame's camera: `LeftOf`/`RightOf`/
    /// `InFrontOf`/`Behind` by the object-pair rule and thresholds
    /// (`FactConfig::relative`) with the ego as the other object, each with
    /// its converse (`InFrontOf(car_3, ego)` with `Behind(ego, car_3)`);
    /// and `SharesFrames`/`DistanceDecrease`/`DistanceIncrease` both ways
    /// from the object's ground distance to the camera, by the significance
    /// test of object pairs. Needs `min_observations` sightings with a
    /// ground point; no image fallback (the ego has no box).
    fn ego_relations(
        &mut self,
        s: &mut RelativeScratch,
        t: &TrackState,
        r: std::ops::Range<usize>,
    ) {
        let cfg = self.a.config;
        let noise = self.a.ego.noise;
        s.clear();
        s.times.clear();
        s.gaps.clear();
        s.gap_vars.clear();
        let mut v = RelativeVotes {
            ego: true,
            ..RelativeVotes::default()
        };
        let origin = CameraBev::new(0.0, 0.0);
        for k in r {
            let Some(p) = t.cam[k] else {
                continue;
            };
            v.add(s, &cfg.relative, p, origin);
            s.times.push(f64::from(t.frames[k]));
            s.gaps.push(p.0.coords.norm());
            s.gap_vars.push(range_noise_var(&noise, p));
        }
        if s.lateral.len() < cfg.min_observations as usize {
            return;
        }
        self.relative_decide(s, &v, &t.name, EGO);
        let RelativeScratch {
            times,
            gaps,
            gap_vars,
            ..
        } = s;
        self.gap_trend(
            (&t.name, EGO),
            times,
            gaps,
            gap_vars,
            "ground distance to the ego",
        );
    }

    /// `Closer(x, y)` or `Closer(y, x)`: over the frames where both have a
    /// ground point, the mean ground distance to the ego (the camera) of
    /// one is smaller than the other's by more than `closer_margin_m` and
    /// by `comparison_significance` standard deviations of the difference
    /// (each sighting's lateral and depth noise projected on its line of
    /// sight, independent sightings). The mean over the shared frames, not
    /// one frame: it is the window's answer, and noise on a single
    /// sighting does not decide it.
    fn closer_facts(
        &mut self,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let cfg = self.a.config;
        let noise = self.a.ego.noise;
        let (mut n, mut sum_x, mut sum_y, mut var_x, mut var_y) = (0usize, 0.0, 0.0, 0.0, 0.0);
        for (a, b) in Self::common(x, rx, y, ry) {
            let (Some(pa), Some(pb)) = (x.cam[a], y.cam[b]) else {
                continue;
            };
            n += 1;
            sum_x += pa.0.coords.norm();
            sum_y += pb.0.coords.norm();
            var_x += range_noise_var(&noise, pa);
            var_y += range_noise_var(&noise, pb);
        }
        if n == 0 {
            return;
        }
        let nf = n as f64;
        let (dx, dy) = (sum_x / nf, sum_y / nf);
        let (sx, sy) = (var_x.sqrt() / nf, var_y.sqrt() / nf);
        let sd = sx.hypot(sy);
        let (k, margin) = (cfg.comparison_significance, cfg.closer_margin_m);
        let threshold = Some(("closer_margin_m", margin));
        for (near, d_near, s_near, far, d_far, s_far) in [
            (&x.name, dx, sx, &y.name, dy, sy),
            (&y.name, dy, sy, &x.name, dx, sx),
        ] {
            let diff = d_far - d_near;
            let note = |yes: bool| {
                let verdict = if yes { ">" } else { "not >" };
                format!(
                    "mean ground distance to the ego over {n} common frames: {near} {d_near:.2} ± {s_near:.2} m, {far} {d_far:.2} ± {s_far:.2} m; {near} is {diff:.2} m nearer, {verdict} closer_margin_m {margin:.2} m by comparison_significance {k:.1} sd of {sd:.2} m"
                )
            };
            self.decide(
                diff - k * sd > margin,
                "Closer",
                &[near, far],
                Some(diff),
                threshold,
                note,
                crate::belief::beyond(diff, margin + k * sd, sd),
            );
        }
    }

    /// `Faster(x, y)` for every ordered pair of the window's movers whose
    /// speed was measured (the ego included): `x`'s window speed (the one
    /// `Moving` tests) exceeds `y`'s by more than `faster_margin_mps` and by
    /// `comparison_significance` standard errors of the difference.
    fn faster_facts(&mut self) {
        let cfg = self.a.config;
        let (k, margin) = (cfg.comparison_significance, cfg.faster_margin_mps);
        let threshold = Some(("faster_margin_mps", margin));
        let speeds = std::mem::take(&mut self.speeds);
        for (i, (xn, vx, sx)) in speeds.iter().enumerate() {
            for (yn, vy, sy) in &speeds[i + 1..] {
                let sd = sx.hypot(*sy);
                for (fast, v_fast, s_fast, slow, v_slow, s_slow) in
                    [(xn, vx, sx, yn, vy, sy), (yn, vy, sy, xn, vx, sx)]
                {
                    let diff = v_fast - v_slow;
                    let note = |yes: bool| {
                        let verdict = if yes { ">" } else { "not >" };
                        format!(
                            "window speed {fast} {v_fast:.2} ± {s_fast:.2} m/s, {slow} {v_slow:.2} ± {s_slow:.2} m/s; {fast} is {diff:.2} m/s faster, {verdict} faster_margin_mps {margin:.2} by comparison_significance {k:.1} se of {sd:.2} m/s"
                        )
                    };
                    self.decide(
                        diff - k * sd > margin,
                        "Faster",
                        &[fast, slow],
                        Some(diff),
                        threshold,
                        note,
                        crate::belief::beyond(diff, margin + k * sd, sd),
                    );
                }
            }
        }
    }

    fn pair_facts(&mut self, present: &[(usize, std::ops::Range<usize>)]) {
        let tracks = &self.a.tracks;
        // One set of buffers for every pair of the window: the pair loop is
        // O(n²), so it must not allocate per pair, let alone per frame.
        let mut scratch = RelativeScratch::default();
        for (i, (ti, ri)) in present.iter().enumerate() {
            let x = &tracks[*ti];
            if x.surface {
                continue;
            }
            for (tj, rj) in present.iter().skip(i + 1) {
                let y = &tracks[*tj];
                if y.surface {
                    continue;
                }
                if x.class.is_static() && y.class.is_static() {
                    continue;
                }
                self.distance_facts(&mut scratch, x, ri.clone(), y, rj.clone());
                if !x.class.is_ground_surface() && !y.class.is_ground_surface() {
                    self.relative_facts(&mut scratch, x, ri.clone(), y, rj.clone());
                    self.closer_facts(x, ri.clone(), y, rj.clone());
                }
            }
        }
        // On(x, y): road users on surfaces, people on vehicles.
        for (ti, ri) in present {
            let x = &tracks[*ti];
            if x.surface || x.class.is_static() {
                continue;
            }
            for (tj, rj) in present {
                if ti == tj {
                    continue;
                }
                let y = &tracks[*tj];
                if y.surface {
                    self.on_surface(x, ri.clone(), y, rj.clone());
                } else if x.class.is_person_like() && y.class == ObjectClass::Vehicle {
                    self.on_vehicle(x, ri.clone(), y, rj.clone());
                }
            }
        }
    }

    /// Frames where both are observed, as pairs of observation indices, in
    /// frame order: a merge of the two sorted frame lists, O(|rx| + |ry|)
    /// and lazy, so the pair loop allocates nothing for it.
    fn common<'t>(
        x: &'t TrackState,
        rx: std::ops::Range<usize>,
        y: &'t TrackState,
        ry: std::ops::Range<usize>,
    ) -> impl Iterator<Item = (usize, usize)> + 't {
        let (mut a, mut b) = (rx.start, ry.start);
        std::iter::from_fn(move || {
            while a < rx.end && b < ry.end {
                match x.frames[a].cmp(&y.frames[b]) {
                    std::cmp::Ordering::Less => a += 1,
                    std::cmp::Ordering::Greater => b += 1,
                    std::cmp::Ordering::Equal => {
                        let both = (a, b);
                        a += 1;
                        b += 1;
                        return Some(both);
                    }
                }
            }
            None
        })
    }

    /// Emits `pred(first, second)` and its converse `conv(second, first)`
    /// from one measurement, so that the converse property holds by
    /// construction (`RightOf(y, x)` iff `LeftOf(x, y)`), both with the
    /// measurement's probability.
    #[allow(clippy::too_many_arguments)]
    fn push_with_converse(
        &mut self,
        (pred, conv): (&str, &str),
        (first, second): (&str, &str),
        measured: f64,
        threshold: (&str, f64),
        note: String,
        converse_note: String,
        probability: f64,
    ) {
        self.push_p(
            pred,
            &[first, second],
            Some(measured),
            Some(threshold),
            note,
            probability,
        );
        self.push_p(
            conv,
            &[second, first],
            Some(measured),
            Some(threshold),
            converse_note,
            probability,
        );
    }

    /// The doubts of a vote that no direction of a relation won: each
    /// direction, and its converse, with the posterior probability that
    /// its fraction of frames exceeds `min_frame_fraction` all the same.
    #[allow(clippy::too_many_arguments)]
    fn vote_doubts(
        &mut self,
        (pred, conv): (&str, &str),
        (x, y): (&str, &str),
        (x_votes, y_votes): (usize, usize),
        frames: usize,
        threshold: (&str, f64),
    ) {
        let f = self.a.config.relative.min_frame_fraction;
        for (first, second, votes) in [(x, y, x_votes), (y, x, y_votes)] {
            let q = crate::belief::majority(votes, frames, f);
            let note = format!(
                "{pred}({first}, {second}) in {votes} of {frames} common frames, not more than relative.min_frame_fraction {f:.2}"
            );
            for (p, args) in [(pred, [first, second]), (conv, [second, first])] {
                self.decide(false, p, &args, None, Some(threshold), |_| note.clone(), q);
            }
        }
    }

    /// `LeftOf`/`RightOf`/`InFrontOf`/`Behind` for one unordered pair.
    ///
    /// Per common frame, in that frame's ego camera coordinates (X right,
    /// Z forward) on the ground points: `x` is left of `y` when
    /// `X_y − X_x >= relative.lateral_min_m`; `x` is in front of `y` when
    /// `Z_x − Z_y >= relative.forward_min_m` and `|X_x − X_y| <=
    /// relative.corridor_m`. A relation holds over the window when more than
    /// `relative.min_frame_fraction` of the frames with both ground points
    /// satisfy it, and there are at least `min_observations` such frames
    /// (the rule of the other pair facts). A pair with fewer such frames
    /// falls back to the box centres for `LeftOf`/`RightOf` only: depth order
    /// cannot be read from a flat image. Offsets must also be strictly
    /// positive, so that a zero threshold cannot make a tie vote both ways.
    fn relative_facts(
        &mut self,
        s: &mut RelativeScratch,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let cfg = self.a.config;
        let rel = &cfg.relative;
        let beyond = |d: f64, min: f64| d > 0.0 && d >= min;
        s.clear();
        let mut v = RelativeVotes::default();
        for (a, b) in Self::common(x, rx.clone(), y, ry.clone()) {
            let (Some(pa), Some(pb)) = (x.cam[a], y.cam[b]) else {
                continue;
            };
            v.add(s, rel, pa, pb);
        }
        let min_frames = cfg.min_observations as usize;
        let wins = |votes: usize, n: usize| votes as f64 > rel.min_frame_fraction * n as f64;
        let belief =
            |votes: usize, n: usize| crate::belief::majority(votes, n, rel.min_frame_fraction);
        let (xn, yn) = (x.name.as_str(), y.name.as_str());
        if s.lateral.len() >= min_frames {
            self.relative_decide(s, &v, xn, yn);
            return;
        }
        // Too few frames with ground points: a second walk over the common
        // frames reads the boxes. Only then, because the observations are
        // scattered in memory and metric sources (KITTI, the simulator)
        // never need it.
        let width = f64::from(self.a.seq.camera.intrinsics.image_width);
        let (mut x_left, mut y_left) = (0usize, 0usize);
        for (a, b) in Self::common(x, rx, y, ry) {
            // Positive: x's box centre is left of y's.
            let (Some(bx), Some(by)) = (&self.obs(x, a).bbox, &self.obs(y, b).bbox) else {
                continue;
            };
            let du = (by.center_x() - bx.center_x()) / width;
            s.image.push(du);
            x_left += usize::from(beyond(du, rel.lateral_min_image_fraction));
            y_left += usize::from(beyond(-du, rel.lateral_min_image_fraction));
        }
        let n = s.image.len();
        if n < min_frames {
            return;
        }
        let side = if wins(x_left, n) {
            Some((xn, yn, x_left, 1.0))
        } else if wins(y_left, n) {
            Some((yn, xn, y_left, -1.0))
        } else {
            None
        };
        if let Some((left, right, k, sign)) = side {
            let m = sign * crate::signal::median_in_place(&mut s.image).unwrap_or(0.0);
            let thr = rel.lateral_min_image_fraction;
            let why = format!(
                "box-centre offset >= relative.lateral_min_image_fraction {thr:.3} of the image width in {k} of {n} common frames (too few frames with ground points: image geometry)"
            );
            self.push_with_converse(
                ("LeftOf", "RightOf"),
                (left, right),
                m,
                ("relative.lateral_min_image_fraction", thr),
                format!("{left}'s box centre is {m:.3} (median) of the image width left of {right}'s: {why}"),
                format!("{right}'s box centre is {m:.3} (median) of the image width right of {left}'s: {why}"),
                belief(k, n),
            );
        } else {
            self.vote_doubts(
                ("LeftOf", "RightOf"),
                (xn, yn),
                (x_left, y_left),
                n,
                (
                    "relative.lateral_min_image_fraction",
                    rel.lateral_min_image_fraction,
                ),
            );
        }
    }

    /// Decides `LeftOf`/`RightOf`/`InFrontOf`/`Behind` for the pair `(xn,
    /// yn)` from the per-frame offsets in `s` (x's lateral offset left of
    /// y, x's forward offset ahead of y) and their votes `v`: the metric
    /// half of [`Self::relative_facts`], shared with the relations to the
    /// ego. The caller has checked that there are `min_observations` frames.
    fn relative_decide(&mut self, s: &mut RelativeScratch, v: &RelativeVotes, xn: &str, yn: &str) {
        let cfg = self.a.config;
        let rel = &cfg.relative;
        let wins = |votes: usize, n: usize| votes as f64 > rel.min_frame_fraction * n as f64;
        let belief =
            |votes: usize, n: usize| crate::belief::majority(votes, n, rel.min_frame_fraction);
        let n = s.lateral.len();
        // Votes first, medians after: sorting for a median breaks the
        // pairing of `lateral` and `forward` frame by frame.
        let lateral_thr = ("relative.lateral_min_m", rel.lateral_min_m);
        let side = if wins(v.x_left, n) {
            Some((xn, yn, v.x_left, 1.0))
        } else if wins(v.y_left, n) {
            Some((yn, xn, v.y_left, -1.0))
        } else {
            None
        };
        let ahead = if wins(v.x_ahead, n) {
            Some((xn, yn, v.x_ahead, 1.0))
        } else if wins(v.y_ahead, n) {
            Some((yn, xn, v.y_ahead, -1.0))
        } else {
            None
        };
        // When no direction won, both are doubts; when one did, its
        // opposite is not (a relation and its opposite cannot both
        // hold), and the winner's own doubt is its probability.
        if side.is_none() {
            self.vote_doubts(
                ("LeftOf", "RightOf"),
                (xn, yn),
                (v.x_left, v.y_left),
                n,
                lateral_thr,
            );
        }
        if ahead.is_none() {
            self.vote_doubts(
                ("InFrontOf", "Behind"),
                (xn, yn),
                (v.x_ahead, v.y_ahead),
                n,
                ("relative.forward_min_m", rel.forward_min_m),
            );
        }
        let lateral_median = if side.is_some() || ahead.is_some() {
            crate::signal::median_in_place(&mut s.lateral).unwrap_or(0.0)
        } else {
            0.0
        };
        if let Some((left, right, k, sign)) = side {
            let m = sign * lateral_median;
            let (thr_name, thr) = lateral_thr;
            let why = format!(
                "lateral offset (camera X) >= {thr_name} {thr:.2} m in {k} of {n} common frames with ground points"
            );
            self.push_with_converse(
                ("LeftOf", "RightOf"),
                (left, right),
                m,
                lateral_thr,
                format!("{left} is {m:.2} m (median) left of {right}: {why}"),
                format!("{right} is {m:.2} m (median) right of {left}: {why}"),
                belief(k, n),
            );
        }
        if let Some((front, back, k, sign)) = ahead {
            let m = sign * crate::signal::median_in_place(&mut s.forward).unwrap_or(0.0);
            let within = if yn == EGO {
                format!(
                    "within relative.corridor_m {:.2} m laterally or 45° of straight ahead",
                    rel.corridor_m
                )
            } else {
                format!(
                    "within relative.corridor_m {:.2} m laterally",
                    rel.corridor_m
                )
            };
            let why = format!(
                "forward offset (camera Z) >= relative.forward_min_m {:.2} m {within} in {k} of {n} common frames with ground points (|median lateral offset| {:.2} m)",
                rel.forward_min_m,
                lateral_median.abs()
            );
            self.push_with_converse(
                ("InFrontOf", "Behind"),
                (front, back),
                m,
                ("relative.forward_min_m", rel.forward_min_m),
                format!("{front} is {m:.2} m (median) ahead of {back}: {why}"),
                format!("{back} is {m:.2} m (median) behind {front}: {why}"),
                belief(k, n),
            );
        }
    }

    fn distance_facts(
        &mut self,
        scratch: &mut RelativeScratch,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let cfg = self.a.config;
        // Buffers shared by every pair of the window: the pair loop is
        // O(n²), so per-pair vectors would allocate n² times.
        let RelativeScratch {
            times: ts,
            gaps,
            gap_vars,
            ..
        } = scratch;
        ts.clear();
        gaps.clear();
        gap_vars.clear();
        let noise = self.a.ego.noise;
        for (a, b) in Self::common(x, rx, y, ry) {
            let (Some(pa), Some(pb)) = (x.cam[a], y.cam[b]) else {
                continue;
            };
            let fa = observation_footprint(pa, self.obs(x, a), DEFAULT_FOOTPRINT_M);
            let fb = observation_footprint(pb, self.obs(y, b), DEFAULT_FOOTPRINT_M);
            ts.push(f64::from(x.frames[a]));
            gaps.push(convex_gap(&fa, &fb));
            gap_vars.push(gap_noise_var(&noise, pa, pb));
        }
        if gaps.is_empty() {
            return;
        }
        let (xn, yn) = (x.name.as_str(), y.name.as_str());
        let both =
            |s: &mut Self, pred: &str, m: Option<f64>, th: Option<(&str, f64)>, note: String| {
                s.push(pred, &[xn, yn], m, th, note.clone());
                s.push(pred, &[yn, xn], m, th, note);
            };
        let (g0, g1) = (gaps[0], gaps[gaps.len() - 1]);
        let min_gap = gaps.iter().copied().fold(f64::INFINITY, f64::min);
        if min_gap < cfg.too_close_distance_m {
            both(
                self,
                "TooClose",
                Some(min_gap),
                Some(("too_close_distance_m", cfg.too_close_distance_m)),
                format!(
                    "smallest gap {min_gap:.2} m < too_close_distance_m {:.2} m",
                    cfg.too_close_distance_m
                ),
            );
        }
        if g0 <= cfg.touch_distance_m {
            both(
                self,
                "DistanceZeroStart",
                Some(g0),
                Some(("touch_distance_m", cfg.touch_distance_m)),
                format!(
                    "gap {g0:.2} m <= touch_distance_m {:.2} m at frame {}",
                    cfg.touch_distance_m, ts[0]
                ),
            );
        }
        if g1 <= cfg.touch_distance_m {
            both(
                self,
                "DistanceZeroEnd",
                Some(g1),
                Some(("touch_distance_m", cfg.touch_distance_m)),
                format!(
                    "gap {g1:.2} m <= touch_distance_m {:.2} m at frame {}",
                    cfg.touch_distance_m,
                    ts[ts.len() - 1]
                ),
            );
        }
        let closer = self.gap_trend((xn, yn), ts, gaps, gap_vars, "gap");
        if closer && g1 <= cfg.touch_distance_m && g0 > cfg.touch_distance_m {
            both(
                self,
                "DistanceDecreasesToZero",
                Some(g1),
                Some(("touch_distance_m", cfg.touch_distance_m)),
                format!(
                    "gap closes from {g0:.1} m to {g1:.2} m <= touch_distance_m {:.2}",
                    cfg.touch_distance_m
                ),
            );
        }
    }

    /// `SharesFrames`, `DistanceDecrease`, `DistanceIncrease` (both ways,
    /// asserted or doubted) for the pair `(xn, yn)` from its distance `gaps`
    /// at frames `ts` with their noise variances `gap_vars`; `noun` names
    /// the distance in the notes. Returns whether `DistanceDecrease` was
    /// asserted. Shared by object pairs (footprint gaps) and the relations
    /// to the ego (ground distance to the camera).
    fn gap_trend(
        &mut self,
        (xn, yn): (&str, &str),
        ts: &[f64],
        gaps: &[f64],
        gap_vars: &[f64],
        noun: &str,
    ) -> bool {
        let cfg = self.a.config;
        let fps = self.a.seq.fps;
        let noise = self.a.ego.noise;
        let both =
            |s: &mut Self, pred: &str, m: Option<f64>, th: Option<(&str, f64)>, note: String| {
                s.push(pred, &[xn, yn], m, th, note.clone());
                s.push(pred, &[yn, xn], m, th, note);
            };
        let both_p = |s: &mut Self,
                      asserted: bool,
                      pred: &str,
                      m: Option<f64>,
                      th: Option<(&str, f64)>,
                      note: String,
                      p: f64| {
            s.decide(asserted, pred, &[xn, yn], m, th, |_| note.clone(), p);
            s.decide(asserted, pred, &[yn, xn], m, th, |_| note.clone(), p);
        };
        let (Some(&g0), Some(&g1)) = (gaps.first(), gaps.last()) else {
            return false;
        };
        if gaps.len() < cfg.min_observations as usize {
            return false;
        }
        let Some((slope, resid_se)) = slope_with_error(ts, gaps) else {
            return false;
        };
        let noise_se = slope_noise_var(ts, gap_vars).map_or(0.0, f64::sqrt);
        // The pair's gap trend was measured: rules such as ConstantDistance
        // need a positive atom that binds both objects before they may say
        // "neither closer nor farther" under negation.
        both(
            self,
            "SharesFrames",
            Some(gaps.len() as f64),
            Some(("min_observations", f64::from(cfg.min_observations))),
            format!(
                "{noun} measured in {} common frames >= min_observations {}",
                gaps.len(),
                cfg.min_observations
            ),
        );
        let rate = slope * fps;
        let rate_se = resid_se.max(noise_se) * fps;
        let k = cfg.distance_significance;
        let margin = k * rate_se;
        let change = slope * (ts[ts.len() - 1] - ts[0]);
        let test = format!(
            "by distance_significance {k:.1} se of {rate_se:.2} m/s (the larger of the residuals' {:.2} and the measured noise's {:.2}: σ {:.2} m lateral, {:.1} % depth + {:.2} %/m)",
            resid_se * fps,
            noise_se * fps,
            noise.lateral_m,
            100.0 * noise.depth_fraction,
            100.0 * noise.depth_fraction_per_m
        );
        // Both conditions must hold; the less certain bounds the fact. The
        // fitted change's standard error is the slope's over the span.
        let (dr, dmin) = (cfg.distance_rate_mps, cfg.distance_change_min_m);
        let change_se = rate_se / fps * (ts[ts.len() - 1] - ts[0]);
        let p_closer = crate::belief::beyond(-rate, dr + margin, rate_se)
            .min(crate::belief::beyond(-change, dmin, change_se));
        let p_farther = crate::belief::beyond(rate, dr + margin, rate_se)
            .min(crate::belief::beyond(change, dmin, change_se));
        let closer = rate + margin < -dr && change < -dmin;
        let farther = !closer && rate - margin > dr && change > dmin;
        let rate_thr = Some(("distance_rate_mps", dr));
        if !closer {
            both_p(
                self,
                false,
                "DistanceDecrease",
                Some(rate),
                rate_thr,
                format!(
                    "{noun} changes at {rate:.2} ± {rate_se:.2} m/s ({g0:.1} → {g1:.1} m), not shrinking faster than distance_rate_mps {dr:.2} {test}"
                ),
                p_closer,
            );
        }
        if !farther {
            both_p(
                self,
                false,
                "DistanceIncrease",
                Some(rate),
                rate_thr,
                format!(
                    "{noun} changes at {rate:.2} ± {rate_se:.2} m/s ({g0:.1} → {g1:.1} m), not growing faster than distance_rate_mps {dr:.2} {test}"
                ),
                p_farther,
            );
        }
        if closer {
            both_p(
                self,
                true,
                "DistanceDecrease",
                Some(rate),
                rate_thr,
                format!(
                    "{noun} shrinks at {:.2} ± {rate_se:.2} m/s ({g0:.1} → {g1:.1} m), faster than distance_rate_mps {:.2} {test}",
                    -rate, cfg.distance_rate_mps
                ),
                p_closer,
            );
        } else if farther {
            both_p(
                self,
                true,
                "DistanceIncrease",
                Some(rate),
                rate_thr,
                format!(
                    "{noun} grows at {rate:.2} ± {rate_se:.2} m/s ({g0:.1} → {g1:.1} m), faster than distance_rate_mps {:.2} {test}",
                    cfg.distance_rate_mps
                ),
                p_farther,
            );
        }
        closer
    }

    fn on_surface(
        &mut self,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let frames = rx.len();
        let on = Self::common(x, rx, y, ry)
            .filter(|&(a, b)| match (x.cam[a], y.footprints[b].as_deref()) {
                (Some(p), Some(poly)) => point_in_polygon(p, poly),
                _ => false,
            })
            .count();
        self.on_fact(x, y, on, frames, "ground point inside the surface");
    }

    fn on_vehicle(
        &mut self,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let frames = rx.len();
        let on = Self::common(x, rx, y, ry)
            .filter(|&(a, b)| match (x.cam[a], y.cam[b]) {
                (Some(pa), Some(pb)) => {
                    let fa = observation_footprint(pa, self.obs(x, a), DEFAULT_FOOTPRINT_M);
                    let fb = observation_footprint(pb, self.obs(y, b), DEFAULT_FOOTPRINT_M);
                    covered_fraction(&fa, &fb) >= 0.5
                }
                _ => false,
            })
            .count();
        self.on_fact(x, y, on, frames, "footprint mostly over the vehicle's");
    }

    fn on_fact(&mut self, x: &TrackState, y: &TrackState, on: usize, frames: usize, what: &str) {
        if on == 0 || frames == 0 {
            return;
        }
        let cfg = self.a.config;
        let frac = on as f64 / frames as f64;
        // `On` holds when the fraction reaches on_min_fraction; its belief
        // is the posterior that the true fraction of frames does.
        self.decide(
            frac >= cfg.on_min_fraction,
            "On",
            &[&x.name, &y.name],
            Some(frac),
            Some(("on_min_fraction", cfg.on_min_fraction)),
            |_| format!("{what} in {on} of {frames} frames"),
            crate::belief::majority(on, frames, cfg.on_min_fraction),
        );
    }
}

/// The value of a first/last sighting, or the robust line's `fit` at its
/// frame when the sighting lies farther than `tolerance(fit)` off it; the
/// second item is `Some(fit)` when the fit replaced the sighting.
fn robust_end(
    observed: f64,
    fit: Option<f64>,
    tolerance: impl Fn(f64) -> f64,
) -> (f64, Option<f64>) {
    match fit {
        Some(f) if f.is_finite() && (observed - f).abs() > tolerance(f) => (f, Some(f)),
        _ => (observed, None),
    }
}

/// Variance (m²) of a sighting's ground distance to the camera at camera
/// ground point `p`: its lateral (camera X) and depth (camera Z) noise
/// projected on its line of sight.
fn range_noise_var(noise: &ego::MeasuredNoise, p: CameraBev) -> f64 {
    let len = p.0.coords.norm();
    let (ux, uz) = if len > f64::EPSILON {
        (p.x() / len, p.z() / len)
    } else {
        (0.0, 1.0)
    };
    let sz = noise.depth_sd(p.z().max(0.0));
    noise.lateral_m * noise.lateral_m * ux * ux + sz * sz * uz * uz
}

/// Variance (m²) of the gap between two sightings at camera ground points
/// `a` and `b` from the measured noise: each sighting's lateral (camera X)
/// and depth (camera Z) noise projected on the line between them, the two
/// sightings independent.
fn gap_noise_var(noise: &ego::MeasuredNoise, a: CameraBev, b: CameraBev) -> f64 {
    let (dx, dz) = (b.x() - a.x(), b.z() - a.z());
    let len = (dx * dx + dz * dz).sqrt();
    let (ux, uz) = if len > f64::EPSILON {
        (dx / len, dz / len)
    } else {
        (
            std::f64::consts::FRAC_1_SQRT_2,
            std::f64::consts::FRAC_1_SQRT_2,
        )
    };
    let one = |p: CameraBev| {
        let sz = noise.depth_sd(p.z().max(0.0));
        noise.lateral_m * noise.lateral_m * ux * ux + sz * sz * uz * uz
    };
    one(a) + one(b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::RelativeConfig;
    use crate::model::{BBox2D, CameraConfig, CameraIntrinsics, Sequence};

    const CAMERA: CameraConfig = CameraConfig {
        intrinsics: CameraIntrinsics {
            fx: 700.0,
            fy: 700.0,
            cx: 600.0,
            cy: 180.0,
            image_width: 1200,
            image_height: 370,
        },
        height_m: 1.65,
    };

    /// An object standing at ground point `(x, z)` of the camera frame, its
    /// box projected through [`CAMERA`] (so that image and metric agree).
    fn at(frame: u32, id: u32, class: ObjectClass, x: f64, z: f64) -> Observation {
        let k = CAMERA.intrinsics;
        let u = k.fx * x / z + k.cx;
        let bottom = k.fy * CAMERA.height_m / z + k.cy;
        let half = 0.4 * k.fx / z;
        Observation {
            frame,
            track_id: id,
            class,
            type_name: None,
            color: None,
            bbox: Some(BBox2D {
                left: u - half,
                top: bottom - 4.0 * half,
                right: u + half,
                bottom,
            }),
            position: Some([x, CAMERA.height_m, z]),
            size: None,
            yaw: None,
            confidence: 1.0,
            truncation: None,
            occlusion: None,
            footprint: None,
            depth_source: None,
        }
    }

    /// Ten frames of track 1 (a vehicle) and track 2 (a pedestrian) at the
    /// ground points `car(f)` and `ped(f)`.
    fn pair(car: impl Fn(u32) -> (f64, f64), ped: impl Fn(u32) -> (f64, f64)) -> Sequence {
        let mut observations = Vec::new();
        for f in 0..10 {
            let (cx, cz) = car(f);
            let (px, pz) = ped(f);
            observations.push(at(f, 1, ObjectClass::Vehicle, cx, cz));
            observations.push(at(f, 2, ObjectClass::Pedestrian, px, pz));
        }
        Sequence {
            name: "t".into(),
            source: "test".into(),
            camera: CAMERA,
            frame_count: 10,
            fps: 10.0,
            observations,
            timestamps_ns: None,
            ego_poses: None,
            map: None,
            track_keys: Default::default(),
            skipped: Vec::new(),
        }
    }

    fn relative(seq: &Sequence, config: &FactConfig) -> Vec<Fact> {
        range_facts(seq, 0, 9, config)
            .unwrap()
            .facts
            .into_iter()
            .filter(|f| ["LeftOf", "RightOf", "InFrontOf", "Behind"].contains(&&*f.predicate))
            // The relations to the ego are tested on their own.
            .filter(|f| !f.args.iter().any(|a| a == EGO))
            .collect()
    }

    fn keys(facts: &[Fact]) -> Vec<String> {
        facts.iter().map(Fact::to_kb_line).collect()
    }

    fn find<'f>(facts: &'f [Fact], line: &str) -> &'f Fact {
        facts
            .iter()
            .find(|f| f.to_kb_line() == line)
            .unwrap_or_else(|| panic!("no {line} in {:?}", keys(facts)))
    }

    #[test]
    fn a_car_clearly_left_of_a_pedestrian_is_left_of_it_and_the_pedestrian_right_of_it() {
        let seq = pair(|_| (-4.0, 15.0), |_| (2.0, 15.0));
        let facts = relative(&seq, &FactConfig::default());
        assert_eq!(
            keys(&facts),
            [
                "LeftOf(vehicle_1, pedestrian_2)",
                "RightOf(pedestrian_2, vehicle_1)"
            ]
        );
        for line in [
            "LeftOf(vehicle_1, pedestrian_2)",
            "RightOf(pedestrian_2, vehicle_1)",
        ] {
            let p = &find(&facts, line).provenance;
            assert_eq!((p.window, p.frames), (0, (0, 9)));
            assert!((p.measured.unwrap() - 6.0).abs() < 1e-9, "{p:?}");
            assert_eq!(p.threshold, Some(("relative.lateral_min_m".into(), 1.0)));
            assert!(p.note.contains("10 of 10 common frames"), "{}", p.note);
            assert!(p.note.contains("6.00 m (median)"), "{}", p.note);
        }
        let lines = keys(&facts);
        assert!(!lines.contains(&"RightOf(vehicle_1, pedestrian_2)".to_string()));
        assert!(!lines.contains(&"LeftOf(pedestrian_2, vehicle_1)".to_string()));
        assert!(
            find(&facts, "RightOf(pedestrian_2, vehicle_1)")
                .provenance
                .note
                .starts_with("pedestrian_2 is 6.00 m (median) right of vehicle_1")
        );
    }

    #[test]
    fn ahead_in_the_same_corridor_is_in_front_and_the_other_behind() {
        let seq = pair(|f| (0.5, 25.0 + 0.2 * f64::from(f)), |_| (0.0, 10.0));
        let facts = relative(&seq, &FactConfig::default());
        assert_eq!(
            keys(&facts),
            [
                "Behind(pedestrian_2, vehicle_1)",
                "InFrontOf(vehicle_1, pedestrian_2)"
            ]
        );
        let p = &find(&facts, "InFrontOf(vehicle_1, pedestrian_2)").provenance;
        // Median of 15.0, 15.2, …, 16.8.
        assert!((p.measured.unwrap() - 15.9).abs() < 1e-9, "{p:?}");
        assert_eq!(p.threshold, Some(("relative.forward_min_m".into(), 2.0)));
        assert!(p.note.contains("relative.corridor_m 3.00 m"), "{}", p.note);
        assert_eq!(
            find(&facts, "Behind(pedestrian_2, vehicle_1)")
                .provenance
                .measured,
            p.measured
        );
    }

    #[test]
    fn ahead_but_ten_metres_to_the_side_is_not_in_front() {
        let seq = pair(|_| (10.0, 25.0), |_| (0.0, 10.0));
        let facts = relative(&seq, &FactConfig::default());
        // Only the lateral relation: the car is out of the pedestrian's path.
        assert_eq!(
            keys(&facts),
            [
                "LeftOf(pedestrian_2, vehicle_1)",
                "RightOf(vehicle_1, pedestrian_2)"
            ]
        );
        // A corridor wide enough takes it in.
        let wide = FactConfig {
            relative: RelativeConfig {
                corridor_m: 12.0,
                ..Default::default()
            },
            ..FactConfig::default()
        };
        assert!(
            keys(&relative(&seq, &wide))
                .contains(&"InFrontOf(vehicle_1, pedestrian_2)".to_string())
        );
    }

    #[test]
    fn offsets_below_the_thresholds_give_nothing() {
        let seq = pair(|_| (-0.9, 11.9), |_| (0.0, 10.0));
        assert!(relative(&seq, &FactConfig::default()).is_empty());
        // The thresholds are the configured ones, not constants.
        let tight = FactConfig {
            relative: RelativeConfig {
                lateral_min_m: 0.5,
                forward_min_m: 1.5,
                ..Default::default()
            },
            ..FactConfig::default()
        };
        assert_eq!(
            keys(&relative(&seq, &tight)),
            [
                "Behind(pedestrian_2, vehicle_1)",
                "InFrontOf(vehicle_1, pedestrian_2)",
                "LeftOf(vehicle_1, pedestrian_2)",
                "RightOf(pedestrian_2, vehicle_1)"
            ]
        );
        let seq = pair(|_| (-6.0, 15.0), |_| (0.0, 15.0));
        let far = FactConfig {
            relative: RelativeConfig {
                lateral_min_m: 7.0,
                ..Default::default()
            },
            ..FactConfig::default()
        };
        assert!(relative(&seq, &far).is_empty());
    }

    #[test]
    fn a_zero_threshold_never_orders_objects_both_ways() {
        let seq = pair(|_| (0.0, 15.0), |_| (0.0, 15.0));
        let zero = FactConfig {
            relative: RelativeConfig {
                lateral_min_m: 0.0,
                forward_min_m: 0.0,
                lateral_min_image_fraction: 0.0,
                ..Default::default()
            },
            ..FactConfig::default()
        };
        assert!(relative(&seq, &zero).is_empty());
    }

    #[test]
    fn a_relation_needs_a_strict_majority_of_the_common_frames() {
        // Left in frames 0-4, right in 5-9: half each, so neither.
        let seq = pair(|f| (if f < 5 { -4.0 } else { 4.0 }, 15.0), |_| (0.0, 15.0));
        assert!(relative(&seq, &FactConfig::default()).is_empty());
        // Left in 6 of 10.
        let seq = pair(|f| (if f < 6 { -4.0 } else { 4.0 }, 15.0), |_| (0.0, 15.0));
        let facts = relative(&seq, &FactConfig::default());
        assert_eq!(
            keys(&facts),
            [
                "LeftOf(vehicle_1, pedestrian_2)",
                "RightOf(pedestrian_2, vehicle_1)"
            ]
        );
        assert!(facts[0].provenance.note.contains("6 of 10 common frames"));
    }

    #[test]
    fn fewer_common_frames_than_min_observations_give_nothing() {
        let mut seq = pair(|_| (-4.0, 15.0), |_| (2.0, 15.0));
        // The pedestrian is seen in frames 0-1 only; the car throughout.
        seq.observations.retain(|o| o.track_id == 1 || o.frame < 2);
        assert!(relative(&seq, &FactConfig::default()).is_empty());
        seq = pair(|_| (-4.0, 15.0), |_| (2.0, 15.0));
        seq.observations.retain(|o| o.track_id == 1 || o.frame < 3);
        let facts = relative(&seq, &FactConfig::default());
        assert!(
            facts[0].provenance.note.contains("3 of 3 common frames"),
            "{:?}",
            facts[0]
        );
    }

    #[test]
    fn without_ground_points_only_left_and_right_come_from_the_image() {
        let mut seq = pair(|_| (-4.0, 15.0), |_| (2.0, 30.0));
        for o in &mut seq.observations {
            // No 3D position, and a box bottom above the horizon, so no
            // flat-ground point either.
            o.position = None;
            if let Some(b) = o.bbox.as_mut() {
                b.top = 100.0;
                b.bottom = 150.0;
            }
        }
        let facts = relative(&seq, &FactConfig::default());
        assert_eq!(
            keys(&facts),
            [
                "LeftOf(vehicle_1, pedestrian_2)",
                "RightOf(pedestrian_2, vehicle_1)"
            ]
        );
        let p = &facts[0].provenance;
        let expected = (700.0 * 2.0 / 30.0 - 700.0 * -4.0 / 15.0) / 1200.0;
        assert!((p.measured.unwrap() - expected).abs() < 1e-9, "{p:?}");
        assert_eq!(
            p.threshold,
            Some(("relative.lateral_min_image_fraction".into(), 0.05))
        );
        assert!(p.note.contains("image geometry"), "{}", p.note);
    }

    #[test]
    fn boxes_without_positions_use_their_flat_ground_points() {
        let mut seq = pair(|_| (0.0, 25.0), |_| (0.5, 10.0));
        for o in &mut seq.observations {
            o.position = None;
        }
        let facts = relative(&seq, &FactConfig::default());
        assert_eq!(
            keys(&facts),
            [
                "Behind(pedestrian_2, vehicle_1)",
                "InFrontOf(vehicle_1, pedestrian_2)"
            ]
        );
        assert!((facts[1].provenance.measured.unwrap() - 15.0).abs() < 1e-6);
    }

    /// Regression (issue 22): under high noise the parked red car of
    /// urban_crossing was `Moving` in most windows ("Is the red car
    /// stopped?" said yes in 2–5 of 8 windows), because noisy ego-motion
    /// drifted. With the noise-adaptive ego fit it is still in every window
    /// of most seeds, and the noise-free run is exactly right.
    #[test]
    fn a_detected_track_is_as_sure_as_its_detections_mean_score() {
        let mut seq = pair(|_| (-3.0, 20.0), |_| (3.0, 20.0));
        for o in seq.observations.iter_mut().filter(|o| o.track_id == 2) {
            o.confidence = if o.frame % 2 == 0 { 0.5 } else { 0.7 };
        }
        let facts = range_facts(&seq, 0, 9, &FactConfig::default())
            .unwrap()
            .facts;
        let class_of = |name: &str| {
            facts
                .iter()
                .find(|f| {
                    f.args.len() == 1
                        && f.args[0] == name
                        && ["Vehicles", "Pedestrian"].contains(&f.predicate.as_str())
                })
                .unwrap_or_else(|| panic!("no class fact for {name}"))
        };
        let ped = class_of("pedestrian_2");
        assert!((ped.provenance.belief() - 0.6).abs() < 1e-6, "{ped:?}");
        assert!(
            ped.provenance
                .note
                .contains("mean detector score 0.60 over 10 sightings"),
            "{ped:?}"
        );
        // Ground truth scores 1: certain, and said the way it always was.
        let car = class_of("vehicle_1");
        assert_eq!(car.provenance.probability, None);
        assert_eq!(car.provenance.note, "class of track vehicle_1");
    }

    #[test]
    fn noise_free_facts_are_certain_and_noisy_ones_say_how_sure_they_are() {
        use crate::sim::{NoisePreset, Scenario, simulate};
        let config = FactConfig::default();
        let mut scenario = Scenario::builtin("urban_crossing").unwrap();
        let windows = |scenario: &Scenario| {
            let run = simulate(scenario, 1).unwrap();
            window_facts(&run.sequence, WindowSpec::PAPER, &config).unwrap()
        };
        for w in windows(&scenario) {
            assert!(w.doubts.is_empty(), "a noise-free doubt: {:?}", w.doubts);
            assert!(w.facts.iter().all(|f| f.provenance.probability.is_none()));
        }
        scenario.noise = NoisePreset::High.spec();
        let noisy = windows(&scenario);
        let measured: Vec<f64> = noisy
            .iter()
            .flat_map(|w| &w.facts)
            .filter(|f| {
                ["Moving", "DistanceDecrease", "DistanceIncrease"].contains(&f.predicate.as_str())
            })
            .filter_map(|f| f.provenance.probability)
            .collect();
        assert!(!measured.is_empty(), "no measured fact has a probability");
        // Centred on the test: an asserted estimate is at least even odds.
        assert!(
            measured.iter().all(|p| (0.5..1.0).contains(p)),
            "{measured:?}"
        );
        let doubts: Vec<&Fact> = noisy.iter().flat_map(|w| &w.doubts).collect();
        assert!(!doubts.is_empty(), "high noise leaves nothing in doubt");
        for d in &doubts {
            let q = d.provenance.belief();
            assert!(q >= config.doubt_min_probability && q < 1.0, "{d:?}");
        }
        // A doubt is never also a fact of its window.
        for w in &noisy {
            for d in &w.doubts {
                assert!(!w.facts.iter().any(|f| f.key() == d.key()), "{d:?}");
            }
        }
    }

    #[test]
    fn the_parked_red_car_is_not_moving_under_high_noise() {
        use crate::sim::{NoisePreset, Scenario, simulate};
        let config = FactConfig::default();
        let mut scenario = Scenario::builtin("urban_crossing").unwrap();
        let red_car_moving = |scenario: &Scenario, seed: u64| {
            let run = simulate(scenario, seed).unwrap();
            let windows = window_facts(&run.sequence, WindowSpec::PAPER, &config).unwrap();
            let red: Vec<String> = windows
                .iter()
                .flat_map(|w| &w.facts)
                .filter(|f| f.predicate == "ColorOf" && f.args[1] == "Red")
                .map(|f| f.args[0].clone())
                .collect();
            assert!(!red.is_empty(), "no red car seen at seed {seed}");
            let moving = windows
                .iter()
                .filter(|w| {
                    w.facts
                        .iter()
                        .any(|f| f.predicate == "Moving" && red.contains(&f.args[0]))
                })
                .count();
            (moving, windows.len())
        };
        assert_eq!(red_car_moving(&scenario, 0).0, 0, "noise-free");
        scenario.noise = NoisePreset::High.spec();
        let (mut moving, mut total) = (0, 0);
        for seed in 0..4 {
            let (m, n) = red_car_moving(&scenario, seed);
            moving += m;
            total += n;
        }
        // Before the fix: about half the windows (16 of 32); now at most one.
        assert!(moving <= 1, "red car Moving in {moving} of {total} windows");
    }

    /// The windows' `SpeedUp`/`SpeedDown` facts of a car of `colour` in
    /// frames `first..=last` of a built-in scenario at a noise level, for
    /// seeds `0..seeds`: one list per seed.
    fn speed_facts(
        name: &str,
        noise: crate::sim::NoisePreset,
        colour: &str,
        first: u32,
        seeds: u64,
    ) -> Vec<Vec<String>> {
        use crate::sim::{Scenario, simulate};
        let config = FactConfig::default();
        let mut scenario = Scenario::builtin(name).unwrap();
        scenario.noise = noise.spec();
        (0..seeds)
            .map(|seed| {
                let run = simulate(&scenario, seed).unwrap();
                let windows = window_facts(&run.sequence, WindowSpec::PAPER, &config).unwrap();
                let w = windows.iter().find(|w| w.first_frame == first).unwrap();
                let car: Vec<&String> = w
                    .facts
                    .iter()
                    .filter(|f| f.predicate == "ColorOf" && f.args[1] == colour)
                    .map(|f| &f.args[0])
                    .collect();
                w.facts
                    .iter()
                    .filter(|f| {
                        matches!(f.predicate.as_str(), "SpeedUp" | "SpeedDown")
                            && car.contains(&&f.args[0])
                    })
                    .map(|f| f.predicate.clone())
                    .collect()
            })
            .collect()
    }

    #[test]
    fn a_far_car_pulling_away_from_rest_is_speeding_up_at_the_default_noise() {
        // Braking's white car accelerates at 2 m/s² from rest 42–31 m ahead
        // over frames 10–19 (0 → 1.8 m/s). Before the constant-acceleration
        // smoother: missed in 3 of 10 seeds.
        let got = speed_facts("braking", crate::sim::NoisePreset::Default, "White", 10, 10);
        for (seed, facts) in got.iter().enumerate() {
            assert_eq!(facts, &["SpeedUp"], "seed {seed}: {got:?}");
        }
    }

    #[test]
    fn a_crash_after_the_window_is_not_smoothed_into_it() {
        // Collision's orange car runs at a steady 8 m/s through frames
        // 20–29 and, in some seeds, crashes to a stop a few frames later. A
        // constant-acceleration smoother without its χ² check spread the
        // stop back into the window (SpeedDown, or SpeedUp from ringing).
        for noise in [
            crate::sim::NoisePreset::Low,
            crate::sim::NoisePreset::Default,
        ] {
            let got = speed_facts("collision", noise, "Orange", 20, 10);
            assert!(got.iter().all(Vec::is_empty), "{noise:?}: {got:?}");
        }
    }

    #[test]
    fn motion_provenance_says_how_the_track_was_smoothed() {
        let seq = pair(|f| (-4.0, 10.0 + 1.0 * f64::from(f)), |_| (2.0, 15.0));
        let facts = range_facts(&seq, 0, 9, &FactConfig::default())
            .unwrap()
            .facts;
        let m = find(&facts, "Moving(vehicle_1)");
        assert!(
            m.provenance.note.contains("Hampel"),
            "{}",
            m.provenance.note
        );
        assert!(
            m.provenance.note.contains("measured noise"),
            "{}",
            m.provenance.note
        );
        let kalman = FactConfig {
            smoother: Smoother::Kalman,
            ..FactConfig::default()
        };
        let facts = range_facts(&seq, 0, 9, &kalman).unwrap().facts;
        let m = find(&facts, "Moving(vehicle_1)");
        assert!(
            m.provenance.note.contains("Kalman/RTS"),
            "{}",
            m.provenance.note
        );
        assert!((m.provenance.measured.unwrap() - 10.0).abs() < 0.5, "{m:?}");
        // The pedestrian stands still under either smoother.
        assert!(!keys(&facts).contains(&"Moving(pedestrian_2)".to_string()));
    }

    /// A car 10 m ahead and a pedestrian about 50 m ahead whose depth
    /// jitters by ±`jitter` m frame to frame (a far monocular depth) and
    /// drifts by `drift` m a frame.
    fn far_jittery_pair(jitter: f64, drift: f64) -> Sequence {
        // Fixed signs, so that the measured noise and the slope are the
        // same on every run.
        const SIGNS: [f64; 10] = [1.0, -1.0, 1.0, 1.0, -1.0, -1.0, 1.0, -1.0, 1.0, -1.0];
        pair(
            |_| (0.0, 10.0),
            |f| {
                (
                    0.0,
                    50.0 + drift * f64::from(f) + jitter * SIGNS[f as usize],
                )
            },
        )
    }

    fn distance_trends(seq: &Sequence, config: &FactConfig) -> Vec<Fact> {
        range_facts(seq, 0, 9, config)
            .unwrap()
            .facts
            .into_iter()
            .filter(|f| {
                f.predicate.starts_with("DistanceIncrease")
                    || f.predicate.starts_with("DistanceDecrease")
            })
            .collect()
    }

    /// Issue 22 item 1: a distance trend is tested against the measured
    /// noise, as `Moving` is. The plain slope of a far pedestrian's jittery
    /// depth says "distance decreases"; the test does not.
    #[test]
    fn distance_trends_must_clear_the_measured_noise() {
        let seq = far_jittery_pair(1.0, 0.0);
        let plain = FactConfig {
            distance_significance: 0.0,
            ..FactConfig::default()
        };
        assert!(
            keys(&distance_trends(&seq, &plain))
                .contains(&"DistanceDecrease(vehicle_1, pedestrian_2)".to_string()),
            "the plain slope should read a trend: {:?}",
            keys(&distance_trends(&seq, &plain))
        );
        let tested = distance_trends(&seq, &FactConfig::default());
        assert!(tested.is_empty(), "{:?}", keys(&tested));
    }

    #[test]
    fn a_clear_approach_clears_the_noise_and_says_how() {
        // Coming towards the car at 8 m/s through the same jitter.
        let seq = far_jittery_pair(1.0, -0.8);
        let facts = distance_trends(&seq, &FactConfig::default());
        let d = find(&facts, "DistanceDecrease(vehicle_1, pedestrian_2)");
        let note = &d.provenance.note;
        assert!(note.contains("distance_significance 0.5"), "{note}");
        assert!(note.contains("measured noise"), "{note}");
        // Noise-free, the same approach is a trend as before.
        let clean = pair(|_| (0.0, 10.0), |f| (0.0, 50.0 - 0.8 * f64::from(f)));
        let facts = distance_trends(&clean, &FactConfig::default());
        find(&facts, "DistanceDecrease(vehicle_1, pedestrian_2)");
    }

    fn initial_locations(seq: &Sequence, config: &FactConfig) -> Vec<String> {
        let facts = range_facts(seq, 0, 9, config).unwrap().facts;
        keys(&facts)
            .into_iter()
            .filter(|k| k.starts_with("InitialLocation(vehicle_1"))
            .collect()
    }

    /// Issue 22 item 3: a one-frame outlier at the window's first sighting
    /// (a box thrown across the image, as an id switch does) does not flip
    /// the first location, and neither does a miss.
    #[test]
    fn a_one_frame_outlier_or_a_miss_does_not_flip_the_first_location() {
        // A car 15 m ahead, 8 m to the left, creeping right: Left throughout.
        let left = |f: u32| (-8.0 + 0.1 * f64::from(f), 15.0);
        let clean = pair(left, |_| (2.0, 40.0));
        let want = [
            "InitialLocation(vehicle_1, Left)",
            "InitialLocation(vehicle_1, NearLeft)",
        ];
        assert_eq!(initial_locations(&clean, &FactConfig::default()), want);
        // Frame 0's box belongs to something 12 m right and 30 m deep.
        let mut outlier = clean.clone();
        let bad = at(0, 1, ObjectClass::Vehicle, 12.0, 30.0);
        for o in &mut outlier.observations {
            if o.frame == 0 && o.track_id == 1 {
                *o = bad.clone();
            }
        }
        assert_eq!(initial_locations(&outlier, &FactConfig::default()), want);
        let first = FactConfig {
            location_sightings: 1,
            ..FactConfig::default()
        };
        assert_eq!(
            initial_locations(&outlier, &first),
            [
                "InitialLocation(vehicle_1, FarRight)",
                "InitialLocation(vehicle_1, Right)"
            ],
            "the first sighting alone is fooled"
        );
        let facts = range_facts(&outlier, 0, 9, &FactConfig::default())
            .unwrap()
            .facts;
        let note = &find(&facts, "InitialLocation(vehicle_1, Left)")
            .provenance
            .note;
        assert!(note.contains("Theil–Sen"), "{note}");
        // Frame 0 missed: the first sighting is frame 1, still on the left.
        let mut missed = clean.clone();
        missed
            .observations
            .retain(|o| !(o.frame == 0 && o.track_id == 1));
        assert_eq!(initial_locations(&missed, &FactConfig::default()), want);
    }

    #[test]
    fn ground_surfaces_take_no_part() {
        let mut seq = pair(|_| (-4.0, 15.0), |_| (2.0, 15.0));
        for o in &mut seq.observations {
            if o.track_id == 2 {
                // A road without a footprint polygon is still a region.
                o.class = ObjectClass::Road;
            }
        }
        assert!(relative(&seq, &FactConfig::default()).is_empty());
    }

    /// The ego taken as parked (ego-motion off): the objects' own motion
    /// alone decides, with two anchors that a RANSAC fit could not tell apart.
    fn parked_camera() -> FactConfig {
        FactConfig {
            ego: crate::config::EgoConfig {
                enabled: false,
                ..Default::default()
            },
            ..FactConfig::default()
        }
    }

    fn with(facts: &[Fact], pred: &str) -> Vec<String> {
        facts
            .iter()
            .filter(|f| f.predicate == pred)
            .map(Fact::to_kb_line)
            .collect()
    }

    #[test]
    fn closer_compares_mean_ground_distances_to_the_ego_with_a_margin() {
        // The car 10 m ahead, the pedestrian at (3, 30): √909 − 10 = 20.15 m.
        let seq = pair(|_| (0.0, 10.0), |_| (3.0, 30.0));
        let facts = range_facts(&seq, 0, 9, &FactConfig::default())
            .unwrap()
            .facts;
        assert_eq!(with(&facts, "Closer"), ["Closer(vehicle_1, pedestrian_2)"]);
        let p = &find(&facts, "Closer(vehicle_1, pedestrian_2)").provenance;
        let want = (9.0f64 + 900.0).sqrt() - 10.0;
        assert!((p.measured.unwrap() - want).abs() < 1e-9, "{p:?}");
        assert_eq!(p.threshold, Some(("closer_margin_m".into(), 1.0)));
        assert!(p.note.contains("vehicle_1 10.00 ± 0.00 m"), "{}", p.note);
        assert!(p.note.contains("pedestrian_2 30.15 ± 0.00 m"), "{}", p.note);
        // Level within the margin: neither is closer.
        let level = pair(|_| (-2.0, 20.0), |_| (2.0, 20.5));
        let facts = range_facts(&level, 0, 9, &FactConfig::default())
            .unwrap()
            .facts;
        assert!(with(&facts, "Closer").is_empty());
        // A wider margin turns the first pair off too.
        let wide = FactConfig {
            closer_margin_m: 25.0,
            ..FactConfig::default()
        };
        let facts = range_facts(&seq, 0, 9, &wide).unwrap().facts;
        assert!(with(&facts, "Closer").is_empty());
    }

    #[test]
    fn faster_compares_window_speeds_and_includes_the_ego() {
        // The car drives away at 10 m/s; the pedestrian walks 0.5 m/s.
        let seq = pair(
            |f| (0.0, 10.0 + f64::from(f)),
            |f| (4.0, 15.0 + 0.05 * f64::from(f)),
        );
        let facts = range_facts(&seq, 0, 9, &parked_camera()).unwrap().facts;
        assert_eq!(
            with(&facts, "Faster"),
            ["Faster(vehicle_1, ego)", "Faster(vehicle_1, pedestrian_2)"]
        );
        let p = &find(&facts, "Faster(vehicle_1, pedestrian_2)").provenance;
        assert!((p.measured.unwrap() - 9.5).abs() < 1e-6, "{p:?}");
        assert_eq!(p.threshold, Some(("faster_margin_mps".into(), 0.5)));
        assert!(p.note.contains("vehicle_1 10.00 ± 0.00 m/s"), "{}", p.note);
        assert!(
            p.note.contains("pedestrian_2 0.50 ± 0.00 m/s"),
            "{}",
            p.note
        );
    }

    #[test]
    fn relations_to_the_ego_use_the_pair_rules_with_the_ego_at_the_camera() {
        // The car ahead in our lane and coming closer at 1 m/frame; the
        // pedestrian 4 m to the left, standing.
        let seq = pair(|f| (0.5, 25.0 - f64::from(f)), |_| (-4.0, 15.0));
        let facts = range_facts(&seq, 0, 9, &parked_camera()).unwrap().facts;
        let lines = keys(&facts);
        for want in [
            "Ego(ego)",
            "InFrontOf(vehicle_1, ego)",
            "Behind(ego, vehicle_1)",
            "LeftOf(pedestrian_2, ego)",
            "RightOf(ego, pedestrian_2)",
            "DistanceDecrease(vehicle_1, ego)",
            "DistanceDecrease(ego, vehicle_1)",
            "SharesFrames(vehicle_1, ego)",
            "SharesFrames(ego, pedestrian_2)",
            "Near(pedestrian_2, ego)",
            "Near(ego, pedestrian_2)",
            "Near(vehicle_1, ego)",
            // 15 m ahead and 4 m to the left: outside the lane corridor,
            // but within 45° of straight ahead, which is "in front of us"
            // (between two objects it would not be).
            "InFrontOf(pedestrian_2, ego)",
        ] {
            assert!(lines.contains(&want.to_string()), "{want}: {lines:?}");
        }
        assert!(!lines.contains(&"InFrontOf(pedestrian_2, vehicle_1)".to_string()));
        for never in [
            "LeftOf(vehicle_1, ego)",
            "RightOf(vehicle_1, ego)",
            "DistanceDecrease(pedestrian_2, ego)",
            "DistanceIncrease(pedestrian_2, ego)",
            "Moving(ego)",
            "Vehicles(ego)",
        ] {
            assert!(!lines.contains(&never.to_string()), "{never}: {lines:?}");
        }
        // The collision facts never involve the ego.
        assert!(facts.iter().all(|f| !(f.args.iter().any(|a| a == EGO)
            && matches!(
                &*f.predicate,
                "TooClose" | "DistanceZeroStart" | "DistanceZeroEnd" | "DistanceDecreasesToZero"
            ))));
        let p = &find(&facts, "DistanceDecrease(vehicle_1, ego)").provenance;
        assert!((p.measured.unwrap() + 10.0).abs() < 0.05, "{p:?}");
        assert!(p.note.contains("ground distance to the ego"), "{}", p.note);
        // Near once its depth falls below near_far_m (20 m): an approach
        // that ends at 31 m never is.
        let far = pair(|f| (0.5, 40.0 - f64::from(f)), |_| (-4.0, 15.0));
        let facts = range_facts(&far, 0, 9, &parked_camera()).unwrap().facts;
        assert!(!keys(&facts).contains(&"Near(vehicle_1, ego)".to_string()));
    }

    #[test]
    fn near_the_ego_agrees_with_the_near_locations() {
        // Depth 19.9 m at the first sighting, 25 m at the last: NearLeft
        // first, so near us; depth 20 m throughout: Far, not near.
        let seq = pair(|f| (-8.0, 19.9 + 0.6 * f64::from(f)), |_| (8.0, 20.0));
        let facts = range_facts(&seq, 0, 9, &parked_camera()).unwrap().facts;
        let lines = keys(&facts);
        assert!(lines.contains(&"InitialLocation(vehicle_1, NearLeft)".to_string()));
        assert!(lines.contains(&"Near(vehicle_1, ego)".to_string()));
        let p = &find(&facts, "Near(vehicle_1, ego)").provenance;
        assert_eq!(p.measured, Some(19.9));
        assert_eq!(p.threshold, Some(("near_far_m".into(), 20.0)));
        assert!(lines.contains(&"InitialLocation(pedestrian_2, FarRight)".to_string()));
        assert!(!lines.contains(&"Near(pedestrian_2, ego)".to_string()));
    }
}
