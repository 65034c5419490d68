//! Scenario files: the world, the ego camera's drive and every agent's
//! commanded motion. YAML or JSON; unknown fields are errors. The format is
//! documented in `docs/formats.md`; built-in scenarios live in
//! `perception/scenarios/*.yaml` and are compiled in.

use serde::{Deserialize, Serialize};

use crate::error::PerceptionError;
use crate::model::{CameraConfig, ObjectClass};

/// A complete scenario.
///
/// Invariants (checked by [`Scenario::validate`]): `frames > 0`, `fps > 0`,
/// unique agent ids, phases inside `0..frames` with `from < to`, references
/// (`enter`, `merge_into`) name existing vehicles, every number finite, sizes
/// positive, `0 < view.min_depth_m < view.max_depth_m`, noise sigmas
/// non-negative and its probabilities in `[0, 1]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Scenario {
    /// Scenario name (provenance `sim:<name>`).
    pub name: String,
    /// One-line description.
    #[serde(default)]
    pub description: String,
    /// Number of frames to simulate.
    pub frames: u32,
    /// Frames per second.
    #[serde(default = "default_fps")]
    pub fps: f64,
    /// The camera; KITTI-like (2011-09-26 calibration) when omitted.
    #[serde(default = "default_camera")]
    pub camera: CameraConfig,
    /// Visibility limits.
    #[serde(default)]
    pub view: ViewSpec,
    /// The ego vehicle carrying the camera.
    pub ego: MotionSpec,
    /// Roads, sidewalks and props.
    #[serde(default)]
    pub world: WorldSpec,
    /// Moving (or parked) road users.
    #[serde(default)]
    pub agents: Vec<AgentSpec>,
    /// Optional perception noise.
    #[serde(default)]
    pub noise: Option<NoiseSpec>,
}

/// The longest scenario name accepted (it names window ids and files).
pub(super) const MAX_NAME_LEN: usize = 64;

fn default_fps() -> f64 {
    10.0
}

/// Most objects a scenario may hold: agents plus static elements, counting
/// each road as three (the road and its two sidewalks) and each prop as one.
///
/// Every object can be observed in every frame, and the simulator's
/// occlusion test and the pair facts compare every object with every other
/// one per frame: 2,000 agents took 113 s and 4.3 GB. The limit is the
/// sequence limit [`crate::model::MAX_OBJECTS_PER_FRAME`], so a scenario
/// that validates also yields a sequence that does.
pub const MAX_SCENARIO_OBJECTS: usize = crate::model::MAX_OBJECTS_PER_FRAME;

/// Most object-frames a scenario may simulate: `frames × (objects + 1)`,
/// the `+ 1` being the ego vehicle.
///
/// The simulator keeps every object's state for every frame, so memory
/// grows with this product: `frames: 1000000` (within
/// [`crate::model::MAX_FRAMES`]) took 3.4 GB and aborted. Half a million
/// object-frames keep a run to a few hundred megabytes and allow, for
/// example, 10 objects for 45,000 frames (75 minutes at 10 fps) or the full
/// 256 objects for about 1,900 frames.
pub const MAX_SCENARIO_OBJECT_FRAMES: u64 = 500_000;

/// The default simulated camera: KITTI's 2011-09-26 left colour camera
/// (`P2` of tracking sequences 0000–0013, 1242×375 pixels, 1.65 m high).
pub fn default_camera() -> CameraConfig {
    crate::kitti::KITTI_2011_09_26_CAMERA
}

/// What the camera can see.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ViewSpec {
    /// Objects farther than this (m, depth) are not observed.
    pub max_depth_m: f64,
    /// Points nearer than this depth (m) are behind the image plane.
    pub min_depth_m: f64,
    /// Clipped boxes smaller than this many pixels in width or height are
    /// not observed.
    pub min_box_px: f64,
}

impl Default for ViewSpec {
    fn default() -> Self {
        ViewSpec {
            max_depth_m: 70.0,
            min_depth_m: 0.5,
            min_box_px: 8.0,
        }
    }
}

