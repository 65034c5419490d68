//! [`FactConfig`]: every threshold the fact extractor compares a measurement
//! with, in one typed, documented, serde-loadable place. Provenance names the
//! field (`threshold: ("moving_speed_vehicle_mps", 1.0)`).

use serde::{Deserialize, Serialize};

use crate::error::PerceptionError;
use crate::model::ObjectClass;

/// Thresholds and smoothing parameters for window facts. Every field has a
/// default (see [`FactConfig::default`]); a JSON/YAML file may set any subset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FactConfig {
    /// Minimum observations with a 3D position inside a window before motion
    /// facts (`Moving`, `SpeedUp`, `SpeedDown`) and distance trends are
    /// measured; fewer gives no motion facts (closed world: not moving).
    pub min_observations: u32,
    /// World-frame speed (m/s) above which a vehicle is `Moving`.
    pub moving_speed_vehicle_mps: f64,
    /// World-frame speed (m/s) above which a pedestrian or person is `Moving`.
    pub moving_speed_pedestrian_mps: f64,
    /// World-frame speed (m/s) above which a cyclist or other road user is `Moving`.
    pub moving_speed_other_mps: f64,
    /// Trends must clear their threshold by this many standard errors of
    /// the regression slope (estimated from the residuals), so that
    /// position noise on far objects is not read as motion; 0 compares the
    /// plain slope.
    pub trend_significance: f64,
    /// Acceleration (m/s², regression slope of speed over the window) above
    /// which a moving object is `SpeedUp` (below its negative: `SpeedDown`).
    pub speed_change_mps2: f64,
    /// Minimum change of the fitted speed across the window (m/s) for
    /// `SpeedUp`/`SpeedDown`, so that noise on a short window is not a trend.
    pub speed_change_min_mps: f64,
    /// Rate (m/s, regression slope of the gap) beyond which the gap between
    /// two objects is `DistanceIncrease`/`DistanceDecrease`.
    pub distance_rate_mps: f64,
    /// Minimum change of the fitted gap across the window (m) for a distance trend.
    pub distance_change_min_m: f64,
    /// Distance trends must clear `distance_rate_mps` by this many
    /// standard errors of the gap's regression slope. The standard error is
    /// the larger of the one the residuals give and the one the measured
    /// position noise gives (each sighting's lateral and depth noise,
    /// `ego::MeasuredNoise`, projected on the line between the two
    /// objects), so that depth noise on far pairs is not read as
    /// approaching or receding; 0 compares the plain slope. 0.5, not
    /// `trend_significance`'s 1.5: on the simulator's question sets 1.5
    /// loses more true trends than it removes false ones (docs/history.md).
    pub distance_significance: f64,
    /// First/last location (`InitialLocation`, `LastLocation`): the first
    /// (last) this many sightings of the window are fitted with a robust
    /// (Theil–Sen) line; 1 uses the first (last) sighting alone.
    pub location_sightings: u32,
    /// A first/last sighting whose box centre lies farther than this
    /// fraction of the image width from the robust line through its
    /// neighbours is an outlier (a bad box, a one-frame id switch) and the
    /// line's value at that frame is used instead.
    pub location_outlier_fraction: f64,
    /// Likewise for its depth, as a fraction of the line's depth.
    pub location_outlier_depth_fraction: f64,
    /// Gap (m) between two footprints at or below which they touch
    /// (`DistanceZeroStart`, `DistanceZeroEnd`, `DistanceDecreasesToZero`).
    pub touch_distance_m: f64,
    /// Gap (m) below which two objects are `TooClose` at some frame.
    pub too_close_distance_m: f64,
    /// Ground distance (m) from the camera below which an object is `CloseToCamera`.
    pub close_to_camera_m: f64,
    /// Depth (m, camera Z) separating `Near*` from `Far*` locations; also
    /// the one threshold of `Near(x, ego)` (an object is near us when its
    /// depth falls below it in the window), so that "near us" and a
    /// `NearLeft`/`NearRight`/`NearFront` location always agree.
    pub near_far_m: f64,
    /// Heading change of the ego (degrees, over the window's first to last
    /// frame) beyond which it is `TurnRight` (heading turning clockwise seen
    /// from above, towards camera +X) or `TurnLeft`; it must also clear
    /// `trend_significance` standard deviations of the change from the
    /// yaw noise measured on the ego's estimated trajectory.
    pub turn_min_deg: f64,
    /// `Closer(x, y)`: `x`'s mean ground distance to the ego over the frames
    /// both are seen must be smaller than `y`'s by more than this (m) ...
    pub closer_margin_m: f64,
    /// `Faster(x, y)`: `x`'s window speed must exceed `y`'s by more than
    /// this (m/s) ...
    pub faster_margin_mps: f64,
    /// ... and, for both comparisons, by more than this many standard
    /// deviations of the difference (from the measured position noise for
    /// `Closer`, from the two speeds' standard errors for `Faster`), so that
    /// noise does not order two objects that are about level; 0 compares the
    /// plain values.
    pub comparison_significance: f64,
    /// Image-width fraction left of which a box centre is `Left`/`AtLeft`.
    pub left_fraction: f64,
    /// Image-width fraction right of which a box centre is `Right`/`AtRight`.
    pub right_fraction: f64,
    /// Frames before a window's first sighting that must be empty of the
    /// object for `Appear` (re-sightings after short occlusions are not `Appear`).
    pub appear_lookback_frames: u32,
    /// Frames after a window's last sighting that must be empty of the object
    /// for `Disappear`.
    pub disappear_lookahead_frames: u32,
    /// Fraction of a window's frames in which an object's ground point must
    /// lie on a surface (or another object's footprint) for `On(x, y)`.
    pub on_min_fraction: f64,
    /// The neighbourhood of the Hampel outlier filter (frames, odd, >= 3:
    /// it looks `savgol_window / 2 + 1` sightings each way). Named for the
    /// Savitzky–Golay speeds it once also sized.
    pub savgol_window: u32,
    /// Savitzky–Golay polynomial order (< `savgol_window`). Checked, and
    /// kept so that existing config files load, but no longer used: the
    /// Savitzky–Golay speeds at a window's edges were the noisiest estimate
    /// of a speed change, which now comes from the Kalman/RTS velocities.
    pub savgol_order: u32,
    /// Hampel outlier filter: positions farther than this many scaled MADs
    /// from the local median are replaced by the median.
    pub outlier_mad_k: f64,
    /// How track positions are smoothed before motion facts are measured
    /// (see [`Smoother`]).
    pub smoother: Smoother,
    /// Kalman smoother: spectral density of the white acceleration driving
    /// the constant-velocity model (m²/s³); larger follows speed changes
    /// faster and smooths less.
    pub kalman_accel_psd: f64,
    /// Spectral density of the white jerk driving the constant-acceleration
    /// RTS smoother that measures `SpeedUp`/`SpeedDown` (m²/s⁵), whichever
    /// `smoother` is set; larger follows changes of acceleration faster
    /// and smooths less.
    pub kalman_jerk_psd: f64,
    /// The constant-acceleration smoother measures a window's speed change
    /// only where the χ² test of its innovations around the window gives a
    /// p-value of at least this (its model holds there: no crash, no
    /// abrupt stop); elsewhere the constant-velocity smoother does.
    pub kalman_ca_min_p: f64,
    /// Kalman smoother: a sighting whose innovation exceeds this many
    /// standard deviations is rejected as an outlier (a bad box, a swapped
    /// detection).
    pub kalman_gate_sd: f64,
    /// Kalman smoother: floor of a sighting's position standard deviation
    /// (m), below whatever noise is measured on the sequence.
    pub kalman_min_sigma_m: f64,
    /// A fact that was measured and not asserted is kept as a doubt (with
    /// the probability that it holds all the same, [`crate::belief`]) when
    /// that probability is at least this; 1 keeps none. Doubts say how sure
    /// an answer resting on a fact's absence is.
    pub doubt_min_probability: f64,
    /// Measured position noise (m; lateral σ, and depth σ at `near_far_m`)
    /// at or below which a sequence's positions count as exact (dataset
    /// labels, a noise-free simulation): its facts are certain and nothing
    /// is in doubt. Not 0: a noise-free track that turns or brakes has
    /// second differences of its own, which the noise estimate reads as a
    /// few millimetres (the simulator's `low` noise is 50 mm).
    pub exact_noise_m: f64,
    /// Ego-motion estimation parameters.
    pub ego: EgoConfig,
    /// Thresholds of the relative-position pair facts (`LeftOf`, `RightOf`,
    /// `InFrontOf`, `Behind`).
    pub relative: RelativeConfig,
    /// Thresholds of the 360° relations and map facts (sources with 3D
    /// positions all around the ego, an ego pose and a map: Argoverse 2).
    pub around: AroundConfig,
}

