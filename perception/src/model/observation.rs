//! One object seen in one frame, and how its 3D position was estimated.

use serde::{Deserialize, Serialize};

use super::{BBox2D, ObjectClass};
use crate::coords::{CameraBev, CameraPoint};

/// One object seen in one frame.
///
/// Invariant: `bbox` is valid when present, and present when `position` is
/// not; `position`, `size`, `yaw` are finite when
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
    /// 2D box in the image, pixels; optional when `position` places the
    /// object (a 360° log's cuboid outside any camera).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bbox: Option<BBox2D>,
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

impl Observation {
    /// Intersection over union of the pixel box with `other`; 0 without a
    /// box.
    pub fn iou(&self, other: &BBox2D) -> f64 {
        self.bbox.map_or(0.0, |b| b.iou(other))
    }

    /// [`Observation::position`] as a typed camera-frame point.
    pub fn camera_position(&self) -> Option<CameraPoint> {
        self.position.map(CameraPoint::from_array)
    }

    /// [`Observation::footprint`] as typed camera-frame bird's-eye points.
    pub fn camera_footprint(&self) -> Option<Vec<CameraBev>> {
        self.footprint
            .as_ref()
            .map(|poly| poly.iter().copied().map(CameraBev::from_xz).collect())
    }
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
