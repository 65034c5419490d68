//! Flat-ground 3D from a 2D box.
//!
//! Assumption (stated, not hidden): the road is a plane, the camera's optical
//! axis is parallel to it (no pitch or roll), the camera's optical centre is
//! `CameraConfig::height_m` above it (KITTI: 1.65 m), and the bottom edge of
//! an object's box is where the object touches the ground. Then a ground point
//! imaged at row `v` lies at depth `Z = fy · height / (v − cy)`. Boxes whose
//! bottom edge is at or above the horizon (`v <= cy`) have no flat-ground
//! depth; boxes cut by the image's bottom edge give a depth that is too large,
//! so they are reported as truncated.

use crate::coords::CameraPoint;
use crate::model::{BBox2D, CameraConfig};

/// Flat-ground estimation settings.
///
/// Invariant: `min_rows_below_horizon > 0`, `max_depth_m > 0`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundConfig {
    /// The box bottom must be at least this many pixels below the horizon
    /// row: nearer to it, one pixel of error is many metres.
    pub min_rows_below_horizon: f64,
    /// Depths beyond this are not reported (metres).
    pub max_depth_m: f64,
    /// A box bottom within this many pixels of the image's last row counts as
    /// cut by the image (detectors stop a pixel or two short of the edge).
    pub bottom_margin_px: f64,
}

impl Default for GroundConfig {
    fn default() -> Self {
        GroundConfig {
            min_rows_below_horizon: 2.0,
            max_depth_m: 120.0,
            bottom_margin_px: 3.0,
        }
    }
}

/// A flat-ground position estimate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GroundPoint {
    /// Bottom-centre of the object in camera coordinates (X right, Y down, Z
    /// forward), metres; `Y` is the camera height.
    pub position: CameraPoint,
    /// Whether the box touches the image's bottom edge (depth overestimated).
    pub truncated_bottom: bool,
}

/// The ground contact point of `bbox` under the flat-ground assumption, or
/// `None` when the bottom edge is too close to or above the horizon.
pub fn ground_point(
    bbox: &BBox2D,
    camera: &CameraConfig,
    config: &GroundConfig,
) -> Option<GroundPoint> {
    let k = &camera.intrinsics;
    let rows = bbox.bottom - k.cy;
    // Also rejects NaN rows (a NaN box compares false everywhere).
    if rows.is_nan() || rows < config.min_rows_below_horizon {
        return None;
    }
    let z = k.fy * camera.height_m / rows;
    if !(z.is_finite() && z <= config.max_depth_m) {
        return None;
    }
    let x = (bbox.center_x() - k.cx) * z / k.fx;
    Some(GroundPoint {
        position: CameraPoint::new(x, camera.height_m, z),
        truncated_bottom: bbox.bottom >= f64::from(k.image_height) - 1.0 - config.bottom_margin_px,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kitti() -> CameraConfig {
        crate::kitti::KITTI_2011_09_26_CAMERA
    }

    #[test]
    fn projecting_a_ground_point_and_back_is_identity() {
        let cam = kitti();
        for &(x, z) in &[(0.0, 8.0), (-3.0, 12.0), (4.0, 30.0)] {
            let uv = cam
                .intrinsics
                .project(CameraPoint::new(x, cam.height_m, z), 0.1)
                .unwrap();
            let (u, v) = (uv.x, uv.y);
            let b = BBox2D {
                left: u - 10.0,
                top: v - 20.0,
                right: u + 10.0,
                bottom: v,
            };
            let g = ground_point(&b, &cam, &GroundConfig::default()).unwrap();
            assert!(
                (g.position.0.z - z).abs() < 1e-9 && (g.position.0.x - x).abs() < 1e-9,
                "{g:?}"
            );
            assert!(!g.truncated_bottom);
        }
    }

    #[test]
    fn above_horizon_and_truncated_boxes() {
        let cam = kitti();
        let above = BBox2D {
            left: 0.0,
            top: 100.0,
            right: 10.0,
            bottom: 170.0,
        };
        assert!(ground_point(&above, &cam, &GroundConfig::default()).is_none());
        let cut = BBox2D {
            left: 0.0,
            top: 200.0,
            right: 100.0,
            bottom: 374.0,
        };
        assert!(
            ground_point(&cut, &cam, &GroundConfig::default())
                .unwrap()
                .truncated_bottom
        );
    }
}