/// Thresholds of the 360° relations (Argoverse's scenario-mining benchmark,
/// RefAV, defines most of them; the defaults are its defaults) and of the
/// map facts. Angles in degrees, distances in metres, speeds in m/s.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AroundConfig {
    /// An object without a camera box is in `Front` of the ego when its
    /// bearing (angle from the ego's heading) is at most this.
    pub bearing_front_deg: f64,
    /// ... and `Behind` when its bearing is at least this; `Left`/`Right`
    /// in between.
    pub bearing_behind_deg: f64,
    /// `Near(x, y)`: centres at most this far apart (RefAV `near_objects`: 10).
    pub near_m: f64,
    /// `InDirectionOf(x, y, d)`: y's centre at most this far from x's box
    /// along direction `d` (RefAV `within_distance`: 50).
    pub direction_within_m: f64,
    /// ... and at most this far off the line of `d` beyond x's half-size
    /// (RefAV `lateral_thresh`; `None`: unlimited, RefAV's default).
    pub direction_lateral_m: Option<f64>,
    /// `SameDirection(x, y)`: headings differ by at most this.
    pub same_direction_max_deg: f64,
    /// `Opposite(x, y)`: headings differ by at least this;
    /// `Perpendicular` in between.
    pub opposite_min_deg: f64,
    /// Headings of objects slower than this are not compared (a parked
    /// car's box may point any way).
    pub heading_min_speed_mps: f64,
    /// `TurnLeft(x)` / `TurnRight(x)` for an object: its heading changes by
    /// more than this over one run of same-sign yaw rate.
    pub object_turn_min_deg: f64,
    /// `Stationary(x)`: moves less than this over the whole log (parked).
    pub stationary_max_travel_m: f64,
    /// `HeadingToward(x, y)`: x's velocity points within this angle of
    /// the direction to y (RefAV: 22.5) ...
    pub heading_toward_max_deg: f64,
    /// ... x is at least this fast (RefAV: 0.5) ...
    pub heading_toward_min_speed_mps: f64,
    /// ... and y at most this far.
    pub heading_toward_max_m: f64,
    /// `CrossedBy(x, y)`: y's centre crosses x's forward half-plane within
    /// this distance ahead of x (RefAV `forward_thresh`: 10) ...
    pub crossing_forward_m: f64,
    /// ... and within this distance of x's sides (RefAV `lateral_thresh`: 5).
    pub crossing_lateral_m: f64,
    /// `OnCrosswalk(x)`: x's centre within this of a crossing (RefAV
    /// `at_pedestrian_crossing`: 1).
    pub on_crosswalk_m: f64,
    /// `NearCrosswalk(x)`: within this of a crossing.
    pub near_crosswalk_m: f64,
    /// `InIntersection(x)` / `NearIntersection(x)`: within this of an
    /// intersection lane (RefAV `near_intersection`: 5) for the latter.
    pub near_intersection_m: f64,
    /// `Following(x, y)`: y ahead of x in the same lane, at most this far.
    pub following_max_m: f64,
    /// A map fact or relation holds in a window when it holds in at least
    /// this share of the frames both objects are seen in.
    pub min_frame_fraction: f64,
    /// On a surround log, relations between two objects (the camera-style
    /// pair facts — `LeftOf`, `Closer`, `Faster`, `SharesFrames`, distance
    /// trends — and the 360° relations above) are measured only between
    /// objects that come within this range of the ego in the window.
    /// A 360° log annotates a hundred objects out to 150 m, whose pairs
    /// cost quadratically (half a million facts for one 16 s log) and
    /// whose relations far from the ego nobody asks about; every object
    /// keeps its own facts and its relations with the ego at any range.
    pub pair_range_m: f64,
}

