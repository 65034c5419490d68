//! The perception data model shared by every source (KITTI labels, JSON
//! tracks, the simulator, the raw-frames pipeline): a [`Sequence`] of
//! per-frame [`Observation`]s seen by one calibrated camera, cut into windows
//! by a [`WindowSpec`], each window yielding [`WindowFacts`] — positive facts
//! with [`Provenance`].
//!
//! Coordinates follow KITTI's rectified camera: X right, Y down, Z forward,
//! metres. The simulator's world frame shares the Y axis (down) with the
//! camera, the ground plane is `Y = 0` and the camera sits at `Y = -height_m`.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

use crate::error::PerceptionError;

/// Pinhole intrinsics of the (rectified) camera plus the image size.
///
/// Invariant: `fx`, `fy` > 0; `image_width`, `image_height` > 0.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraIntrinsics {
    /// Focal length in pixels along x.
    pub fx: f64,
    /// Focal length in pixels along y.
    pub fy: f64,
    /// Principal point x, pixels.
    pub cx: f64,
    /// Principal point y, pixels.
    pub cy: f64,
    /// Image width in pixels.
    pub image_width: u32,
    /// Image height in pixels.
    pub image_height: u32,
}

impl CameraIntrinsics {
    /// Projects a camera-frame point to pixel coordinates; `None` when the
    /// point is not in front of the camera (`Z <= min_depth`).
    pub fn project(&self, p: [f64; 3], min_depth: f64) -> Option<[f64; 2]> {
        if p[2] <= min_depth || !p.iter().all(|v| v.is_finite()) {
            return None;
        }
        Some([
            self.fx * p[0] / p[2] + self.cx,
            self.fy * p[1] / p[2] + self.cy,
        ])
    }

    /// Back-projects pixel `(u, v)` at depth `z` (metres along the optical
    /// axis) into camera coordinates.
    pub fn back_project(&self, u: f64, v: f64, z: f64) -> [f64; 3] {
        [(u - self.cx) * z / self.fx, (v - self.cy) * z / self.fy, z]
    }

    /// Horizontal field of view in radians.
    pub fn horizontal_fov(&self) -> f64 {
        2.0 * (f64::from(self.image_width) / (2.0 * self.fx)).atan()
    }

    /// Checks the documented invariant.
    pub fn validate(&self) -> Result<(), PerceptionError> {
        let ok = self.fx.is_finite()
            && self.fy.is_finite()
            && self.cx.is_finite()
            && self.cy.is_finite()
            && self.fx > 0.0
            && self.fy > 0.0
            && self.image_width > 0
            && self.image_height > 0;
        if ok {
            Ok(())
        } else {
            Err(PerceptionError::InvalidConfig {
                field: "camera.intrinsics".into(),
                message: format!(
                    "focal lengths and image size must be positive and finite, got {self:?}"
                ),
            })
        }
    }
}

/// A calibrated camera mounted on the ego vehicle.
///
/// Invariant: `height_m` > 0 and the intrinsics are valid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraConfig {
    /// Intrinsics (KITTI: from the calib file's `P2`).
    pub intrinsics: CameraIntrinsics,
    /// Height of the optical centre above the flat ground, metres.
    pub height_m: f64,
}

/// An axis-aligned image box in pixels.
///
/// Invariant: `left <= right`, `top <= bottom`, all finite.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BBox2D {
    /// Left edge, pixels.
    pub left: f64,
    /// Top edge, pixels.
    pub top: f64,
    /// Right edge, pixels.
    pub right: f64,
    /// Bottom edge, pixels.
    pub bottom: f64,
}

impl BBox2D {
    /// The smallest box enclosing image points `[u, v]`; `None` without
    /// points.
    pub fn enclosing(points: impl IntoIterator<Item = [f64; 2]>) -> Option<BBox2D> {
        let mut it = points.into_iter();
        let [u, v] = it.next()?;
        let first = BBox2D {
            left: u,
            top: v,
            right: u,
            bottom: v,
        };
        Some(it.fold(first, |b, [u, v]| BBox2D {
            left: b.left.min(u),
            top: b.top.min(v),
            right: b.right.max(u),
            bottom: b.bottom.max(v),
        }))
    }

