//! The static map of a log and the ego's known pose: what a 360° sensor
//! log (Argoverse 2, nuScenes, Waymo) carries beyond its object tracks.
//!
//! Both live in the source's own *world frame* (AV2: the city frame):
//! right-handed, `z` up, metres, yaw counter-clockwise about `z` from `+x`.
//! Facts never depend on that frame: `perception::ego` re-anchors poses and
//! map alike on the ego's pose at frame 0 ([`crate::coords::WorldAnchor`]),
//! so rotating or translating the whole world changes nothing.

use serde::{Deserialize, Serialize};

/// The ego vehicle's pose in the world frame at one frame.
///
/// Invariant (checked by [`crate::Sequence::validate`]): every field is
/// finite.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WorldPose {
    /// Position `x`, metres.
    pub x: f64,
    /// Position `y`, metres.
    pub y: f64,
    /// Height `z`, metres (kept for provenance; facts are on the ground plane).
    #[serde(default)]
    pub z: f64,
    /// Heading about `z`, counter-clockwise from `+x`, radians.
    pub yaw: f64,
}

impl WorldPose {
    /// Whether every field is finite.
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite() && self.yaw.is_finite()
    }
}

impl WorldPose {
    /// The pose at timestamp `t` from `rows` sorted by timestamp (no two
    /// alike): linear in `x, y, z` and in the yaw the short way round
    /// between the two rows around `t`; a `t` outside the rows by at most
    /// `tolerance_ns` takes the nearest end row, farther is an error
    /// saying by how much (the caller names the file or table). One rule
    /// for every source that carries poses at their own rate (the `av2:`
    /// reader's 200 Hz pose file, a tracks table's pose rows).
    pub fn interpolate(
        rows: &[(i64, WorldPose)],
        t: i64,
        tolerance_ns: i64,
    ) -> Result<WorldPose, String> {
        let (Some(first), Some(last)) = (rows.first(), rows.last()) else {
            return Err("no ego pose rows".into());
        };
        if t <= first.0 || t >= last.0 {
            let (end, gap) = if t <= first.0 {
                (first, first.0.saturating_sub(t))
            } else {
                (last, t.saturating_sub(last.0))
            };
            if gap > tolerance_ns {
                return Err(format!(
                    "timestamp_ns {t} is {:.1} ms outside the ego poses ({} to {}); at most {:.1} ms is bridged by the nearest pose",
                    gap as f64 / 1e6,
                    first.0,
                    last.0,
                    tolerance_ns as f64 / 1e6
                ));
            }
            return Ok(end.1);
        }
        // first < t < last: the row after t exists and is not the first.
        let i = rows.partition_point(|r| r.0 <= t);
        let (a, b) = (&rows[i - 1], &rows[i]);
        let u = (t - a.0) as f64 / (b.0 - a.0) as f64;
        let (pa, pb) = (a.1, b.1);
        let lerp = |x: f64, y: f64| x + u * (y - x);
        let wrap = crate::geometry::wrap_angle;
        Ok(WorldPose {
            x: lerp(pa.x, pb.x),
            y: lerp(pa.y, pb.y),
            z: lerp(pa.z, pb.z),
            yaw: wrap(pa.yaw + u * wrap(pb.yaw - pa.yaw)),
        })
    }
}

/// Frames per second from the median interval between sorted timestamps
/// (nanoseconds); [`crate::model::DEFAULT_FPS`] for fewer than two.
pub fn fps_from_timestamps(timestamps: &[i64]) -> f64 {
    let mut gaps: Vec<i64> = timestamps.windows(2).map(|w| w[1] - w[0]).collect();
    if gaps.is_empty() {
        return crate::model::DEFAULT_FPS;
    }
    gaps.sort_unstable();
    let mid = gaps.len() / 2;
    let median = if gaps.len() % 2 == 1 {
        gaps[mid] as f64
    } else {
        (gaps[mid - 1] as f64 + gaps[mid] as f64) / 2.0
    };
    1e9 / median
}

/// What a lane is for (AV2 `lane_type`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum LaneKind {
    /// A lane for general traffic (AV2 `VEHICLE`).
    Vehicle,
    /// A bus lane (AV2 `BUS`).
    Bus,
    /// A bike lane (AV2 `BIKE`).
    Bike,
}

impl LaneKind {
    /// The `LaneType(lane, …)` value.
    pub const fn value(&self) -> &'static str {
        match self {
            LaneKind::Vehicle => "Vehicle",
            LaneKind::Bus => "Bus",
            LaneKind::Bike => "Bike",
        }
    }
}

/// One lane segment: its two boundaries in the direction of travel.
///
/// Invariant: each boundary has at least two finite points; the lane's
/// polygon is the left boundary followed by the reversed right boundary.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapLane {
    /// The map's id of the segment.
    pub id: i64,
    /// What the lane is for.
    pub kind: LaneKind,
    /// Whether the segment lies inside an intersection.
    #[serde(default)]
    pub is_intersection: bool,
    /// Left boundary `[x, y]`, in the direction of travel.
    pub left_boundary: Vec<[f64; 2]>,
    /// Right boundary `[x, y]`, in the direction of travel.
    pub right_boundary: Vec<[f64; 2]>,
    /// Segments that continue this one.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub successors: Vec<i64>,
    /// Segments this one continues.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub predecessors: Vec<i64>,
    /// The neighbouring segment on the left, when the map names one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub left_neighbor: Option<i64>,
    /// The neighbouring segment on the right, when the map names one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub right_neighbor: Option<i64>,
}

