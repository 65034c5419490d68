//! Geometry on the bird's-eye (X, Z) plane: back-projection of a box's
//! ground contact with the calibrated intrinsics, oriented footprints, gaps
//! between footprints, point-in-polygon.

use crate::model::{BBox2D, CameraConfig, Observation};

/// A point on the bird's-eye plane `(X, Z)`, metres.
pub type Bev = [f64; 2];

/// Minimum pixel distance of a box bottom below the horizon for flat-ground
/// back-projection; closer to the horizon the depth is unbounded.
pub const MIN_PIXELS_BELOW_HORIZON: f64 = 1.0;

/// Ground point of an observation on the bird's-eye plane: the labelled 3D
/// position when present, otherwise the flat-ground back-projection of the
/// box's bottom-centre ([`ground_point_from_box`]).
pub fn ground_point(obs: &Observation, camera: &CameraConfig) -> Option<Bev> {
    match obs.position {
        Some(p) => Some([p[0], p[2]]),
        None => ground_point_from_box(&obs.bbox, camera),
    }
}

/// Back-projects the bottom-centre of a 2D box onto flat ground `Y =
/// height_m`: `Z = fy·h / (v − cy)`, `X = (u − cx)·Z / fx`. `None` when the
/// bottom is at or above the horizon. A box truncated at the image bottom
/// yields a point that is too far, which is the best the box can say.
pub fn ground_point_from_box(b: &BBox2D, camera: &CameraConfig) -> Option<Bev> {
    let k = &camera.intrinsics;
    let dv = b.bottom - k.cy;
    if dv < MIN_PIXELS_BELOW_HORIZON {
        return None;
    }
    let z = k.fy * camera.height_m / dv;
    let p = k.back_project(b.center_x(), b.bottom, z);
    Some([p[0], p[2]])
}

/// The four footprint corners of an oriented box on the bird's-eye plane.
/// `yaw` follows KITTI: heading `(cos yaw, −sin yaw)` in `(X, Z)`.
pub fn footprint(center: Bev, width: f64, length: f64, yaw: f64) -> [Bev; 4] {
    let (s, c) = yaw.sin_cos();
    let (hl, hw) = (length / 2.0, width / 2.0);
    let mut out = [[0.0; 2]; 4];
    for (k, (dl, dw)) in [(hl, hw), (hl, -hw), (-hl, -hw), (-hl, hw)]
        .iter()
        .enumerate()
    {
        out[k] = [center[0] + c * dl + s * dw, center[1] - s * dl + c * dw];
    }
    out
}

/// Footprint of an observation: oriented rectangle when size and yaw are
/// known, otherwise a square of side `default_width` around the ground point.
pub fn observation_footprint(center: Bev, obs: &Observation, default_width: f64) -> [Bev; 4] {
    match (obs.size, obs.yaw) {
        (Some([_, w, l]), Some(yaw)) => footprint(center, w, l, yaw),
        (Some([_, w, l]), None) => footprint(center, w, l, 0.0),
        _ => footprint(center, default_width, default_width, 0.0),
    }
}

fn sub(a: Bev, b: Bev) -> Bev {
    [a[0] - b[0], a[1] - b[1]]
}

fn dot(a: Bev, b: Bev) -> f64 {
    a[0] * b[0] + a[1] * b[1]
}

/// Distance from `p` to segment `ab`.
pub fn point_segment_distance(p: Bev, a: Bev, b: Bev) -> f64 {
    let ab = sub(b, a);
    let len2 = dot(ab, ab);
    let t = if len2 > 0.0 {
        (dot(sub(p, a), ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = [a[0] + t * ab[0], a[1] + t * ab[1]];
    dot(sub(p, q), sub(p, q)).sqrt()
}

/// Whether two convex polygons overlap (separating axis test).
pub fn convex_overlap(a: &[Bev], b: &[Bev]) -> bool {
    for poly in [a, b] {
        let n = poly.len();
        for i in 0..n {
            let e = sub(poly[(i + 1) % n], poly[i]);
            let axis = [-e[1], e[0]];
            let (amin, amax) = project(a, axis);
            let (bmin, bmax) = project(b, axis);
            if amax < bmin || bmax < amin {
                return false;
            }
        }
    }
    true
}

fn project(poly: &[Bev], axis: Bev) -> (f64, f64) {
    poly.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| {
            let d = dot(*p, axis);
            (lo.min(d), hi.max(d))
        })
}

/// Gap between two convex polygons: 0 when they overlap, otherwise the
/// smallest vertex-to-edge distance.
pub fn convex_gap(a: &[Bev], b: &[Bev]) -> f64 {
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
pub fn point_in_polygon(p: Bev, poly: &[Bev]) -> bool {
    let n = poly.len();
    if n < 3 {
        return false;
    }
    let mut inside = false;
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if p[0] < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// Overlap fraction of footprint `a` covered by `b`, estimated on a 5×5
/// sample grid of `a` (enough to decide "mostly on top of").
pub fn covered_fraction(a: &[Bev; 4], b: &[Bev]) -> f64 {
    let mut inside = 0;
    let n = 5;
    for i in 0..n {
        for j in 0..n {
            let u = (i as f64 + 0.5) / n as f64;
            let v = (j as f64 + 0.5) / n as f64;
            // Bilinear point inside the quadrilateral a.
            let p0 = [
                a[0][0] + u * (a[1][0] - a[0][0]),
                a[0][1] + u * (a[1][1] - a[0][1]),
            ];
            let p1 = [
                a[3][0] + u * (a[2][0] - a[3][0]),
                a[3][1] + u * (a[2][1] - a[3][1]),
            ];
            let p = [p0[0] + v * (p1[0] - p0[0]), p0[1] + v * (p1[1] - p0[1])];
            if point_in_polygon(p, b) {
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
        let p = [2.0, 1.65, 12.0];
        let uv = c.intrinsics.project(p, 0.1).unwrap();
        let b = BBox2D {
            left: uv[0] - 10.0,
            right: uv[0] + 10.0,
            top: uv[1] - 40.0,
            bottom: uv[1],
        };
        let g = ground_point_from_box(&b, &c).unwrap();
        assert!((g[0] - 2.0).abs() < 1e-9 && (g[1] - 12.0).abs() < 1e-9);
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
            bbox: b,
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
        let a = footprint([0.0, 0.0], 2.0, 4.0, 0.0);
        let b = footprint([7.0, 0.0], 2.0, 4.0, 0.0);
        assert!((convex_gap(&a, &b) - 3.0).abs() < 1e-9);
        let c = footprint([3.0, 0.5], 2.0, 4.0, 0.3);
        assert_eq!(convex_gap(&a, &c), 0.0);
        let sq = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]];
        assert!(point_in_polygon([5.0, 5.0], &sq));
        assert!(!point_in_polygon([15.0, 5.0], &sq));
        assert_eq!(
            covered_fraction(&footprint([5.0, 5.0], 1.0, 1.0, 0.2), &sq),
            1.0
        );
    }

    #[test]
    fn wraps_angles() {
        assert!((wrap_angle(3.0 * std::f64::consts::PI) - std::f64::consts::PI).abs() < 1e-12);
        assert!((wrap_angle(-0.5) + 0.5).abs() < 1e-12);
    }
}