    /// Box width in pixels.
    pub fn width(&self) -> f64 {
        self.right - self.left
    }
    /// Box height in pixels.
    pub fn height(&self) -> f64 {
        self.bottom - self.top
    }
    /// Horizontal centre, pixels.
    pub fn center_x(&self) -> f64 {
        0.5 * (self.left + self.right)
    }
    /// Area in square pixels.
    pub fn area(&self) -> f64 {
        self.width().max(0.0) * self.height().max(0.0)
    }
    /// Intersection over union with another box (0 when disjoint).
    pub fn iou(&self, other: &BBox2D) -> f64 {
        let w = (self.right.min(other.right) - self.left.max(other.left)).max(0.0);
        let h = (self.bottom.min(other.bottom) - self.top.max(other.top)).max(0.0);
        let inter = w * h;
        let union = self.area() + other.area() - inter;
        if union > 0.0 { inter / union } else { 0.0 }
    }
    /// Clips the box to an image; `None` when nothing of it is inside.
    pub fn clip(&self, width: u32, height: u32) -> Option<BBox2D> {
        let b = BBox2D {
            left: self.left.max(0.0),
            top: self.top.max(0.0),
            right: self.right.min(f64::from(width) - 1.0),
            bottom: self.bottom.min(f64::from(height) - 1.0),
        };
        (b.left < b.right && b.top < b.bottom).then_some(b)
    }
    /// Whether the box satisfies its invariant.
    pub fn is_valid(&self) -> bool {
        [self.left, self.top, self.right, self.bottom]
            .iter()
            .all(|v| v.is_finite())
            && self.left <= self.right
            && self.top <= self.bottom
    }
}

/// Semantic class of an object; maps one-to-one onto a LogicPad class
/// predicate (see [`ObjectClass::predicate`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum ObjectClass {
    /// Any motor vehicle or tram (predicate `Vehicles`).
    #[serde(rename = "Vehicles", alias = "Vehicle")]
    Vehicle,
    /// A person on foot.
    Pedestrian,
    /// A sitting person (KITTI `Person_sitting`).
    Person,
    /// A person riding a bicycle.
    Cyclist,
    /// KITTI `Misc` (trailers, segways, …).
    Misc,
    /// Drivable road surface.
    Road,
    /// Sidewalk surface.
    Sidewalk,
    /// Painted lane marking.
    LaneMarking,
    /// Pole.
    Pole,
    /// Traffic sign.
    TrafficSign,
    /// Traffic light.
    TrafficLight,
    /// Building.
    Building,
    /// Trees, bushes.
    Vegetation,
    /// Fence.
    Fence,
    /// Wall.
    Wall,
    /// Terrain (grass, soil).
    Terrain,
    /// Construction object (barrier, cone).
    ConstructionObj,
    /// Anything else.
    Other,
}

impl ObjectClass {
    /// Every class, in declaration order.
    pub const ALL: [ObjectClass; 18] = [
        ObjectClass::Vehicle,
        ObjectClass::Pedestrian,
        ObjectClass::Person,
        ObjectClass::Cyclist,
        ObjectClass::Misc,
        ObjectClass::Road,
        ObjectClass::Sidewalk,
        ObjectClass::LaneMarking,
        ObjectClass::Pole,
        ObjectClass::TrafficSign,
        ObjectClass::TrafficLight,
        ObjectClass::Building,
        ObjectClass::Vegetation,
        ObjectClass::Fence,
        ObjectClass::Wall,
        ObjectClass::Terrain,
        ObjectClass::ConstructionObj,
        ObjectClass::Other,
    ];