impl Default for AroundConfig {
    fn default() -> Self {
        AroundConfig {
            bearing_front_deg: 45.0,
            bearing_behind_deg: 135.0,
            near_m: 10.0,
            direction_within_m: 50.0,
            direction_lateral_m: None,
            same_direction_max_deg: 45.0,
            opposite_min_deg: 135.0,
            heading_min_speed_mps: 0.5,
            object_turn_min_deg: 45.0,
            stationary_max_travel_m: 2.0,
            heading_toward_max_deg: 22.5,
            heading_toward_min_speed_mps: 0.5,
            heading_toward_max_m: 50.0,
            crossing_forward_m: 10.0,
            crossing_lateral_m: 5.0,
            on_crosswalk_m: 1.0,
            near_crosswalk_m: 5.0,
            near_intersection_m: 5.0,
            following_max_m: 25.0,
            min_frame_fraction: 0.5,
            pair_range_m: 50.0,
        }
    }
}

impl AroundConfig {
    /// Checks the documented ranges; the field is named `around.<name>`.
    pub fn validate(&self) -> Result<(), PerceptionError> {
        let bad = |field: &str, message: &str| {
            Err(PerceptionError::InvalidConfig {
                field: format!("around.{field}"),
                message: message.to_string(),
            })
        };
        let non_negative = [
            ("bearing_front_deg", self.bearing_front_deg),
            ("bearing_behind_deg", self.bearing_behind_deg),
            ("near_m", self.near_m),
            ("direction_within_m", self.direction_within_m),
            (
                "direction_lateral_m",
                self.direction_lateral_m.unwrap_or(0.0),
            ),
            ("same_direction_max_deg", self.same_direction_max_deg),
            ("opposite_min_deg", self.opposite_min_deg),
            ("heading_min_speed_mps", self.heading_min_speed_mps),
            ("object_turn_min_deg", self.object_turn_min_deg),
            ("stationary_max_travel_m", self.stationary_max_travel_m),
            ("heading_toward_max_deg", self.heading_toward_max_deg),
            (
                "heading_toward_min_speed_mps",
                self.heading_toward_min_speed_mps,
            ),
            ("heading_toward_max_m", self.heading_toward_max_m),
            ("crossing_forward_m", self.crossing_forward_m),
            ("crossing_lateral_m", self.crossing_lateral_m),
            ("on_crosswalk_m", self.on_crosswalk_m),
            ("near_crosswalk_m", self.near_crosswalk_m),
            ("near_intersection_m", self.near_intersection_m),
            ("following_max_m", self.following_max_m),
            ("pair_range_m", self.pair_range_m),
        ];
        for (field, v) in non_negative {
            // `!(v >= 0)` is also true for NaN.
            if !(v >= 0.0 && v.is_finite()) {
                return bad(field, "must be a finite number >= 0");
            }
        }
        if !(self.bearing_front_deg <= self.bearing_behind_deg && self.bearing_behind_deg <= 180.0)
        {
            return bad(
                "bearing_behind_deg",
                "must lie between bearing_front_deg and 180",
            );
        }
        if !(self.same_direction_max_deg <= self.opposite_min_deg && self.opposite_min_deg <= 180.0)
        {
            return bad(
                "opposite_min_deg",
                "must lie between same_direction_max_deg and 180",
            );
        }
        if !(0.0..=1.0).contains(&self.min_frame_fraction) {
            return bad("min_frame_fraction", "must be in [0, 1]");
        }
        Ok(())
    }
}