impl MapLane {
    /// The lane's area: the left boundary, then the right one reversed.
    pub fn polygon(&self) -> Vec<[f64; 2]> {
        let mut p = self.left_boundary.clone();
        p.extend(self.right_boundary.iter().rev().copied());
        p
    }

    /// The centre line, sampled at the longer boundary's points (pairs of
    /// points at equal fractions of each boundary's length).
    pub fn centerline(&self) -> Vec<[f64; 2]> {
        let n = self
            .left_boundary
            .len()
            .max(self.right_boundary.len())
            .max(2);
        (0..n)
            .map(|i| {
                let t = i as f64 / (n - 1) as f64;
                let a = polyline_at(&self.left_boundary, t);
                let b = polyline_at(&self.right_boundary, t);
                [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0]
            })
            .collect()
    }
}

/// The point at fraction `t` of a polyline's length (its first point for an
/// empty or zero-length line).
fn polyline_at(line: &[[f64; 2]], t: f64) -> [f64; 2] {
    let Some(&first) = line.first() else {
        return [0.0, 0.0];
    };
    let seg = |a: [f64; 2], b: [f64; 2]| ((b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2)).sqrt();
    let total: f64 = line.windows(2).map(|w| seg(w[0], w[1])).sum();
    if total <= 0.0 {
        return first;
    }
    let mut left = t.clamp(0.0, 1.0) * total;
    for w in line.windows(2) {
        let d = seg(w[0], w[1]);
        if left <= d && d > 0.0 {
            let u = left / d;
            return [
                w[0][0] + u * (w[1][0] - w[0][0]),
                w[0][1] + u * (w[1][1] - w[0][1]),
            ];
        }
        left -= d;
    }
    line.last().copied().unwrap_or(first)
}

/// A polygon element of the map (a pedestrian crossing, a drivable area).
///
/// Invariant: at least three finite points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MapArea {
    /// The map's id of the element.
    pub id: i64,
    /// Outline `[x, y]` (either winding).
    pub polygon: Vec<[f64; 2]>,
}

/// A log's static map in the world frame.
///
/// Invariant (checked by [`SceneMap::validate`]): every coordinate finite,
/// lanes with two points per boundary, areas with three points, ids unique
/// within each layer.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneMap {
    /// Where the map came from (a file), named in map facts' provenance.
    #[serde(default)]
    pub origin: String,
    /// Lane segments.
    #[serde(default)]
    pub lanes: Vec<MapLane>,
    /// Pedestrian crossings.
    #[serde(default)]
    pub crosswalks: Vec<MapArea>,
    /// Drivable areas.
    #[serde(default)]
    pub drivable_areas: Vec<MapArea>,
}

impl SceneMap {
    /// Checks the documented invariants; the message names the layer and id.
    pub fn validate(&self) -> Result<(), String> {
        let finite = |p: &[[f64; 2]]| p.iter().all(|q| q[0].is_finite() && q[1].is_finite());
        let mut seen = std::collections::BTreeSet::new();
        for l in &self.lanes {
            if !seen.insert(l.id) {
                return Err(format!("lane segment {} appears twice", l.id));
            }
            if l.left_boundary.len() < 2 || l.right_boundary.len() < 2 {
                return Err(format!(
                    "lane segment {} needs at least two points on each boundary",
                    l.id
                ));
            }
            if !finite(&l.left_boundary) || !finite(&l.right_boundary) {
                return Err(format!("lane segment {} has a non-finite coordinate", l.id));
            }
        }
        for (layer, areas) in [
            ("pedestrian crossing", &self.crosswalks),
            ("drivable area", &self.drivable_areas),
        ] {
            let mut seen = std::collections::BTreeSet::new();
            for a in areas {
                if !seen.insert(a.id) {
                    return Err(format!("{layer} {} appears twice", a.id));
                }
                if a.polygon.len() < 3 {
                    return Err(format!("{layer} {} needs at least three points", a.id));
                }
                if !finite(&a.polygon) {
                    return Err(format!("{layer} {} has a non-finite coordinate", a.id));
                }
            }
        }
        Ok(())
    }

    /// Whether the map holds nothing.
    pub fn is_empty(&self) -> bool {
        self.lanes.is_empty() && self.crosswalks.is_empty() && self.drivable_areas.is_empty()
    }
}

/// One kind of input a source skipped, counted (never silently dropped):
/// shown with the facts so a user sees what did not become facts and why.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Skipped {
    /// Why, e.g. `"beyond max_range_m (80 m) from the ego"`.
    pub reason: String,
    /// How many rows or objects.
    pub count: usize,
    /// One example (file and row, or track), for finding it.
    #[serde(default)]
    pub example: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lane_polygon_and_centerline() {
        let lane = MapLane {
            id: 1,
            kind: LaneKind::Vehicle,
            is_intersection: false,
            left_boundary: vec![[0.0, 2.0], [10.0, 2.0]],
            right_boundary: vec![[0.0, -2.0], [5.0, -2.0], [10.0, -2.0]],
            successors: vec![],
            predecessors: vec![],
            left_neighbor: None,
            right_neighbor: None,
        };
        assert_eq!(lane.polygon().len(), 5);
        let c = lane.centerline();
        assert_eq!(c.len(), 3);
        assert!((c[1][0] - 5.0).abs() < 1e-9 && c[1][1].abs() < 1e-9);
    }

    #[test]
    fn validate_names_the_element() {
        let mut map = SceneMap::default();
        map.crosswalks.push(MapArea {
            id: 7,
            polygon: vec![[0.0, 0.0], [1.0, f64::NAN], [0.0, 1.0]],
        });
        let e = map.validate().unwrap_err();
        assert!(e.contains("pedestrian crossing 7"), "{e}");
    }
}