    /// The LogicPad class predicate, e.g. `"Vehicles"`.
    pub const fn predicate(&self) -> &'static str {
        match self {
            ObjectClass::Vehicle => "Vehicles",
            ObjectClass::Pedestrian => "Pedestrian",
            ObjectClass::Person => "Person",
            ObjectClass::Cyclist => "Cyclist",
            ObjectClass::Misc => "Misc",
            ObjectClass::Road => "Road",
            ObjectClass::Sidewalk => "Sidewalk",
            ObjectClass::LaneMarking => "LaneMarking",
            ObjectClass::Pole => "Pole",
            ObjectClass::TrafficSign => "TrafficSign",
            ObjectClass::TrafficLight => "TrafficLight",
            ObjectClass::Building => "Building",
            ObjectClass::Vegetation => "Vegetation",
            ObjectClass::Fence => "Fence",
            ObjectClass::Wall => "Wall",
            ObjectClass::Terrain => "Terrain",
            ObjectClass::ConstructionObj => "ConstructionObj",
            ObjectClass::Other => "Other",
        }
    }

    /// Parses a class predicate (or the variant name) back into a class.
    pub fn from_predicate(name: &str) -> Option<ObjectClass> {
        if name == "Vehicle" {
            return Some(ObjectClass::Vehicle);
        }
        ObjectClass::ALL
            .iter()
            .copied()
            .find(|c| c.predicate() == name)
    }

    /// Whether objects of this class never move (scene structure); static
    /// objects are ego-motion anchors and are never `Moving`.
    pub fn is_static(&self) -> bool {
        !matches!(
            self,
            ObjectClass::Vehicle
                | ObjectClass::Pedestrian
                | ObjectClass::Person
                | ObjectClass::Cyclist
                | ObjectClass::Misc
                | ObjectClass::Other
        )
    }

    /// Whether the class is a region of the ground (road, sidewalk, lane
    /// marking, terrain) rather than an object with one position: its box
    /// centre or ground point says nothing about where the region lies, so
    /// relations between positions (`LeftOf`, `InFrontOf`, …) skip it even
    /// when a source gives it no footprint.
    pub fn is_ground_surface(&self) -> bool {
        matches!(
            self,
            ObjectClass::Road
                | ObjectClass::Sidewalk
                | ObjectClass::LaneMarking
                | ObjectClass::Terrain
        )
    }

    /// Whether the class is a road user that can walk (pedestrian-like).
    pub fn is_person_like(&self) -> bool {
        matches!(self, ObjectClass::Pedestrian | ObjectClass::Person)
    }

    /// Lower snake case kind used in object names when no type is known.
    pub fn kind(&self) -> &'static str {
        match self {
            ObjectClass::Vehicle => "vehicle",
            ObjectClass::Pedestrian => "pedestrian",
            ObjectClass::Person => "person",
            ObjectClass::Cyclist => "cyclist",
            ObjectClass::Misc => "misc",
            ObjectClass::Road => "road",
            ObjectClass::Sidewalk => "sidewalk",
            ObjectClass::LaneMarking => "lane_marking",
            ObjectClass::Pole => "pole",
            ObjectClass::TrafficSign => "traffic_sign",
            ObjectClass::TrafficLight => "traffic_light",
            ObjectClass::Building => "building",
            ObjectClass::Vegetation => "vegetation",
            ObjectClass::Fence => "fence",
            ObjectClass::Wall => "wall",
            ObjectClass::Terrain => "terrain",
            ObjectClass::ConstructionObj => "construction_obj",
            ObjectClass::Other => "other",
        }
    }
}

/// One object seen in one frame.
///
/// Invariant: `bbox` is valid; `position`, `size`, `yaw` are finite when
/// present; `confidence` in `[0, 1]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Observation {
    /// Frame index (0-based).
    pub frame: u32,
    /// Track identity, stable over the object's life.
    pub track_id: u32,
    /// Semantic class.
    pub class: ObjectClass,
    /// `TypeOf` value, e.g. `"Car"`, `"Van"`, `"Motorcycle"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub type_name: Option<String>,
    /// `ColorOf` value when the source knows it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color: Option<String>,
    /// 2D box in the image, pixels.
    pub bbox: BBox2D,
    /// Bottom-centre of the 3D box in camera coordinates (KITTI
    /// `location`), metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub position: Option<[f64; 3]>,
    /// 3D size `[h, w, l]`, metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size: Option<[f64; 3]>,
    /// Rotation about the camera Y axis (KITTI `rotation_y`), radians.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yaw: Option<f64>,
    /// Detection confidence; 1 for ground truth.
    #[serde(default = "default_confidence")]
    pub confidence: f32,
    /// KITTI truncation in `[0, 1]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub truncation: Option<f32>,
    /// KITTI occlusion level 0–3.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub occlusion: Option<u8>,
    /// For ground-surface classes (road, sidewalk, terrain, lane marking):
    /// the visible surface as a polygon `[X, Z]` on the bird's-eye plane in
    /// this frame's camera coordinates. `On(x, y)` tests object positions
    /// against it, so it needs no ego-motion.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub footprint: Option<Vec<[f64; 2]>>,
    /// How `position` was estimated when it is not the source's own
    /// measurement (raw frames: depth model, flat ground, size prior or
    /// their fusion); `None` for labels, JSON tracks and the simulator.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub depth_source: Option<DepthSource>,
}