/// Start state and commanded phases of a moving thing (ego or agent).
/// Headings are degrees in the world's ground plane: 0 is the ego's initial
/// forward (+Z), 90 is to its right (+X).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionSpec {
    /// Start position `[x, z]`, metres.
    #[serde(default)]
    pub start: [f64; 2],
    /// Start heading, degrees.
    #[serde(default)]
    pub heading_deg: f64,
    /// Start speed, m/s.
    #[serde(default)]
    pub speed: f64,
    /// Commanded phases; frames outside every phase keep speed and heading.
    #[serde(default)]
    pub phases: Vec<Phase>,
}

/// A commanded phase over frames `from..to` (end exclusive).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Phase {
    /// First frame of the phase.
    pub from: u32,
    /// Frame after the last one.
    pub to: u32,
    /// Constant acceleration, m/s² (speed never goes below 0).
    #[serde(default)]
    pub accel: Option<f64>,
    /// Reach this speed (m/s) linearly by the end of the phase (instead of `accel`).
    #[serde(default)]
    pub speed_to: Option<f64>,
    /// Total heading change over the phase, degrees (positive turns right).
    #[serde(default)]
    pub turn_deg: Option<f64>,
    /// Pedestrians: walk to this vehicle and get in (vanish on contact).
    #[serde(default)]
    pub enter: Option<u32>,
    /// Vehicles: this phase is a merge into the lane of that vehicle
    /// (logged as a `Merge` event; the motion itself comes from `turn_deg`).
    #[serde(default)]
    pub merge_into: Option<u32>,
}

/// A road user.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AgentSpec {
    /// Track id (unique; static elements are numbered after the largest).
    pub id: u32,
    /// Class: `Vehicles`, `Pedestrian`, `Person`, `Cyclist`, `Misc`.
    pub class: ObjectClass,
    /// Type value (`Car`, `Van`, `SUV`, `Pedestrian`, …).
    #[serde(default, rename = "type")]
    pub type_name: Option<String>,
    /// Colour value (`White`, `Black`, …).
    #[serde(default)]
    pub color: Option<String>,
    /// `[h, w, l]`, metres; a class default when omitted.
    #[serde(default)]
    pub size: Option<[f64; 3]>,
    /// Parked: never moves whatever its speed and phases say (logged as `Parked`).
    #[serde(default)]
    pub parked: bool,
    /// Start position `[x, z]`, metres.
    #[serde(default)]
    pub start: [f64; 2],
    /// Start heading, degrees.
    #[serde(default)]
    pub heading_deg: f64,
    /// Start speed, m/s.
    #[serde(default)]
    pub speed: f64,
    /// Commanded phases.
    #[serde(default)]
    pub phases: Vec<Phase>,
}

impl AgentSpec {
    /// The agent's motion as a [`MotionSpec`].
    pub fn motion(&self) -> MotionSpec {
        MotionSpec {
            start: self.start,
            heading_deg: self.heading_deg,
            speed: self.speed,
            phases: self.phases.clone(),
        }
    }
}

/// Static world on flat ground.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldSpec {
    /// Straight road segments, each with a sidewalk on both sides.
    #[serde(default)]
    pub roads: Vec<RoadSpec>,
    /// Poles, signs, lights, buildings, vegetation, … as boxes.
    #[serde(default)]
    pub props: Vec<PropSpec>,
}

/// A straight road segment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RoadSpec {
    /// Centre of the segment `[x, z]`.
    pub center: [f64; 2],
    /// Direction, degrees (0 = along +Z).
    #[serde(default)]
    pub heading_deg: f64,
    /// Length, metres.
    pub length: f64,
    /// Carriageway width, metres.
    pub width: f64,
    /// Sidewalk width on each side, metres (0: none).
    #[serde(default = "default_sidewalk")]
    pub sidewalk_width: f64,
}

fn default_sidewalk() -> f64 {
    3.0
}

/// A static object standing on the ground.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PropSpec {
    /// Class (`Pole`, `TrafficSign`, `TrafficLight`, `Building`, `Vegetation`, `ConstructionObj`, …).
    pub class: ObjectClass,
    /// Ground position `[x, z]`.
    pub at: [f64; 2],
    /// `[h, w, l]`; a class default when omitted.
    #[serde(default)]
    pub size: Option<[f64; 3]>,
    /// Heading, degrees.
    #[serde(default)]
    pub heading_deg: f64,
    /// Colour value.
    #[serde(default)]
    pub color: Option<String>,
}

