//! Points whose type names their coordinate frame, on `nalgebra`.
//!
//! Perception measures in two kinds of frame, and mixing them is the bug
//! these types exist to stop: a camera point read as a world point puts a
//! parked car in motion as soon as the camera moves.
//!
//! - The **camera frame** of one image: KITTI's rectified camera, X right,
//!   Y down, Z forward, metres, origin at the optical centre.
//!   [`CameraPoint`] is a 3D point there; [`CameraBev`] its bird's-eye
//!   ground position `(X, Z)`.
//! - A **world frame** fixed to the ground: for ego-motion, the camera frame
//!   of frame 0 ([`crate::ego::EgoPose`] maps [`CameraBev`] →
//!   [`WorldBev`]); in the simulator, the scenario's map, whose Y axis also
//!   points down with the ground at `Y = 0` ([`crate::model::CameraPose`]
//!   maps [`CameraPoint`] ↔ [`WorldPoint`]). Sim-world and ego-world points
//!   never meet: the simulator hands perception camera-frame observations.
//!
//! Bird's-eye points store `(X, Z)` in a [`Point2`] whose `y` component is
//! Z; read them with `x()` and `z()`. The wrapped nalgebra point is public
//! (`.0`) for arithmetic; wrapping it in another frame's type is a change of
//! frame and should be as rare as it is visible. Serialized formats keep
//! plain arrays (`[f64; 3]` positions, `[f64; 2]` polygons); `from_xz` /
//! `xz` and `from_array` / `to_array` convert at that boundary.
//!
//! Geometry that holds in any single frame (footprints, gaps,
//! point-in-polygon, [`crate::geometry`]) is generic over [`BevPoint`], so
//! both operands of one call are in the same frame by construction.

use nalgebra::{Point2, Point3, UnitComplex, Vector2};

/// A bird's-eye ground point in the camera frame of one image: `x()` right,
/// `z()` forward (depth), metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraBev(pub Point2<f64>);

/// A bird's-eye ground point in a world frame fixed to the ground (see the
/// module docs for which world): `x()` and `z()`, metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldBev(pub Point2<f64>);

/// A 3D point in the camera frame of one image: X right, Y down, Z forward,
/// metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraPoint(pub Point3<f64>);

/// A 3D point in the simulator's world frame: Y down, ground at `Y = 0`,
/// metres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldPoint(pub Point3<f64>);

/// A bird's-eye point of one frame; what frame-agnostic geometry works on.
pub trait BevPoint: Copy {
    /// The `(X, Z)` coordinates as an nalgebra point (`y` holds Z).
    fn point(&self) -> Point2<f64>;
    /// A point of the same frame from `(X, Z)` coordinates.
    fn from_point(p: Point2<f64>) -> Self;
}

macro_rules! bev_point {
    ($t:ident) => {
        impl $t {
            /// The point `(x, z)`.
            pub fn new(x: f64, z: f64) -> $t {
                $t(Point2::new(x, z))
            }
            /// From a serialized `[X, Z]` pair.
            pub fn from_xz(xz: [f64; 2]) -> $t {
                $t::new(xz[0], xz[1])
            }
            /// As a serialized `[X, Z]` pair.
            pub fn xz(&self) -> [f64; 2] {
                [self.0.x, self.0.y]
            }
            /// X (right), metres.
            pub fn x(&self) -> f64 {
                self.0.x
            }
            /// Z (forward), metres.
            pub fn z(&self) -> f64 {
                self.0.y
            }
        }

        impl BevPoint for $t {
            fn point(&self) -> Point2<f64> {
                self.0
            }
            fn from_point(p: Point2<f64>) -> $t {
                $t(p)
            }
        }
    };
}

bev_point!(CameraBev);
bev_point!(WorldBev);

impl CameraBev {
    /// The 3D point on the ground seen at this bird's-eye position, `y`
    /// metres below the optical centre (the camera's mounting height for
    /// the road under it).
    pub fn at_y(&self, y: f64) -> CameraPoint {
        CameraPoint(Point3::new(self.0.x, y, self.0.y))
    }
}

impl WorldBev {
    /// The 3D world point at this bird's-eye position and height `y` (the
    /// simulator's ground is `y = 0`).
    pub fn at_y(&self, y: f64) -> WorldPoint {
        WorldPoint(Point3::new(self.0.x, y, self.0.y))
    }
}