/// How a track's world positions are smoothed for `Moving`. `SpeedUp` and
/// `SpeedDown` always use the Kalman/RTS velocities (a speed change
/// compares the window's first and last speeds, where per-window estimates
/// are at their worst).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Smoother {
    /// Hampel outlier replacement, then per-window least-squares slopes
    /// with their standard errors (the default: measured best for `Moving`).
    Savgol,
    /// A constant-velocity Kalman filter over the whole track with an
    /// innovation gate for outliers and a Rauch–Tung–Striebel smoother;
    /// each sighting weighted by the noise measured on the sequence
    /// ([`crate::ego::MeasuredNoise`]); decisions use the smoothed speed
    /// and its posterior standard deviation.
    Kalman,
}

/// Thresholds of the relative-position pair facts, measured per frame in the
/// ego camera's frame (X right, Z forward) and decided by a vote over the
/// frames a pair shares (see `docs/perception.md`).
///
/// Invariant (checked by [`FactConfig::validate`]): the metric fields are
/// finite and `>= 0`, `lateral_min_image_fraction` is in `[0, 1]`, and
/// `min_frame_fraction` is in `[0.5, 1)` — at least a half, so that a
/// relation and its opposite (`LeftOf(x, y)`, `LeftOf(y, x)`) cannot both win
/// the vote.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RelativeConfig {
    /// Lateral offset (m, camera X) by which `x` must lie left of `y` in a
    /// frame for that frame to count towards `LeftOf(x, y)`; a margin above
    /// position noise, so that objects nearly in line are not ordered by it.
    pub lateral_min_m: f64,
    /// Forward offset (m, camera Z) by which `x` must lie ahead of `y` in a
    /// frame for that frame to count towards `InFrontOf(x, y)`; about half
    /// a car length, so that two cars side by side are not ordered.
    pub forward_min_m: f64,
    /// Largest lateral distance (m) at which `x` still counts as in `y`'s
    /// path (the same corridor) for `InFrontOf(x, y)`; ~ a lane width.
    pub corridor_m: f64,
    /// Without ground points (no 3D position, box bottom above the horizon)
    /// `LeftOf` compares box centres: the image-width fraction by which `x`'s
    /// centre must lie left of `y`'s.
    pub lateral_min_image_fraction: f64,
    /// A relation holds when the share of the pair's measured common frames
    /// that satisfy it is strictly greater than this (0.5: a majority).
    pub min_frame_fraction: f64,
}