/// Perception noise applied to observations (not to the ground truth).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NoiseSpec {
    /// Standard deviation of lateral/vertical position noise, metres.
    pub position_sigma_m: f64,
    /// Standard deviation of depth noise as a fraction of depth.
    pub depth_sigma_fraction: f64,
    /// Standard deviation of box edge jitter, pixels.
    pub box_jitter_px: f64,
    /// Probability that an observation is dropped.
    pub miss_probability: f64,
    /// Probability per observation that the object's track id switches to a
    /// fresh id from then on.
    pub id_switch_probability: f64,
    /// Growth of the depth noise with distance: the depth's standard
    /// deviation is `depth_sigma_fraction + depth_sigma_per_m × depth` of
    /// the depth, so the absolute error grows faster than linearly, as a
    /// monocular depth estimate's does.
    pub depth_sigma_per_m: f64,
    /// Standard deviation of a per-track depth scale bias (a fraction),
    /// drawn once per object: a monocular size prior misjudges one car's
    /// size the same way in every frame.
    pub depth_bias_fraction: f64,
    /// Probability of a miss added per metre of depth.
    pub miss_per_m: f64,
    /// Probability of a miss added per unit of occluded box fraction (the
    /// share of the box covered by nearer objects' boxes).
    pub miss_per_occlusion: f64,
}

impl Default for NoiseSpec {
    fn default() -> Self {
        NoiseSpec {
            position_sigma_m: 0.1,
            depth_sigma_fraction: 0.01,
            box_jitter_px: 1.5,
            miss_probability: 0.02,
            id_switch_probability: 0.0,
            depth_sigma_per_m: 0.0,
            depth_bias_fraction: 0.0,
            miss_per_m: 0.0,
            miss_per_occlusion: 0.0,
        }
    }
}

/// The named noise levels of the noise study (`eval --noise LEVEL`).
///
/// A preset replaces a scenario's own `noise:`; [`NoisePreset::spec`] gives
/// the model it stands for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum NoisePreset {
    /// No noise: the simulator's ground truth (the oracle).
    None,
    /// σ 0.05 m, depth 0.5 %, 1 px boxes, 1 % misses.
    Low,
    /// [`NoiseSpec::default`]: σ 0.1 m, depth 1 %, 1.5 px, 2 % misses.
    Default,
    /// σ 0.3 m, depth 3 %, 4 px boxes, 10 % misses, 1 % id switches.
    High,
    /// A monocular camera: depth σ of 2 % plus 0.15 % per metre (3.5 % at
    /// 10 m, 6.5 % at 30 m; the shipped fused estimator's median error is
    /// 3.7 % within 30 m, `docs/benchmarks.md`) and a 3 % per-object scale
    /// bias; σ 0.15 m laterally, 3 px boxes; misses 2 % plus 0.25 % per
    /// metre (12 % at 40 m) plus half the occluded fraction; 0.5 % id
    /// switches.
    Mono,
}

impl NoisePreset {
    /// Every preset, from none to the noisiest.
    pub const ALL: [NoisePreset; 5] = [
        NoisePreset::None,
        NoisePreset::Low,
        NoisePreset::Default,
        NoisePreset::High,
        NoisePreset::Mono,
    ];

    /// The preset's name as written on the command line.
    pub fn name(self) -> &'static str {
        match self {
            NoisePreset::None => "none",
            NoisePreset::Low => "low",
            NoisePreset::Default => "default",
            NoisePreset::High => "high",
            NoisePreset::Mono => "mono",
        }
    }

    /// The noise model; `None` for no noise.
    pub fn spec(self) -> Option<NoiseSpec> {
        let zero = NoiseSpec {
            position_sigma_m: 0.0,
            depth_sigma_fraction: 0.0,
            box_jitter_px: 0.0,
            miss_probability: 0.0,
            ..NoiseSpec::default()
        };
        match self {
            NoisePreset::None => None,
            NoisePreset::Low => Some(NoiseSpec {
                position_sigma_m: 0.05,
                depth_sigma_fraction: 0.005,
                box_jitter_px: 1.0,
                miss_probability: 0.01,
                ..zero
            }),
            NoisePreset::Default => Some(NoiseSpec::default()),
            NoisePreset::High => Some(NoiseSpec {
                position_sigma_m: 0.3,
                depth_sigma_fraction: 0.03,
                box_jitter_px: 4.0,
                miss_probability: 0.1,
                id_switch_probability: 0.01,
                ..zero
            }),
            NoisePreset::Mono => Some(NoiseSpec {
                position_sigma_m: 0.15,
                depth_sigma_fraction: 0.02,
                depth_sigma_per_m: 0.0015,
                depth_bias_fraction: 0.03,
                box_jitter_px: 3.0,
                miss_probability: 0.02,
                miss_per_m: 0.0025,
                miss_per_occlusion: 0.5,
                id_switch_probability: 0.005,
            }),
        }
    }
}