macro_rules! point3 {
    ($t:ident, $bev:ident) => {
        impl $t {
            /// The point `(x, y, z)`.
            pub fn new(x: f64, y: f64, z: f64) -> $t {
                $t(Point3::new(x, y, z))
            }
            /// From a serialized `[X, Y, Z]` array.
            pub fn from_array(p: [f64; 3]) -> $t {
                $t(Point3::from(p))
            }
            /// As a serialized `[X, Y, Z]` array.
            pub fn to_array(&self) -> [f64; 3] {
                [self.0.x, self.0.y, self.0.z]
            }
            /// The bird's-eye position `(X, Z)` (drops the height).
            pub fn bev(&self) -> $bev {
                $bev::new(self.0.x, self.0.z)
            }
        }
    };
}

point3!(CameraPoint, CameraBev);
point3!(WorldPoint, WorldBev);

/// The bird's-eye axes of something turned by heading `yaw` about the
/// down-pointing Y axis (KITTI's `rotation_y` sense: a positive yaw turns
/// +X towards −Z), in the frame it is turned in: where its +X goes,
/// `(cos yaw, −sin yaw)`, and where its +Z goes, `(sin yaw, cos yaw)`. A
/// camera's right and forward axes; a box's length and width axes.
///
/// Frame changes are written `origin + x·axes.0 + z·axes.1`: the transform
/// of [`yaw_rotation`] with the origin added first, which keeps positions,
/// facts and provenance values bit-identical to those the thresholds were
/// tuned on.
pub fn yaw_axes(yaw: f64) -> (Vector2<f64>, Vector2<f64>) {
    let (s, c) = yaw.sin_cos();
    (Vector2::new(c, -s), Vector2::new(s, c))
}

/// The rotation of the bird's-eye `(X, Z)` plane by heading `yaw` (see
/// [`yaw_axes`]): `(x, z) ↦ (c·x + s·z, −s·x + c·z)` with
/// `(s, c) = yaw.sin_cos()`.
pub fn yaw_rotation(yaw: f64) -> UnitComplex<f64> {
    let (s, c) = yaw.sin_cos();
    UnitComplex::from_cos_sin_unchecked(c, -s)
}

/// The change from a source's own world frame (a 360° log's city frame:
/// `x`, `y` on the ground, `z` up, yaw counter-clockwise from `+x`) to the
/// ego-anchored world frame every fact is measured in (the camera frame of
/// frame 0 on the bird's-eye plane, [`WorldBev`]): the ego's pose at frame
/// 0 becomes the origin, heading along +Z.
///
/// Facts computed after this change do not depend on where the source put
/// its origin or which way its axes point, which is what makes them
/// invariant to rotating and translating the world.
///
/// Invariant: the fields are finite.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WorldAnchor {
    /// The ego's position at frame 0 in the source frame.
    pub x0: f64,
    /// See `x0`.
    pub y0: f64,
    /// The ego's heading at frame 0 in the source frame (radians, CCW from +x).
    pub yaw0: f64,
}

impl WorldAnchor {
    /// A source-frame ground point as a [`WorldBev`].
    pub fn to_bev(&self, p: [f64; 2]) -> WorldBev {
        let (s, c) = self.yaw0.sin_cos();
        let (dx, dy) = (p[0] - self.x0, p[1] - self.y0);
        let forward = c * dx + s * dy;
        let left = -s * dx + c * dy;
        WorldBev::new(-left, forward)
    }

    /// A [`WorldBev`] back in the source frame.
    pub fn from_bev(&self, p: WorldBev) -> [f64; 2] {
        let (s, c) = self.yaw0.sin_cos();
        let (forward, left) = (p.z(), -p.x());
        [
            self.x0 + c * forward - s * left,
            self.y0 + s * forward + c * left,
        ]
    }

    /// A source-frame heading (CCW from +x) as the ego-world heading of
    /// [`crate::ego::EgoPose::yaw`] (KITTI sense: growing as it turns right,
    /// 0 along +Z), wrapped to `(−π, π]`.
    pub fn heading_to_bev(&self, yaw: f64) -> f64 {
        crate::geometry::wrap_angle(-(yaw - self.yaw0))
    }
}