/// Which estimator gave an observation's 3D position (provenance).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DepthSource {
    /// A metric depth model's map, sampled inside the box (the near
    /// surface), plus the type's nearest-face → centre offset.
    DepthMap,
    /// The box bottom on a flat ground plane at the camera's height.
    FlatGround,
    /// The box height against the class's prior height.
    SizePrior,
    /// Inverse-variance fusion of flat ground and the size prior.
    Fused,
    /// A relative depth model's map, sampled inside the box and fitted
    /// per frame onto the monocular near-face depths (scale, or scale and
    /// shift for inverse depth; `raw::relative`), plus the type's
    /// nearest-face → centre offset.
    RelativeAligned,
}

fn default_confidence() -> f32 {
    1.0
}

/// All observations of one object, sorted by frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Track {
    /// Track identity.
    pub track_id: u32,
    /// Stable object constant, e.g. `car_3`.
    pub name: String,
    /// Class of the first observation.
    pub class: ObjectClass,
    /// Type of the first observation that has one.
    pub type_name: Option<String>,
    /// Colour of the first observation that has one.
    pub color: Option<String>,
    /// Observations sorted by frame, one per frame.
    pub observations: Vec<Observation>,
}

impl Track {
    /// First frame the object is seen.
    pub fn first_frame(&self) -> Option<u32> {
        self.observations.first().map(|o| o.frame)
    }
    /// Last frame the object is seen.
    pub fn last_frame(&self) -> Option<u32> {
        self.observations.last().map(|o| o.frame)
    }
}

/// A sequence of frames seen by one camera.
///
/// Invariant (checked by [`Sequence::validate`]): observations are sorted by
/// `(frame, track_id)` with no duplicate pair, every `frame < frame_count`,
/// `frame_count <= MAX_FRAMES`, every box valid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sequence {
    /// Name used in provenance, e.g. `"0000"` or `"urban_crossing"`.
    pub name: String,
    /// Source prefix used in provenance, e.g. `"kitti"`, `"sim"`, `"json"`.
    #[serde(default = "default_source_kind")]
    pub source: String,
    /// The camera.
    pub camera: CameraConfig,
    /// Number of frames (frames without any observation count too).
    pub frame_count: u32,
    /// Frame rate in frames per second (KITTI: 10).
    #[serde(default = "default_fps")]
    pub fps: f64,
    /// Observations sorted by `(frame, track_id)`.
    pub observations: Vec<Observation>,
}

fn default_source_kind() -> String {
    "json".to_string()
}

/// KITTI's frame rate; also the default for JSON tracks that omit `fps`.
pub const DEFAULT_FPS: f64 = 10.0;

/// Most frames a sequence (`frame_count`) or a scenario (`frames`) may have.
///
/// Per-frame state (ego poses, window spans, simulator histories) is
/// allocated for every frame up front, so an untrusted count near
/// `u32::MAX` would exhaust memory before anything could fail. One million
/// is far beyond real inputs — KITTI tracking sequences have at most about
/// 1,100 frames and an hour of video at 30 fps is 108,000 — while every
/// per-frame allocation stays in the tens of megabytes.
pub const MAX_FRAMES: u32 = 1_000_000;

/// Checks a frame count against [`MAX_FRAMES`]; the error message names
/// `field` (`frame_count`, `frames`, …), the value and the limit, for the
/// caller to wrap with the file or scenario it came from.
pub fn check_frame_count(field: &str, frames: u32) -> Result<(), String> {
    if frames > MAX_FRAMES {
        return Err(format!(
            "`{field}` {frames} exceeds the limit of {MAX_FRAMES} frames (perception::MAX_FRAMES)"
        ));
    }
    Ok(())
}

fn default_fps() -> f64 {
    DEFAULT_FPS
}

impl Sequence {
    /// `"<source>:<name>"`, used as provenance source.
    pub fn source_label(&self) -> String {
        format!("{}:{}", self.source, self.name)
    }

    /// Sorts observations into the invariant order (stable for equal keys,
    /// which [`Sequence::validate`] then reports as duplicates).
    pub fn sort(&mut self) {
        self.observations.sort_by_key(|o| (o.frame, o.track_id));
    }