impl Default for RelativeConfig {
    fn default() -> Self {
        RelativeConfig {
            lateral_min_m: 1.0,
            forward_min_m: 2.0,
            corridor_m: 3.0,
            // 62 px on KITTI's 1242-px image: about 1 m of lateral offset at
            // 12 m depth (fx 721 px).
            lateral_min_image_fraction: 0.05,
            min_frame_fraction: 0.5,
        }
    }
}

/// Parameters of the robust ego-motion fit (see [`crate::ego`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EgoConfig {
    /// Whether to estimate ego-motion at all; `false` measures motion in the
    /// camera frame (only right for a parked camera).
    pub enabled: bool,
    /// Base inlier radius (m) for an anchor's predicted position.
    pub inlier_base_m: f64,
    /// Extra inlier radius per metre of depth (label and depth noise grow
    /// with distance).
    pub inlier_depth_fraction: f64,
    /// Weight of static-class anchors (poles, signs, buildings) relative to
    /// road users, which may be moving.
    pub static_anchor_weight: f64,
    /// Hypotheses implying a faster ego (m/s) are rejected.
    pub max_speed_mps: f64,
    /// Hypotheses implying a faster turn (rad/s) are rejected.
    pub max_yaw_rate_rps: f64,
    /// Minimum total inlier weight to accept a fit; below it the previous
    /// frame's motion is reused (constant-velocity fallback).
    pub min_inlier_weight: f64,
    /// Whether the inlier radius widens with the position noise measured
    /// on the sequence itself (second differences of every track's camera
    /// positions, see [`crate::ego::MeasuredNoise`]). The radius is never
    /// narrower than `inlier_base_m + inlier_depth_fraction × depth`, so
    /// noise-free input is fitted as without it.
    pub noise_adaptive: bool,
    /// Noise-adaptive inlier radius, in standard deviations of an anchor's
    /// expected residual at its depth.
    pub inlier_noise_k: f64,
    /// Each frame's pose is the inlier-weighted mean of its fits against
    /// each of the previous `averaging_frames` frames (1: frame to frame
    /// only), so that one noisy step does not become drift. Used only when
    /// the measured noise widens the inlier radius somewhere (noisy input);
    /// noise-free input keeps the frame-to-frame chain.
    pub averaging_frames: u32,
}

impl Default for EgoConfig {
    fn default() -> Self {
        EgoConfig {
            enabled: true,
            inlier_base_m: 0.15,
            inlier_depth_fraction: 0.01,
            static_anchor_weight: 3.0,
            max_speed_mps: 45.0,
            max_yaw_rate_rps: 1.2,
            min_inlier_weight: 2.0,
            noise_adaptive: true,
            inlier_noise_k: 2.5,
            averaging_frames: 5,
        }
    }
}

impl Default for FactConfig {
    fn default() -> Self {
        FactConfig {
            min_observations: 3,
            moving_speed_vehicle_mps: 1.0,
            moving_speed_pedestrian_mps: 0.4,
            moving_speed_other_mps: 0.8,
            trend_significance: 1.5,
            speed_change_mps2: 0.8,
            speed_change_min_mps: 0.6,
            distance_rate_mps: 0.5,
            distance_change_min_m: 0.5,
            distance_significance: 0.5,
            location_sightings: 5,
            location_outlier_fraction: 0.05,
            location_outlier_depth_fraction: 0.15,
            touch_distance_m: 0.4,
            too_close_distance_m: 1.0,
            close_to_camera_m: 10.0,
            near_far_m: 20.0,
            turn_min_deg: 5.0,
            closer_margin_m: 1.0,
            faster_margin_mps: 0.5,
            comparison_significance: 1.5,
            left_fraction: 1.0 / 3.0,
            right_fraction: 2.0 / 3.0,
            appear_lookback_frames: 5,
            disappear_lookahead_frames: 5,
            on_min_fraction: 0.5,
            savgol_window: 5,
            savgol_order: 2,
            outlier_mad_k: 4.0,
            smoother: Smoother::Savgol,
            kalman_accel_psd: 4.0,
            kalman_jerk_psd: 0.5,
            kalman_ca_min_p: 0.01,
            kalman_gate_sd: 3.5,
            kalman_min_sigma_m: 0.05,
            doubt_min_probability: 0.01,
            exact_noise_m: 0.025,
            ego: EgoConfig::default(),
            relative: RelativeConfig::default(),
            around: AroundConfig::default(),
        }
    }
}

