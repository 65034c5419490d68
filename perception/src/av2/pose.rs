//! The ego's city pose at each annotation timestamp, interpolated from
//! `city_SE3_egovehicle.feather` (about 200 Hz against the 10 Hz sweeps).

use std::path::Path;

use super::feather::PoseRow;
use crate::error::PerceptionError;
use crate::model::WorldPose;

/// Yaw about `z` (counter-clockwise from `+x`) of a rotation quaternion
/// `[qw, qx, qy, qz]`: the heading of the rotated `+x` axis projected on the
/// ground plane. The quaternion need not be normalised.
pub fn yaw_of_quaternion(q: [f64; 4]) -> f64 {
    let [w, x, y, z] = q;
    (2.0 * (w * z + x * y)).atan2(w * w + x * x - y * y - z * z)
}

/// A pose row as a world pose (position and ground-plane heading).
fn world_pose(p: &PoseRow) -> WorldPose {
    WorldPose {
        x: p.translation[0],
        y: p.translation[1],
        z: p.translation[2],
        yaw: yaw_of_quaternion(p.quaternion),
    }
}

/// Sorts pose rows by timestamp; two rows with one timestamp are an error
/// naming it (which of them holds is unknowable).
pub fn sorted_poses(
    mut rows: Vec<PoseRow>,
    origin: &Path,
) -> Result<Vec<PoseRow>, PerceptionError> {
    rows.sort_by_key(|r| r.timestamp_ns);
    if let Some(w) = rows
        .windows(2)
        .find(|w| w[0].timestamp_ns == w[1].timestamp_ns)
    {
        return Err(PerceptionError::File {
            path: origin.to_path_buf(),
            message: format!("two ego poses at timestamp_ns {}", w[0].timestamp_ns),
        });
    }
    if rows.is_empty() {
        return Err(PerceptionError::File {
            path: origin.to_path_buf(),
            message: "no ego pose rows".into(),
        });
    }
    Ok(rows)
}

/// The pose at timestamp `t` from rows sorted by [`sorted_poses`]: linear in
/// `x, y, z` and in the unwrapped yaw between the two rows around `t`; a
/// timestamp outside the rows by at most `tolerance_ns` takes the nearest
/// end row, farther is an error naming it.
pub fn pose_at(
    rows: &[PoseRow],
    t: i64,
    tolerance_ns: i64,
    origin: &Path,
) -> Result<WorldPose, PerceptionError> {
    // Converted per call: a log asks for ~160 frames of ~3,000 rows.
    let poses: Vec<(i64, WorldPose)> = rows
        .iter()
        .map(|r| (r.timestamp_ns, world_pose(r)))
        .collect();
    WorldPose::interpolate(&poses, t, tolerance_ns).map_err(|message| PerceptionError::File {
        path: origin.to_path_buf(),
        message: format!("annotation {message}"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(t: i64, x: f64, yaw: f64) -> PoseRow {
        PoseRow {
            timestamp_ns: t,
            quaternion: [(yaw / 2.0).cos(), 0.0, 0.0, (yaw / 2.0).sin()],
            translation: [x, 2.0 * x, 0.5],
        }
    }

    #[test]
    fn yaw_of_a_rotation_about_z() {
        for yaw in [-3.0, -1.0, 0.0, 0.7, 3.1] {
            let q = [(yaw / 2.0_f64).cos(), 0.0, 0.0, (yaw / 2.0_f64).sin()];
            assert!((yaw_of_quaternion(q) - yaw).abs() < 1e-12);
        }
    }

    #[test]
    fn interpolates_position_and_unwrapped_yaw() {
        let p = Path::new("poses.feather");
        // Yaw crosses ±π between the rows: the short way, not through 0.
        let rows = vec![row(0, 0.0, 3.0), row(100, 10.0, -3.0)];
        let m = pose_at(&rows, 50, 0, p).unwrap();
        assert!((m.x - 5.0).abs() < 1e-12 && (m.y - 10.0).abs() < 1e-12);
        assert!(
            (m.yaw.abs() - std::f64::consts::PI).abs() < 1e-9,
            "{}",
            m.yaw
        );
        // At a row: that row.
        assert!((pose_at(&rows, 100, 0, p).unwrap().x - 10.0).abs() < 1e-12);
    }

    #[test]
    fn outside_the_rows_within_tolerance_clamps_beyond_errs() {
        let p = Path::new("poses.feather");
        let rows = vec![row(1_000, 1.0, 0.0), row(2_000, 2.0, 0.0)];
        assert_eq!(pose_at(&rows, 500, 600, p).unwrap().x, 1.0);
        assert_eq!(pose_at(&rows, 2_400, 600, p).unwrap().x, 2.0);
        let e = pose_at(&rows, 3_000, 600, p).unwrap_err().to_string();
        assert!(e.contains("poses.feather") && e.contains("3000"), "{e}");
    }

    #[test]
    fn duplicate_timestamps_are_an_error() {
        let e = sorted_poses(vec![row(5, 0.0, 0.0), row(5, 1.0, 0.0)], Path::new("p"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("timestamp_ns 5"), "{e}");
    }
}