    /// Checks the documented invariants.
    pub fn validate(&self) -> Result<(), PerceptionError> {
        check_frame_count("frame_count", self.frame_count)
            .map_err(|m| PerceptionError::invalid_sequence(&self.name, m))?;
        self.camera.intrinsics.validate()?;
        if !(self.camera.height_m.is_finite() && self.camera.height_m > 0.0) {
            return Err(PerceptionError::invalid_sequence(
                &self.name,
                format!(
                    "camera height must be positive, got {}",
                    self.camera.height_m
                ),
            ));
        }
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(PerceptionError::invalid_sequence(
                &self.name,
                format!("fps must be positive, got {}", self.fps),
            ));
        }
        let mut prev: Option<(u32, u32)> = None;
        for (i, o) in self.observations.iter().enumerate() {
            let key = (o.frame, o.track_id);
            if let Some(p) = prev
                && key <= p
            {
                return Err(PerceptionError::invalid_sequence(
                    &self.name,
                    format!(
                        "observation {i} (frame {}, track {}) is out of order or duplicated",
                        o.frame, o.track_id
                    ),
                ));
            }
            prev = Some(key);
            if o.frame >= self.frame_count {
                return Err(PerceptionError::invalid_sequence(
                    &self.name,
                    format!(
                        "observation {i} has frame {} >= frame_count {}",
                        o.frame, self.frame_count
                    ),
                ));
            }
            if !o.bbox.is_valid() {
                return Err(PerceptionError::invalid_sequence(
                    &self.name,
                    format!(
                        "observation {i} (frame {}, track {}) has an invalid box {:?}",
                        o.frame, o.track_id, o.bbox
                    ),
                ));
            }
            let finite = o.position.is_none_or(|p| p.iter().all(|v| v.is_finite()))
                && o.size.is_none_or(|p| p.iter().all(|v| v.is_finite()))
                && o.yaw.is_none_or(f64::is_finite);
            if !finite {
                return Err(PerceptionError::invalid_sequence(
                    &self.name,
                    format!(
                        "observation {i} (frame {}, track {}) has non-finite 3D values",
                        o.frame, o.track_id
                    ),
                ));
            }
        }
        Ok(())
    }

    /// Groups observations into tracks, sorted by track id.
    pub fn tracks(&self) -> Vec<Track> {
        let mut by_id: BTreeMap<u32, Vec<Observation>> = BTreeMap::new();
        for o in &self.observations {
            by_id.entry(o.track_id).or_default().push(o.clone());
        }
        by_id
            .into_iter()
            .filter_map(|(track_id, mut observations)| {
                observations.sort_by_key(|o| o.frame);
                let first = observations.first()?;
                let class = first.class;
                let type_name = observations.iter().find_map(|o| o.type_name.clone());
                let color = observations.iter().find_map(|o| o.color.clone());
                let name = object_name_for(type_name.as_deref(), class, track_id);
                Some(Track {
                    track_id,
                    name,
                    class,
                    type_name,
                    color,
                    observations,
                })
            })
            .collect()
    }

    /// Stable object constant for a track, e.g. `car_3`; `object_<id>` when
    /// the track id does not occur.
    pub fn object_name(&self, track_id: u32) -> String {
        let mut class = None;
        let mut type_name = None;
        for o in self.observations.iter().filter(|o| o.track_id == track_id) {
            class.get_or_insert(o.class);
            if type_name.is_none() {
                type_name = o.type_name.as_deref();
            }
        }
        match class {
            Some(c) => object_name_for(type_name, c, track_id),
            None => format!("object_{track_id}"),
        }
    }
}

/// The object constant `<kind>_<id>`: kind is the type lower-cased into snake
/// case (`PoliceCar` → `police_car`, KITTI `Person_sitting` → `person`) or
/// the class kind when no type is known.
pub fn object_name_for(type_name: Option<&str>, class: ObjectClass, track_id: u32) -> String {
    let kind = match type_name {
        Some(t) if !t.trim().is_empty() => type_kind(t),
        _ => class.kind().to_string(),
    };
    format!("{kind}_{track_id}")
}

fn type_kind(t: &str) -> String {
    // KITTI spells sitting people `Person_sitting`; the vocabulary calls them
    // `person`.
    if t.eq_ignore_ascii_case("person_sitting") {
        return "person".to_string();
    }
    let mut out = String::with_capacity(t.len() + 4);
    let chars: Vec<char> = t.chars().collect();
    for (i, &c) in chars.iter().enumerate() {
        if c.is_ascii_alphanumeric() {
            if c.is_ascii_uppercase() && i > 0 {
                let prev = chars[i - 1];
                let next_lower = chars.get(i + 1).is_some_and(|n| n.is_ascii_lowercase());
                if (prev.is_ascii_lowercase() || (prev.is_ascii_uppercase() && next_lower))
                    && !out.ends_with('_')
                {
                    out.push('_');
                }
            }
            out.push(c.to_ascii_lowercase());
        } else if !out.is_empty() && !out.ends_with('_') {
            out.push('_');
        }
    }
    let trimmed = out.trim_end_matches('_');
    if trimmed.is_empty() {
        "object".to_string()
    } else {
        trimmed.to_string()
    }
}