impl std::fmt::Display for NoisePreset {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for NoisePreset {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        NoisePreset::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| {
                format!(
                    "unknown noise level `{s}`; expected one of {}",
                    NoisePreset::ALL.map(NoisePreset::name).join(", ")
                )
            })
    }
}

impl NoiseSpec {
    /// This model with every standard deviation (position, depth, its
    /// growth with distance, the per-track depth bias, box jitter)
    /// multiplied by `factor`; the miss and id-switch probabilities are
    /// rates, not spreads, and stay as they are.
    pub fn scaled(self, factor: f64) -> NoiseSpec {
        NoiseSpec {
            position_sigma_m: self.position_sigma_m * factor,
            depth_sigma_fraction: self.depth_sigma_fraction * factor,
            box_jitter_px: self.box_jitter_px * factor,
            depth_sigma_per_m: self.depth_sigma_per_m * factor,
            depth_bias_fraction: self.depth_bias_fraction * factor,
            ..self
        }
    }
}

/// A noise level of the noise study as written after `--noise`: a preset,
/// optionally with its sigmas scaled (`high*2`, for stress studies).
///
/// Invariant: `scale` is finite and positive, and `preset` is not
/// [`NoisePreset::None`] unless `scale` is 1 (there is no noise to scale).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseLevel {
    preset: NoisePreset,
    scale: f64,
}

/// Errors of reading a noise level.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum NoiseLevelError {
    /// Occurs when the name before `*` is not a preset.
    #[error("unknown noise level `{0}`; expected one of {list}, optionally scaled as NAME*K (high*2)", list = NoisePreset::ALL.map(NoisePreset::name).join(", "))]
    UnknownPreset(String),
    /// Occurs when the factor after `*` is not a positive finite number.
    #[error(
        "noise level `{0}`: the factor after `*` must be a positive finite number (high*2, mono*1.5)"
    )]
    BadFactor(String),
    /// Occurs when `none` is given a factor other than 1.
    #[error("noise level `{0}`: `none` has no noise to scale")]
    ScaledNone(String),
}

impl NoiseLevel {
    /// `preset` with its sigmas multiplied by `scale`.
    pub fn new(preset: NoisePreset, scale: f64) -> Result<NoiseLevel, NoiseLevelError> {
        let text = || format!("{preset}*{scale}");
        if !(scale.is_finite() && scale > 0.0) {
            return Err(NoiseLevelError::BadFactor(text()));
        }
        if preset == NoisePreset::None && scale != 1.0 {
            return Err(NoiseLevelError::ScaledNone(text()));
        }
        Ok(NoiseLevel { preset, scale })
    }

    /// The preset scaled.
    pub fn preset(self) -> NoisePreset {
        self.preset
    }

    /// The factor on the preset's sigmas (1 for the preset itself).
    pub fn scale(self) -> f64 {
        self.scale
    }

    /// The noise model; `None` for no noise.
    pub fn spec(self) -> Option<NoiseSpec> {
        self.preset.spec().map(|s| s.scaled(self.scale))
    }
}

impl From<NoisePreset> for NoiseLevel {
    fn from(preset: NoisePreset) -> Self {
        NoiseLevel { preset, scale: 1.0 }
    }
}

impl std::fmt::Display for NoiseLevel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.scale == 1.0 {
            write!(f, "{}", self.preset)
        } else {
            write!(f, "{}*{}", self.preset, self.scale)
        }
    }
}

impl std::str::FromStr for NoiseLevel {
    type Err = NoiseLevelError;