/// An object's heading in a vehicle frame (x forward, y left, z up; yaw
/// CCW from +x, AV2's cuboid yaw) as KITTI's `rotation_y` in that vehicle's
/// camera-convention frame (X right, Z forward; the box's length axis along
/// `(cos ry, −sin ry)`), wrapped to `(−π, π]`.
pub fn vehicle_yaw_to_rotation_y(yaw: f64) -> f64 {
    crate::geometry::wrap_angle(-yaw - std::f64::consts::FRAC_PI_2)
}

/// The inverse of [`vehicle_yaw_to_rotation_y`].
pub fn rotation_y_to_vehicle_yaw(ry: f64) -> f64 {
    crate::geometry::wrap_angle(-ry - std::f64::consts::FRAC_PI_2)
}

#[cfg(test)]
mod anchor_tests {
    use super::*;

    #[test]
    fn anchor_round_trips_and_puts_the_ego_on_plus_z() {
        let a = WorldAnchor {
            x0: 100.0,
            y0: -50.0,
            yaw0: 0.7,
        };
        // A point 10 m ahead of the ego in the source frame.
        let ahead = [100.0 + 10.0 * 0.7f64.cos(), -50.0 + 10.0 * 0.7f64.sin()];
        let b = a.to_bev(ahead);
        assert!(b.x().abs() < 1e-9 && (b.z() - 10.0).abs() < 1e-9, "{b:?}");
        // 5 m to the ego's left is -X (left) in the camera convention.
        let left = [100.0 - 5.0 * 0.7f64.sin(), -50.0 + 5.0 * 0.7f64.cos()];
        let l = a.to_bev(left);
        assert!((l.x() + 5.0).abs() < 1e-9 && l.z().abs() < 1e-9, "{l:?}");
        let back = a.from_bev(b);
        assert!((back[0] - ahead[0]).abs() < 1e-9 && (back[1] - ahead[1]).abs() < 1e-9);
        // Turning left by 0.3 rad is a heading of -0.3 (KITTI sense).
        assert!((a.heading_to_bev(1.0) + 0.3).abs() < 1e-12);
    }

    #[test]
    fn vehicle_yaw_and_rotation_y_agree_on_the_length_axis() {
        for yaw in [-3.0, -1.0, 0.0, 0.5, 2.0] {
            let ry = vehicle_yaw_to_rotation_y(yaw);
            // Heading in the vehicle frame (x fwd, y left) as camera (X, Z):
            // X = -y, Z = x.
            let (hx, hz) = (-yaw.sin(), yaw.cos());
            assert!((ry.cos() - hx).abs() < 1e-12 && (-ry.sin() - hz).abs() < 1e-12);
            assert!(
                (crate::geometry::wrap_angle(rotation_y_to_vehicle_yaw(ry) - yaw)).abs() < 1e-12
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn yaw_rotation_turns_forward_towards_the_heading() {
        // Yaw 0: heading along +X (KITTI), so the box's local length axis
        // stays X; a quarter turn sends +X to −Z and +Z to +X.
        let q = yaw_rotation(std::f64::consts::FRAC_PI_2);
        let x = q * Vector2::new(1.0, 0.0);
        let z = q * Vector2::new(0.0, 1.0);
        assert!((x - Vector2::new(0.0, -1.0)).norm() < 1e-12, "{x}");
        assert!((z - Vector2::new(1.0, 0.0)).norm() < 1e-12, "{z}");
        for yaw in [-3.0, -0.4, 0.0, 0.7, 3.1] {
            let (ax, az) = yaw_axes(yaw);
            let r = yaw_rotation(yaw);
            assert_eq!((ax, az), (r * Vector2::x(), r * Vector2::y()));
            assert!((-r.angle() - yaw).abs() < 1e-12);
        }
    }

    #[test]
    fn serialized_forms_round_trip() {
        let c = CameraPoint::from_array([1.5, 1.65, 12.0]);
        assert_eq!(c.to_array(), [1.5, 1.65, 12.0]);
        assert_eq!(c.bev(), CameraBev::new(1.5, 12.0));
        assert_eq!(c.bev().at_y(1.65), c);
        let w = WorldBev::from_xz([3.0, -4.0]);
        assert_eq!((w.x(), w.z(), w.xz()), (3.0, -4.0, [3.0, -4.0]));
        assert_eq!(w.at_y(0.0).bev(), w);
    }
}
