//! The simulator's per-frame scene state: dynamic objects, the static world
//! and the camera pose, everything a renderer needs.

use serde::{Deserialize, Serialize};

use super::{BBox2D, Box3D, CameraConfig, CameraPose, ObjectClass};

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