/// How a sequence is cut into windows: windows start at `0, stride,
/// 2·stride, …` and span `size` frames. `size = stride = 10` reproduces the
/// paper; `stride < size` gives overlapping windows.
///
/// Invariant: `size > 0`, `stride > 0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct WindowSpec {
    /// Frames per window.
    pub size: u32,
    /// Frames between window starts.
    pub stride: u32,
}

impl Default for WindowSpec {
    fn default() -> Self {
        WindowSpec {
            size: 10,
            stride: 10,
        }
    }
}

impl WindowSpec {
    /// The paper's setting: 10-frame non-overlapping windows.
    pub const PAPER: WindowSpec = WindowSpec {
        size: 10,
        stride: 10,
    };

    /// The windows `(index, first_frame, last_frame)` (inclusive) over
    /// `frame_count` frames. The last window is clipped to the sequence; a
    /// window that would only repeat the tail already covered by the previous
    /// one is not produced.
    pub fn windows(&self, frame_count: u32) -> Result<Vec<(u32, u32, u32)>, PerceptionError> {
        if self.size == 0 || self.stride == 0 {
            return Err(PerceptionError::InvalidWindow(format!(
                "size and stride must be positive, got size {} stride {}",
                self.size, self.stride
            )));
        }
        let mut out = Vec::new();
        let mut start = 0u32;
        let mut index = 0u32;
        while start < frame_count {
            let last = start.saturating_add(self.size - 1).min(frame_count - 1);
            out.push((index, start, last));
            if last == frame_count - 1 {
                break;
            }
            index += 1;
            start = start.saturating_add(self.stride);
        }
        Ok(out)
    }
}

/// Where a fact came from and why it holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// Window index.
    pub window: u32,
    /// Inclusive frame range of the window.
    pub frames: (u32, u32),
    /// `"kitti:0000"`, `"sim:urban_crossing"`, …
    pub source: String,
    /// The measured value compared with the threshold, when there is one.
    pub measured: Option<f64>,
    /// `(FactConfig field name, value)` the measurement was compared with.
    pub threshold: Option<(String, f64)>,
    /// Short human sentence, e.g. `"mean speed 3.2 m/s > moving_speed_vehicle 0.7 m/s"`.
    pub note: String,
}

/// A positive ground fact `predicate(args…)` with its provenance.
///
/// Ordering and equality used for sorting and deduplication consider only
/// `(predicate, args)`; see [`Fact::key`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fact {
    /// Predicate name, e.g. `"Moving"`.
    pub predicate: String,
    /// Constant arguments, e.g. `["car_3"]`.
    pub args: Vec<String>,
    /// Why the fact holds.
    pub provenance: Provenance,
}

impl Fact {
    /// The sort and deduplication key.
    pub fn key(&self) -> (&str, &[String]) {
        (&self.predicate, &self.args)
    }

    /// The fact in the reference KB syntax, e.g. `TypeOf(car_3, Car)`.
    pub fn to_kb_line(&self) -> String {
        format!("{}({})", self.predicate, self.args.join(", "))
    }
}

/// The facts of one window.
///
/// Invariant: `facts` sorted by [`Fact::key`] with no duplicate key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WindowFacts {
    /// Window index.
    pub index: u32,
    /// First frame (inclusive).
    pub first_frame: u32,
    /// Last frame (inclusive).
    pub last_frame: u32,
    /// Sorted, deduplicated facts.
    pub facts: Vec<Fact>,
}

impl WindowFacts {
    /// Sorts by key and keeps the first fact of each key.
    pub fn normalize(&mut self) {
        self.facts.sort_by(|a, b| a.key().cmp(&b.key()));
        self.facts.dedup_by(|a, b| a.key() == b.key());
    }

    /// The text KB, one `Pred(a, b)` per line, sorted.
    pub fn to_kb(&self) -> String {
        let mut s = String::new();
        for f in &self.facts {
            s.push_str(&f.to_kb_line());
            s.push('\n');
        }
        s
    }

