//! The calibrated camera: pinhole intrinsics, mounting height, and the
//! simulator's camera pose in its world.

use nalgebra::{Matrix3, Point2, Point3, Vector2};
use serde::{Deserialize, Serialize};

use crate::coords::{CameraPoint, WorldPoint, yaw_axes};
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
    /// The calibration matrix `K` (`[fx 0 cx; 0 fy cy; 0 0 1]`): pixel
    /// `(u, v, 1)·Z = K·p` for a camera point `p`.
    pub fn matrix(&self) -> Matrix3<f64> {
        Matrix3::new(
            self.fx, 0.0, self.cx, //
            0.0, self.fy, self.cy, //
            0.0, 0.0, 1.0,
        )
    }

    /// Projects a camera-frame point to pixel coordinates `(u, v)`; `None`
    /// when the point is not in front of the camera (`Z <= min_depth`).
    pub fn project(&self, p: CameraPoint, min_depth: f64) -> Option<Point2<f64>> {
        let p = p.0;
        if p.z <= min_depth || !p.iter().all(|v| v.is_finite()) {
            return None;
        }
        // Written out rather than as `(K·p) / Z`: one rounding fewer, and
        // exactly the formula `back_project` inverts.
        Some(Point2::new(
            self.fx * p.x / p.z + self.cx,
            self.fy * p.y / p.z + self.cy,
        ))
    }

    /// Back-projects pixel `(u, v)` at depth `z` (metres along the optical
    /// axis) into camera coordinates: `K⁻¹·(u, v, 1)·z`, written out.
    pub fn back_project(&self, u: f64, v: f64, z: f64) -> CameraPoint {
        CameraPoint::new((u - self.cx) * z / self.fx, (v - self.cy) * z / self.fy, z)
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
                    "focal lengths and image size must be positive and finite, got fx {}, fy {}, cx {}, cy {}, image {}×{}",
                    self.fx, self.fy, self.cx, self.cy, self.image_width, self.image_height
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
    /// World point → camera coordinates: the offset from the optical centre
    /// read along the camera's right, down and forward axes.
    pub fn world_to_camera(&self, p: WorldPoint) -> CameraPoint {
        let (right, forward) = yaw_axes(self.yaw);
        let d = p.0 - Point3::from(self.position);
        let ground = Vector2::new(d.x, d.z);
        CameraPoint::new(right.dot(&ground), d.y, forward.dot(&ground))
    }

    /// Camera point → world coordinates.
    pub fn camera_to_world(&self, p: CameraPoint) -> WorldPoint {
        let (right, forward) = yaw_axes(self.yaw);
        let [x, y, z] = self.position;
        let ground = Vector2::new(x, z) + right * p.0.x + forward * p.0.z;
        WorldPoint::new(ground.x, y + p.0.y, ground.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pose_round_trip() {
        let pose = CameraPose {
            position: [3.0, -1.65, 7.0],
            yaw: 0.4,
        };
        let p = WorldPoint::new(1.0, 0.5, -2.0);
        let q = pose.camera_to_world(pose.world_to_camera(p));
        for k in 0..3 {
            assert!((p.0[k] - q.0[k]).abs() < 1e-12);
        }
        // Forward axis.
        let f = pose.camera_to_world(CameraPoint::new(0.0, 0.0, 1.0));
        assert!((f.0[0] - 3.0 - 0.4f64.sin()).abs() < 1e-12);
    }

    #[test]
    fn the_calibration_matrix_projects_and_back_projects() {
        let k = CameraIntrinsics {
            fx: 721.5,
            fy: 720.0,
            cx: 609.6,
            cy: 172.9,
            image_width: 1242,
            image_height: 375,
        };
        let p = CameraPoint::new(-2.0, 1.65, 12.5);
        let uv = k.project(p, 0.1).unwrap();
        let h = k.matrix() * p.0.coords;
        assert!((h.x / h.z - uv.x).abs() < 1e-9 && (h.y / h.z - uv.y).abs() < 1e-9);
        let back = k.back_project(uv.x, uv.y, p.0.z);
        assert!((back.0 - p.0).norm() < 1e-9, "{back:?}");
        assert_eq!(k.project(CameraPoint::new(0.0, 0.0, 0.05), 0.1), None);
    }
}
