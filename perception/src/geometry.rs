//! Geometry on the bird's-eye (X, Z) plane: back-projection of a box's
//! ground contact with the calibrated intrinsics, oriented footprints, gaps
//! between footprints, point-in-polygon.
//!
//! Ground points come out as [`CameraBev`]; the polygon functions are
//! generic over [`BevPoint`], so they work in the camera or a world frame
//! but never on a mix of both.

use nalgebra::{Point2, Vector2};

use crate::coords::{BevPoint, CameraBev, yaw_axes};
use crate::model::{BBox2D, CameraConfig, Observation};

/// Minimum pixel distance of a box bottom below the horizon for flat-ground
/// back-projection; closer to the horizon the depth is unbounded.
pub const MIN_PIXELS_BELOW_HORIZON: f64 = 1.0;

/// Ground point of an observation on the bird's-eye plane: the labelled 3D
/// position when present, otherwise the flat-ground back-projection of the
/// box's bottom-centre ([`ground_point_from_box`]).
pub fn ground_point(obs: &Observation, camera: &CameraConfig) -> Option<CameraBev> {
    match obs.camera_position() {
        Some(p) => Some(p.bev()),
        None => ground_point_from_box(obs.bbox.as_ref()?, camera),
    }
}

/// Back-projects the bottom-centre of a 2D box onto flat ground `Y =
/// height_m`: `Z = fy·h / (v − cy)`, `X = (u − cx)·Z / fx`. `None` when the
/// bottom is at or above the horizon. A box truncated at the image bottom
/// yields a point that is too far, which is the best the box can say.
pub fn ground_point_from_box(b: &BBox2D, camera: &CameraConfig) -> Option<CameraBev> {
    let k = &camera.intrinsics;
    let dv = b.bottom - k.cy;
    if dv < MIN_PIXELS_BELOW_HORIZON {
        return None;
    }
    let z = k.fy * camera.height_m / dv;
    Some(k.back_project(b.center_x(), b.bottom, z).bev())
}

/// The four footprint corners of an oriented box on the bird's-eye plane,
/// in the frame of `center` and `yaw`. `yaw` follows KITTI: heading
/// `(cos yaw, −sin yaw)` in `(X, Z)`.
pub fn footprint<P: BevPoint>(center: P, width: f64, length: f64, yaw: f64) -> [P; 4] {
    let (along, across) = yaw_axes(yaw);
    let (hl, hw) = (length / 2.0, width / 2.0);
    [(hl, hw), (hl, -hw), (-hl, -hw), (-hl, hw)]
        .map(|(dl, dw)| P::from_point(center.point() + along * dl + across * dw))
}

/// Footprint of an observation: oriented rectangle when size and yaw are
/// known, otherwise a square of side `default_width` around the ground point.
/// Camera frame only: the observation's yaw is relative to its camera.
pub fn observation_footprint(
    center: CameraBev,
    obs: &Observation,
    default_width: f64,
) -> [CameraBev; 4] {
    match (obs.size, obs.yaw) {
        (Some([_, w, l]), Some(yaw)) => footprint(center, w, l, yaw),
        (Some([_, w, l]), None) => footprint(center, w, l, 0.0),
        _ => footprint(center, default_width, default_width, 0.0),
    }
}

/// Distance from `p` to segment `ab`.
pub fn point_segment_distance<P: BevPoint>(p: P, a: P, b: P) -> f64 {
    let (p, a) = (p.point(), a.point());
    let ab = b.point() - a;
    let len2 = ab.norm_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(&ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * t)).norm()
}

/// Whether two convex polygons overlap (separating axis test).
pub fn convex_overlap<P: BevPoint>(a: &[P], b: &[P]) -> bool {
    for poly in [a, b] {
        let n = poly.len();
        for i in 0..n {
            let e = poly[(i + 1) % n].point() - poly[i].point();
            let axis = Vector2::new(-e.y, e.x);
            let (amin, amax) = project(a, &axis);
            let (bmin, bmax) = project(b, &axis);
            if amax < bmin || bmax < amin {
                return false;
            }
        }
    }
    true
}

fn project<P: BevPoint>(poly: &[P], axis: &Vector2<f64>) -> (f64, f64) {
    poly.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            let d = p.point().coords.dot(axis);
            (lo.min(d), hi.max(d))
        })
}