    /// `NAME` or `NAME*K`, `K` a positive finite number.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (name, factor) = match s.split_once('*') {
            Some((n, k)) => (n.trim(), Some(k.trim())),
            None => (s.trim(), None),
        };
        let preset: NoisePreset = name
            .parse()
            .map_err(|_| NoiseLevelError::UnknownPreset(name.to_string()))?;
        let Some(k) = factor else {
            return Ok(preset.into());
        };
        let scale: f64 = k
            .parse()
            .map_err(|_| NoiseLevelError::BadFactor(s.to_string()))?;
        NoiseLevel::new(preset, scale).map_err(|e| match e {
            NoiseLevelError::BadFactor(_) => NoiseLevelError::BadFactor(s.to_string()),
            NoiseLevelError::ScaledNone(_) => NoiseLevelError::ScaledNone(s.to_string()),
            other => other,
        })
    }
}

/// Default `[h, w, l]` of a class/type.
pub fn default_size(class: ObjectClass, type_name: Option<&str>) -> [f64; 3] {
    match (class, type_name) {
        (ObjectClass::Vehicle, Some("Van" | "Minivan")) => [2.0, 1.9, 4.8],
        (ObjectClass::Vehicle, Some("Truck")) => [3.2, 2.5, 8.0],
        (ObjectClass::Vehicle, Some("Bus" | "Tram")) => [3.2, 2.6, 12.0],
        (ObjectClass::Vehicle, Some("Motorcycle" | "Bicycle")) => [1.4, 0.8, 2.0],
        (ObjectClass::Vehicle, _) => [1.5, 1.7, 4.2],
        (ObjectClass::Pedestrian | ObjectClass::Person, _) => [1.75, 0.6, 0.6],
        (ObjectClass::Cyclist, _) => [1.7, 0.6, 1.8],
        (ObjectClass::Pole, _) => [6.0, 0.3, 0.3],
        (ObjectClass::TrafficSign, _) => [2.5, 0.7, 0.2],
        (ObjectClass::TrafficLight, _) => [4.0, 0.4, 0.4],
        (ObjectClass::Building, _) => [12.0, 10.0, 15.0],
        (ObjectClass::Vegetation, _) => [5.0, 3.0, 3.0],
        (ObjectClass::ConstructionObj, _) => [1.0, 0.5, 0.5],
        _ => [1.0, 1.0, 1.0],
    }
}

/// Names of the built-in scenarios.
pub const BUILTIN_NAMES: [&str; 7] = [
    "urban_crossing",
    "highway_merge",
    "parking_lot",
    "intersection",
    "braking",
    "pickup",
    "collision",
];

/// The YAML text of a built-in scenario.
pub fn builtin_text(name: &str) -> Option<&'static str> {
    Some(match name {
        "urban_crossing" => include_str!("../../scenarios/urban_crossing.yaml"),
        "highway_merge" => include_str!("../../scenarios/highway_merge.yaml"),
        "parking_lot" => include_str!("../../scenarios/parking_lot.yaml"),
        "intersection" => include_str!("../../scenarios/intersection.yaml"),
        "braking" => include_str!("../../scenarios/braking.yaml"),
        "pickup" => include_str!("../../scenarios/pickup.yaml"),
        "collision" => include_str!("../../scenarios/collision.yaml"),
        _ => return None,
    })
}

impl Scenario {
    /// A built-in scenario by name.
    pub fn builtin(name: &str) -> Result<Scenario, PerceptionError> {
        let text = builtin_text(name).ok_or_else(|| PerceptionError::Scenario {
            scenario: name.to_string(),
            message: format!(
                "no built-in scenario of that name (built in: {})",
                BUILTIN_NAMES.join(", ")
            ),
        })?;
        Scenario::from_yaml(text, &format!("built-in scenario {name}"))
    }

    /// Parses YAML; `origin` names the text in errors.
    pub fn from_yaml(text: &str, origin: &str) -> Result<Scenario, PerceptionError> {
        let s: Scenario = serde_saphyr::from_str(text).map_err(|e| PerceptionError::Yaml {
            origin: origin.to_string(),
            message: crate::error::yaml_message(&e, origin),
        })?;
        // Before `validate` (which names only the scenario), so the error
        // names the file.
        crate::model::check_frame_count("frames", s.frames)
            .and_then(|()| s.check_size())
            .map_err(|message| PerceptionError::Yaml {
                origin: origin.to_string(),
                message,
            })?;
        s.validate()?;
        Ok(s)
    }