    /// The facts as relation tables: predicate → sorted argument tuples.
    pub fn relation_tables(&self) -> BTreeMap<String, Vec<Vec<String>>> {
        let mut out: BTreeMap<String, Vec<Vec<String>>> = BTreeMap::new();
        for f in &self.facts {
            out.entry(f.predicate.clone())
                .or_default()
                .push(f.args.clone());
        }
        out
    }

    /// Whether the window holds `predicate(args…)`.
    pub fn contains(&self, predicate: &str, args: &[&str]) -> bool {
        self.facts.iter().any(|f| {
            f.predicate == predicate
                && f.args.len() == args.len()
                && f.args.iter().zip(args).all(|(a, b)| a == b)
        })
    }
}

/// Camera pose in the world frame: position of the optical centre and heading
/// `yaw` (rotation about the shared down-pointing Y axis). The camera's
/// forward axis in the world is `(sin yaw, 0, cos yaw)` and its right axis
/// `(cos yaw, 0, -sin yaw)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CameraPose {
    /// Optical centre in world coordinates (Y down, so `y = -height`).
    pub position: [f64; 3],
    /// Heading, radians.
    pub yaw: f64,
}

impl CameraPose {
    /// World point → camera coordinates.
    pub fn world_to_camera(&self, p: [f64; 3]) -> [f64; 3] {
        let (s, c) = self.yaw.sin_cos();
        let d = [
            p[0] - self.position[0],
            p[1] - self.position[1],
            p[2] - self.position[2],
        ];
        // Camera axes expressed in the world: right (c, 0, -s), down (0,1,0), forward (s, 0, c).
        [c * d[0] - s * d[2], d[1], s * d[0] + c * d[2]]
    }

    /// Camera point → world coordinates.
    pub fn camera_to_world(&self, p: [f64; 3]) -> [f64; 3] {
        let (s, c) = self.yaw.sin_cos();
        [
            self.position[0] + c * p[0] + s * p[2],
            self.position[1] + p[1],
            self.position[2] - s * p[0] + c * p[2],
        ]
    }
}

/// An oriented 3D box: bottom-centre on its supporting surface, size
/// `[h, w, l]`, yaw about the Y axis (KITTI convention: yaw 0 faces +X).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Box3D {
    /// Bottom-centre, metres.
    pub center: [f64; 3],
    /// `[h, w, l]`, metres.
    pub size: [f64; 3],
    /// Heading, radians.
    pub yaw: f64,
}

impl Box3D {
    /// The 8 corners: bottom four then top four (Y down, so top has `y - h`).
    pub fn corners(&self) -> [[f64; 3]; 8] {
        let [h, w, l] = self.size;
        let (s, c) = self.yaw.sin_cos();
        let mut out = [[0.0; 3]; 8];
        let local = [
            (l / 2.0, w / 2.0),
            (l / 2.0, -w / 2.0),
            (-l / 2.0, -w / 2.0),
            (-l / 2.0, w / 2.0),
        ];
        for (k, (dx, dz)) in local.iter().enumerate() {
            // Heading direction (c, 0, -s), lateral direction (s, 0, c).
            let x = self.center[0] + c * dx + s * dz;
            let z = self.center[2] - s * dx + c * dz;
            out[k] = [x, self.center[1], z];
            out[k + 4] = [x, self.center[1] - h, z];
        }
        out
    }
}

/// A dynamic object's state in one simulated frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneObject {
    /// Track id (after any simulated id switch, this is the true id).
    pub track_id: u32,
    /// Object constant, e.g. `car_3`.
    pub name: String,
    /// Class.
    pub class: ObjectClass,
    /// Type value, e.g. `Car`.
    pub type_name: Option<String>,
    /// Colour value, e.g. `White`.
    pub color: Option<String>,
    /// Box in world coordinates.
    pub world: Box3D,
    /// Box in camera coordinates.
    pub camera: Box3D,
    /// Projected 2D box clipped to the image; `None` when not in view.
    pub bbox: Option<BBox2D>,
    /// Whether the camera observes the object in this frame.
    pub visible: bool,
}

/// Shape of a static world element.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum StaticShape {
    /// A polygon on the flat ground (`Y = 0`), vertices `[x, z]` in world
    /// coordinates, counter-clockwise seen from above.
    Ground {
        /// Vertices `[x, z]`.
        polygon: Vec<[f64; 2]>,
    },
    /// A solid box standing on the ground (world coordinates).
    Solid(Box3D),
}