/// The longest Savitzky–Golay window accepted, in frames: wider smooths
/// away every change a window of frames could show.
pub const MAX_SAVGOL_WINDOW: u32 = 101;
/// The most previous frames a pose is averaged over (each costs one fit).
pub const MAX_AVERAGING_FRAMES: u32 = 30;
/// The most sightings a first/last location is fitted over.
pub const MAX_LOCATION_SIGHTINGS: u32 = 30;
/// The highest Savitzky–Golay polynomial order accepted.
pub const MAX_SAVGOL_ORDER: u32 = 10;

impl FactConfig {
    /// The `Moving` threshold for a class, with its field name.
    pub fn moving_threshold(&self, class: ObjectClass) -> (&'static str, f64) {
        match class {
            ObjectClass::Vehicle => ("moving_speed_vehicle_mps", self.moving_speed_vehicle_mps),
            ObjectClass::Pedestrian | ObjectClass::Person => (
                "moving_speed_pedestrian_mps",
                self.moving_speed_pedestrian_mps,
            ),
            _ => ("moving_speed_other_mps", self.moving_speed_other_mps),
        }
    }

    /// Parses a JSON config (unknown fields are errors).
    pub fn from_json(text: &str, origin: &str) -> Result<FactConfig, PerceptionError> {
        let c: FactConfig = serde_json::from_str(text).map_err(|e| PerceptionError::Json {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
        c.validate().map_err(|e| in_file(e, text, origin))?;
        Ok(c)
    }

    /// Parses a YAML config (unknown fields are errors).
    pub fn from_yaml(text: &str, origin: &str) -> Result<FactConfig, PerceptionError> {
        let c: FactConfig = serde_saphyr::from_str(text).map_err(|e| PerceptionError::Yaml {
            origin: origin.to_string(),
            message: crate::error::yaml_message(&e, origin),
        })?;
        c.validate().map_err(|e| in_file(e, text, origin))?;
        Ok(c)
    }

    /// Loads a config file: JSON when the extension is `.json`, YAML otherwise.
    pub fn load(path: &std::path::Path) -> Result<FactConfig, PerceptionError> {
        crate::textfile::load_yaml_or_json(path, FactConfig::from_json, FactConfig::from_yaml)
    }

    /// Checks every field's documented range.
    pub fn validate(&self) -> Result<(), PerceptionError> {
        let bad = |field: &str, message: &str| {
            Err(PerceptionError::InvalidConfig {
                field: field.to_string(),
                message: message.to_string(),
            })
        };
        let non_negative = [
            ("moving_speed_vehicle_mps", self.moving_speed_vehicle_mps),
            (
                "moving_speed_pedestrian_mps",
                self.moving_speed_pedestrian_mps,
            ),
            ("moving_speed_other_mps", self.moving_speed_other_mps),
            ("trend_significance", self.trend_significance),
            ("speed_change_mps2", self.speed_change_mps2),
            ("speed_change_min_mps", self.speed_change_min_mps),
            ("distance_rate_mps", self.distance_rate_mps),
            ("distance_change_min_m", self.distance_change_min_m),
            ("distance_significance", self.distance_significance),
            ("location_outlier_fraction", self.location_outlier_fraction),
            (
                "location_outlier_depth_fraction",
                self.location_outlier_depth_fraction,
            ),
            ("touch_distance_m", self.touch_distance_m),
            ("too_close_distance_m", self.too_close_distance_m),
            ("close_to_camera_m", self.close_to_camera_m),
            ("near_far_m", self.near_far_m),
            ("turn_min_deg", self.turn_min_deg),
            ("closer_margin_m", self.closer_margin_m),
            ("faster_margin_mps", self.faster_margin_mps),
            ("comparison_significance", self.comparison_significance),
            ("outlier_mad_k", self.outlier_mad_k),
            ("kalman_accel_psd", self.kalman_accel_psd),
            ("kalman_jerk_psd", self.kalman_jerk_psd),
            ("kalman_ca_min_p", self.kalman_ca_min_p),
            ("kalman_gate_sd", self.kalman_gate_sd),
            ("kalman_min_sigma_m", self.kalman_min_sigma_m),
            ("exact_noise_m", self.exact_noise_m),
            ("ego.inlier_base_m", self.ego.inlier_base_m),
            ("ego.inlier_depth_fraction", self.ego.inlier_depth_fraction),
            ("ego.static_anchor_weight", self.ego.static_anchor_weight),
            ("ego.max_speed_mps", self.ego.max_speed_mps),
            ("ego.max_yaw_rate_rps", self.ego.max_yaw_rate_rps),
            ("ego.min_inlier_weight", self.ego.min_inlier_weight),
            ("ego.inlier_noise_k", self.ego.inlier_noise_k),
            ("relative.lateral_min_m", self.relative.lateral_min_m),
            ("relative.forward_min_m", self.relative.forward_min_m),
            ("relative.corridor_m", self.relative.corridor_m),
        ];
        for (field, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return bad(field, "must be a finite number >= 0");
            }
        }
        if !(0.0..=1.0).contains(&self.left_fraction)
            || !(0.0..=1.0).contains(&self.right_fraction)
            || self.left_fraction > self.right_fraction
        {
            return bad(
                "left_fraction",
                "need 0 <= left_fraction <= right_fraction <= 1",
            );
        }
        if self.turn_min_deg > 180.0 {
            return bad("turn_min_deg", "must be at most 180 degrees");
        }
        if !(0.0..=1.0).contains(&self.doubt_min_probability) {
            return bad("doubt_min_probability", "must be in [0, 1]");
        }
        if !(0.0..=1.0).contains(&self.kalman_ca_min_p) {
            return bad("kalman_ca_min_p", "must be in [0, 1]");
        }
        if !(0.0..=1.0).contains(&self.on_min_fraction) {
            return bad("on_min_fraction", "must be in [0, 1]");
        }
        self.around.validate()?;
        // `contains` is false for NaN, so these reject it too.
        if !(0.0..=1.0).contains(&self.relative.lateral_min_image_fraction) {
            return bad("relative.lateral_min_image_fraction", "must be in [0, 1]");
        }
        if !(0.5..1.0).contains(&self.relative.min_frame_fraction) {
            return bad(
                "relative.min_frame_fraction",
                "must be in [0.5, 1): at least a half, so that a relation and its opposite cannot both hold",
            );
        }
        if self.savgol_window < 3
            || self.savgol_window.is_multiple_of(2)
            || self.savgol_window > MAX_SAVGOL_WINDOW
        {
            // A window of a billion frames allocated 8 GB before failing.
            return bad(
                "savgol_window",
                &format!("must be odd, in 3..={MAX_SAVGOL_WINDOW}"),
            );
        }
        if self.savgol_order > MAX_SAVGOL_ORDER {
            return bad(
                "savgol_order",
                &format!("must be at most {MAX_SAVGOL_ORDER}"),
            );
        }
        if self.savgol_order >= self.savgol_window {
            return bad("savgol_order", "must be smaller than savgol_window");
        }
        if !(1..=MAX_AVERAGING_FRAMES).contains(&self.ego.averaging_frames) {
            return bad(
                "ego.averaging_frames",
                &format!("must be in 1..={MAX_AVERAGING_FRAMES}"),
            );
        }
        if !(1..=MAX_LOCATION_SIGHTINGS).contains(&self.location_sightings) {
            return bad(
                "location_sightings",
                &format!("must be in 1..={MAX_LOCATION_SIGHTINGS}"),
            );
        }
        if self.min_observations < 2 {
            return bad(
                "min_observations",
                "must be >= 2 (a trend needs two points)",
            );
        }
        Ok(())
    }
}

/// Names the file, and the line of the field where one can be found, in a
/// range error of a config that was read from text: `validate` itself only
/// knows the field.
fn in_file(e: PerceptionError, text: &str, origin: &str) -> PerceptionError {
    let PerceptionError::InvalidConfig { field, .. } = &e else {
        return e;
    };
    let yaml_key = format!("{field}:");
    let json_key = format!("\"{field}\"");
    let line = text.lines().position(|l| {
        let t = l.trim_start();
        t.starts_with(&yaml_key) || t.contains(&json_key)
    });
    match line {
        Some(i) => PerceptionError::Parse {
            path: origin.into(),
            line: i + 1,
            message: e.to_string(),
        },
        None => PerceptionError::File {
            path: origin.into(),
            message: e.to_string(),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_partial_files_load() {
        FactConfig::default().validate().unwrap();
        let c =
            FactConfig::from_json(r#"{"near_far_m": 30, "ego": {"enabled": false}}"#, "t").unwrap();
        assert_eq!(c.near_far_m, 30.0);
        assert!(!c.ego.enabled);
        assert_eq!(c.close_to_camera_m, FactConfig::default().close_to_camera_m);
        // Regression: a billion-frame window allocated 8 GB and aborted.
        let e = FactConfig::from_yaml("savgol_window: 1000000001\n", "t.yaml").unwrap_err();
        assert!(
            e.to_string().contains("savgol_window") && e.to_string().contains("3..=101"),
            "{e}"
        );
        // The file and the field's line are named, in YAML and JSON.
        let e = FactConfig::from_yaml("near_far_m: 30\nsavgol_window: 4\n", "c.yaml").unwrap_err();
        assert!(e.to_string().starts_with("c.yaml:2: "), "{e}");
        let e = FactConfig::from_json("{\n \"savgol_window\": 4\n}", "c.json").unwrap_err();
        assert!(e.to_string().starts_with("c.json:2: "), "{e}");
        let y = FactConfig::from_yaml("savgol_window: 7\n", "t.yaml").unwrap();
        assert_eq!(y.savgol_window, 7);
    }

    #[test]
    fn unknown_and_out_of_range_fields_are_errors() {
        assert!(FactConfig::from_json(r#"{"nearfar": 3}"#, "t").is_err());
        let e = FactConfig::from_json(r#"{"savgol_window": 4}"#, "t").unwrap_err();
        assert!(e.to_string().contains("savgol_window"));
    }

    #[test]
    fn relative_thresholds_load_partially_and_bad_values_name_their_field() {
        // A file written before `relative` existed still loads, with defaults.
        let c = FactConfig::from_json(r#"{"near_far_m": 30}"#, "t").unwrap();
        assert_eq!(c.relative, RelativeConfig::default());
        assert_eq!(
            (
                c.relative.lateral_min_m,
                c.relative.forward_min_m,
                c.relative.corridor_m
            ),
            (1.0, 2.0, 3.0)
        );
        let y = FactConfig::from_yaml("relative:\n  corridor_m: 2.5\n", "t.yaml").unwrap();
        assert_eq!(y.relative.corridor_m, 2.5);
        assert_eq!(y.relative.lateral_min_m, 1.0);
        assert!(FactConfig::from_json(r#"{"relative": {"corridor": 1}}"#, "t").is_err());
        for (json, field) in [
            (
                r#"{"relative": {"lateral_min_m": -1}}"#,
                "relative.lateral_min_m",
            ),
            (
                r#"{"relative": {"forward_min_m": -0.5}}"#,
                "relative.forward_min_m",
            ),
            (r#"{"relative": {"corridor_m": -3}}"#, "relative.corridor_m"),
            (
                r#"{"relative": {"lateral_min_image_fraction": 1.5}}"#,
                "relative.lateral_min_image_fraction",
            ),
            (
                r#"{"relative": {"min_frame_fraction": 0.4}}"#,
                "relative.min_frame_fraction",
            ),
            (
                r#"{"relative": {"min_frame_fraction": 1.0}}"#,
                "relative.min_frame_fraction",
            ),
        ] {
            let e = FactConfig::from_json(json, "t").unwrap_err().to_string();
            assert!(e.contains(&format!("`{field}`")), "{json}: {e}");
        }
        // JSON has no NaN; a config built in code can.
        for nan in [
            RelativeConfig {
                lateral_min_m: f64::NAN,
                ..Default::default()
            },
            RelativeConfig {
                forward_min_m: f64::NAN,
                ..Default::default()
            },
            RelativeConfig {
                corridor_m: f64::INFINITY,
                ..Default::default()
            },
            RelativeConfig {
                lateral_min_image_fraction: f64::NAN,
                ..Default::default()
            },
            RelativeConfig {
                min_frame_fraction: f64::NAN,
                ..Default::default()
            },
        ] {
            let c = FactConfig {
                relative: nan,
                ..FactConfig::default()
            };
            let e = c.validate().unwrap_err().to_string();
            assert!(e.contains("relative."), "{e}");
        }
    }

    #[test]
    fn the_constant_acceleration_fields_are_checked() {
        for (c, field) in [
            (
                FactConfig {
                    kalman_ca_min_p: 1.5,
                    ..FactConfig::default()
                },
                "kalman_ca_min_p",
            ),
            (
                FactConfig {
                    kalman_jerk_psd: -1.0,
                    ..FactConfig::default()
                },
                "kalman_jerk_psd",
            ),
        ] {
            let e = c.validate().unwrap_err().to_string();
            assert!(e.contains(field), "{e}");
        }
    }
}