    /// Parses JSON; `origin` names the text in errors.
    pub fn from_json(text: &str, origin: &str) -> Result<Scenario, PerceptionError> {
        let s: Scenario = serde_json::from_str(text).map_err(|e| PerceptionError::Json {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
        // As in `from_yaml`: the error names the file.
        crate::model::check_frame_count("frames", s.frames)
            .and_then(|()| s.check_size())
            .map_err(|message| PerceptionError::Json {
                origin: origin.to_string(),
                message,
            })?;
        s.validate()?;
        Ok(s)
    }

    /// Loads a `.yaml`/`.yml`/`.json` scenario file.
    pub fn load(path: &std::path::Path) -> Result<Scenario, PerceptionError> {
        crate::textfile::load_yaml_or_json(path, Scenario::from_json, Scenario::from_yaml)
    }

    /// Objects the scenario can put in a frame (see [`MAX_SCENARIO_OBJECTS`]).
    pub fn object_count(&self) -> usize {
        self.agents
            .len()
            .saturating_add(self.world.roads.len().saturating_mul(3))
            .saturating_add(self.world.props.len())
    }

    /// Checks [`MAX_SCENARIO_OBJECTS`] and [`MAX_SCENARIO_OBJECT_FRAMES`];
    /// the message names the counts and the limit, for the caller to wrap
    /// with the file or scenario.
    fn check_size(&self) -> Result<(), String> {
        let objects = self.object_count();
        if objects > MAX_SCENARIO_OBJECTS {
            return Err(format!(
                "{objects} objects ({} agents, {} roads × 3 with their sidewalks, {} props) exceed the limit of {MAX_SCENARIO_OBJECTS} objects per scenario (perception::sim::MAX_SCENARIO_OBJECTS)",
                self.agents.len(),
                self.world.roads.len(),
                self.world.props.len()
            ));
        }
        let object_frames = u64::from(self.frames).saturating_mul(objects as u64 + 1);
        if object_frames > MAX_SCENARIO_OBJECT_FRAMES {
            return Err(format!(
                "`frames` {} × ({objects} objects + the ego) = {object_frames} object-frames exceed the limit of {MAX_SCENARIO_OBJECT_FRAMES} (perception::sim::MAX_SCENARIO_OBJECT_FRAMES); shorten the scenario or remove objects",
                self.frames
            ));
        }
        Ok(())
    }

    /// Checks the documented invariants.
    pub fn validate(&self) -> Result<(), PerceptionError> {
        let bad = |message: String| {
            Err(PerceptionError::Scenario {
                scenario: self.name.clone(),
                message,
            })
        };
        // The name becomes file names (window ids, `simulate --out`): a
        // name like `../../x` wrote outside the output folder.
        let safe = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-';
        if self.name.is_empty() || self.name.len() > MAX_NAME_LEN || !self.name.chars().all(safe) {
            return bad(format!(
                "`name` must be 1 to {MAX_NAME_LEN} letters, digits, `_` or `-` (it names files), got {:?}",
                self.name.chars().take(MAX_NAME_LEN).collect::<String>()
            ));
        }
        if self.frames == 0 {
            return bad("`frames` must be positive".into());
        }
        if let Err(m) = crate::model::check_frame_count("frames", self.frames) {
            return bad(m);
        }
        if let Err(m) = self.check_size() {
            return bad(m);
        }
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return bad(format!("`fps` must be positive, got {}", self.fps));
        }
        self.camera.intrinsics.validate()?;
        let mut ids: Vec<u32> = self.agents.iter().map(|a| a.id).collect();
        ids.sort_unstable();
        if let Some(w) = ids.windows(2).find(|w| w[0] == w[1]) {
            return bad(format!("agent id {} is used twice", w[0]));
        }
        let vehicle = |id: u32| {
            self.agents
                .iter()
                .any(|a| a.id == id && a.class == ObjectClass::Vehicle)
        };
        let motions = std::iter::once(("ego".to_string(), self.ego.clone())).chain(
            self.agents
                .iter()
                .map(|a| (format!("agent {}", a.id), a.motion())),
        );
        for (who, m) in &motions.collect::<Vec<_>>() {
            let finite = m.start.iter().all(|v| v.is_finite())
                && m.heading_deg.is_finite()
                && m.speed.is_finite()
                && m.speed >= 0.0;
            if !finite {
                return bad(format!(
                    "{who}: start, heading and a non-negative speed must be finite numbers"
                ));
            }
            for p in &m.phases {
                if p.from >= p.to || p.to > self.frames {
                    return bad(format!(
                        "{who}: phase {}..{} must satisfy from < to <= frames ({})",
                        p.from, p.to, self.frames
                    ));
                }
                if p.accel.is_some() && p.speed_to.is_some() {
                    return bad(format!(
                        "{who}: phase {}..{} gives both `accel` and `speed_to`",
                        p.from, p.to
                    ));
                }
                if [p.accel, p.turn_deg]
                    .into_iter()
                    .flatten()
                    .any(|v| !v.is_finite())
                {
                    return bad(format!(
                        "{who}: phase {}..{} `accel` and `turn_deg` must be finite numbers",
                        p.from, p.to
                    ));
                }
                if p.speed_to.is_some_and(|v| !(v.is_finite() && v >= 0.0)) {
                    return bad(format!(
                        "{who}: phase {}..{} `speed_to` must be >= 0",
                        p.from, p.to
                    ));
                }
                for r in [p.enter, p.merge_into].into_iter().flatten() {
                    if !vehicle(r) {
                        return bad(format!(
                            "{who}: phase {}..{} refers to {r}, which is not a vehicle agent",
                            p.from, p.to
                        ));
                    }
                }
            }
        }
        for r in &self.world.roads {
            let finite = r
                .center
                .iter()
                .chain([&r.heading_deg])
                .all(|v| v.is_finite());
            if !(finite
                && r.length.is_finite()
                && r.width.is_finite()
                && r.sidewalk_width.is_finite()
                && r.length > 0.0
                && r.width > 0.0
                && r.sidewalk_width >= 0.0)
            {
                return bad(
                    "roads need a finite centre and heading, a positive length and width and a non-negative sidewalk width"
                        .into(),
                );
            }
        }
        // A NaN or non-positive size or place would not fail later: it
        // would silently turn into boxes that are never seen or never touch.
        let size_ok = |size: Option<[f64; 3]>| {
            size.is_none_or(|s| s.iter().all(|v| v.is_finite() && *v > 0.0))
        };
        for a in &self.agents {
            if !size_ok(a.size) {
                return bad(format!(
                    "agent {}: `size` must be three positive numbers",
                    a.id
                ));
            }
        }
        for (i, p) in self.world.props.iter().enumerate() {
            let finite = p.at.iter().chain([&p.heading_deg]).all(|v| v.is_finite());
            if !(finite && size_ok(p.size)) {
                return bad(format!(
                    "world.props[{i}]: `at` and `heading_deg` must be finite and `size` three positive numbers"
                ));
            }
        }
        let v = &self.view;
        if !(v.min_depth_m.is_finite()
            && v.min_depth_m > 0.0
            && v.max_depth_m.is_finite()
            && v.max_depth_m > v.min_depth_m
            && v.min_box_px.is_finite()
            && v.min_box_px >= 0.0)
        {
            return bad(format!(
                "view needs 0 < min_depth_m < max_depth_m and min_box_px >= 0, got min_depth_m {}, max_depth_m {}, min_box_px {}",
                v.min_depth_m, v.max_depth_m, v.min_box_px
            ));
        }
        if let Some(n) = &self.noise {
            let sigmas = [
                n.position_sigma_m,
                n.depth_sigma_fraction,
                n.box_jitter_px,
                n.depth_sigma_per_m,
                n.depth_bias_fraction,
                n.miss_per_m,
                n.miss_per_occlusion,
            ];
            let probabilities = [n.miss_probability, n.id_switch_probability];
            if !(sigmas.iter().all(|v| v.is_finite() && *v >= 0.0)
                && probabilities.iter().all(|v| (0.0..=1.0).contains(v)))
            {
                return bad(format!(
                    "noise needs finite non-negative sigmas and rates and probabilities in [0, 1], got position_sigma_m {}, depth_sigma_fraction {}, box_jitter_px {}, miss_probability {}, id_switch_probability {}, depth_sigma_per_m {}, depth_bias_fraction {}, miss_per_m {}, miss_per_occlusion {}",
                    n.position_sigma_m,
                    n.depth_sigma_fraction,
                    n.box_jitter_px,
                    n.miss_probability,
                    n.id_switch_probability,
                    n.depth_sigma_per_m,
                    n.depth_bias_fraction,
                    n.miss_per_m,
                    n.miss_per_occlusion
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