/// A static element of the simulated world (road, sidewalk, pole, …).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StaticElement {
    /// Track id (unique across dynamic and static objects).
    pub id: u32,
    /// Object constant, e.g. `road_0`.
    pub name: String,
    /// Class.
    pub class: ObjectClass,
    /// Geometry.
    pub shape: StaticShape,
    /// Colour, when meaningful.
    pub color: Option<String>,
}

/// Everything needed to render one simulated frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SceneState {
    /// Frame index.
    pub frame: u32,
    /// Camera pose in the world.
    pub camera_pose: CameraPose,
    /// Camera calibration.
    pub camera: CameraConfig,
    /// Dynamic objects (visible or not), sorted by track id.
    pub objects: Vec<SceneObject>,
    /// The static world (same in every frame).
    pub statics: std::sync::Arc<Vec<StaticElement>>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn object_names_are_snake_case() {
        assert_eq!(
            object_name_for(Some("Car"), ObjectClass::Vehicle, 3),
            "car_3"
        );
        assert_eq!(
            object_name_for(Some("Person_sitting"), ObjectClass::Person, 4),
            "person_4"
        );
        assert_eq!(
            object_name_for(Some("PoliceCar"), ObjectClass::Vehicle, 1),
            "police_car_1"
        );
        assert_eq!(
            object_name_for(Some("SUV"), ObjectClass::Vehicle, 2),
            "suv_2"
        );
        assert_eq!(
            object_name_for(None, ObjectClass::TrafficSign, 7),
            "traffic_sign_7"
        );
    }

    #[test]
    fn a_frame_count_beyond_max_frames_fails_validation_before_anything_is_sized() {
        // Regression: window_facts sized its window spans, then ego poses,
        // by an unchecked frame_count; near u32::MAX that exhausted memory.
        let mut seq = Sequence {
            name: "huge".into(),
            source: "test".into(),
            camera: crate::kitti::KITTI_2011_09_26_CAMERA,
            frame_count: u32::MAX,
            fps: DEFAULT_FPS,
            observations: Vec::new(),
        };
        let config = crate::FactConfig::default();
        for n in [u32::MAX, MAX_FRAMES + 1] {
            seq.frame_count = n;
            let e = seq.validate().unwrap_err().to_string();
            assert!(
                e.contains("sequence huge")
                    && e.contains(&format!("`frame_count` {n} exceeds the limit of 1000000")),
                "{e}"
            );
            let e = crate::window_facts(&seq, WindowSpec { size: 1, stride: 1 }, &config)
                .unwrap_err()
                .to_string();
            assert!(e.contains("exceeds the limit"), "{e}");
        }
        seq.frame_count = MAX_FRAMES;
        seq.validate().unwrap();
    }

    #[test]
    fn windows_cover_and_clip() {
        let w = WindowSpec {
            size: 10,
            stride: 10,
        };
        let ws = w.windows(25).unwrap();
        assert_eq!(ws, vec![(0, 0, 9), (1, 10, 19), (2, 20, 24)]);
        let o = WindowSpec {
            size: 10,
            stride: 5,
        };
        assert_eq!(
            o.windows(20).unwrap(),
            vec![(0, 0, 9), (1, 5, 14), (2, 10, 19)]
        );
        assert!(WindowSpec { size: 0, stride: 1 }.windows(5).is_err());
        assert!(w.windows(0).unwrap().is_empty());
    }

    #[test]
    fn pose_round_trip() {
        let pose = CameraPose {
            position: [3.0, -1.65, 7.0],
            yaw: 0.4,
        };
        let p = [1.0, 0.5, -2.0];
        let q = pose.camera_to_world(pose.world_to_camera(p));
        for k in 0..3 {
            assert!((p[k] - q[k]).abs() < 1e-12);
        }
        // Forward axis.
        let f = pose.camera_to_world([0.0, 0.0, 1.0]);
        assert!((f[0] - 3.0 - 0.4f64.sin()).abs() < 1e-12);
    }

    #[test]
    fn class_predicates_round_trip() {
        for c in ObjectClass::ALL {
            assert_eq!(ObjectClass::from_predicate(c.predicate()), Some(c));
        }
        assert!(ObjectClass::Road.is_static());
        assert!(!ObjectClass::Vehicle.is_static());
    }
}