/// Gap between two convex polygons: 0 when they overlap, otherwise the
/// smallest vertex-to-edge distance.
pub fn convex_gap<P: BevPoint>(a: &[P], b: &[P]) -> f64 {
    if convex_overlap(a, b) {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    for (p, q) in [(a, b), (b, a)] {
        let n = q.len();
        for v in p {
            for i in 0..n {
                best = best.min(point_segment_distance(*v, q[i], q[(i + 1) % n]));
            }
        }
    }
    best
}

/// Whether `p` lies inside a simple polygon (even-odd rule; boundary counts
/// as inside up to floating point).
pub fn point_in_polygon<P: BevPoint>(p: P, poly: &[P]) -> bool {
    let n = poly.len();
    if n < 3 {
        return false;
    }
    let p = p.point();
    let mut inside = false;
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (poly[i].point(), poly[j].point());
        if (a.y > p.y) != (b.y > p.y) {
            let x = a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y);
            if p.x < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// Overlap fraction of footprint `a` covered by `b`, estimated on a 5×5
/// sample grid of `a` (enough to decide "mostly on top of").
pub fn covered_fraction<P: BevPoint>(a: &[P; 4], b: &[P]) -> f64 {
    let a = a.map(|p| p.point());
    let mut inside = 0;
    let n = 5;
    for i in 0..n {
        for j in 0..n {
            let u = (i as f64 + 0.5) / n as f64;
            let v = (j as f64 + 0.5) / n as f64;
            // Bilinear point inside the quadrilateral a.
            let p0: Point2<f64> = a[0] + (a[1] - a[0]) * u;
            let p1: Point2<f64> = a[3] + (a[2] - a[3]) * u;
            let p = p0 + (p1 - p0) * v;
            if point_in_polygon(P::from_point(p), b) {
                inside += 1;
            }
        }
    }
    f64::from(inside) / f64::from(n * n)
}

/// Wraps an angle to `(−π, π]`.
pub fn wrap_angle(a: f64) -> f64 {
    let mut x = a % std::f64::consts::TAU;
    if x > std::f64::consts::PI {
        x -= std::f64::consts::TAU;
    } else if x <= -std::f64::consts::PI {
        x += std::f64::consts::TAU;
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coords::{CameraPoint, WorldBev};
    use crate::model::{CameraIntrinsics, ObjectClass};

    fn cam() -> CameraConfig {
        CameraConfig {
            intrinsics: CameraIntrinsics {
                fx: 721.5,
                fy: 721.5,
                cx: 609.6,
                cy: 172.9,
                image_width: 1242,
                image_height: 375,
            },
            height_m: 1.65,
        }
    }

    #[test]
    fn back_projection_inverts_projection() {
        let c = cam();
        let p = CameraPoint::new(2.0, 1.65, 12.0);
        let uv = c.intrinsics.project(p, 0.1).unwrap();
        let b = BBox2D {
            left: uv[0] - 10.0,
            right: uv[0] + 10.0,
            top: uv[1] - 40.0,
            bottom: uv[1],
        };
        let g = ground_point_from_box(&b, &c).unwrap();
        assert!((g.x() - 2.0).abs() < 1e-9 && (g.z() - 12.0).abs() < 1e-9);
        let above = BBox2D {
            left: 0.0,
            right: 1.0,
            top: 0.0,
            bottom: 100.0,
        };
        assert!(ground_point_from_box(&above, &c).is_none());
        let o = Observation {
            frame: 0,
            track_id: 0,
            class: ObjectClass::Vehicle,
            type_name: None,
            color: None,
            bbox: Some(b),
            position: None,
            size: None,
            yaw: None,
            confidence: 1.0,
            truncation: None,
            occlusion: None,
            footprint: None,
            depth_source: None,
        };
        assert!(ground_point(&o, &c).is_some());
    }

    #[test]
    fn gaps_between_boxes() {
        let a = footprint(WorldBev::new(0.0, 0.0), 2.0, 4.0, 0.0);
        let b = footprint(WorldBev::new(7.0, 0.0), 2.0, 4.0, 0.0);
        assert!((convex_gap(&a, &b) - 3.0).abs() < 1e-9);
        let c = footprint(WorldBev::new(3.0, 0.5), 2.0, 4.0, 0.3);
        assert_eq!(convex_gap(&a, &c), 0.0);
        let sq = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]].map(WorldBev::from_xz);
        assert!(point_in_polygon(WorldBev::new(5.0, 5.0), &sq));
        assert!(!point_in_polygon(WorldBev::new(15.0, 5.0), &sq));
        assert_eq!(
            covered_fraction(&footprint(WorldBev::new(5.0, 5.0), 1.0, 1.0, 0.2), &sq),
            1.0
        );
    }

    #[test]
    fn wraps_angles() {
        assert!((wrap_angle(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap_angle(-0.5) + 0.5).abs() < 1e-12);
    }
}
