//! Map facts of surround (360°) sequences with a static map: where each
//! object (the ego included) stands on the map — `OnCrosswalk`,
//! `NearCrosswalk`, `InDrivableArea`, `OnLane`, `InIntersection`,
//! `NearIntersection`, the lanes it uses (`Lane`, `LaneType`) — and the
//! lane relations between objects (`SameLane`, `Following`, measured with
//! the pairs in [`crate::around`]).
//!
//! The map's polygons are brought into the facts' world frame
//! ([`WorldBev`]) once per sequence with the ego's anchor
//! ([`crate::coords::WorldAnchor`]), so map facts do not depend on where
//! the source put its world origin. Each sighting's place on the map is
//! looked up once (`MapPrep::spot`), each map element behind a bounding
//! box test first.

use std::collections::BTreeMap;

use crate::config::AroundConfig;
use crate::coords::{BevPoint, WorldAnchor, WorldBev};
use crate::geometry::{point_in_polygon, point_segment_distance, wrap_angle};
use crate::model::{LaneKind, MapArea, SceneMap};

/// A polygon of the map in the facts' world frame with its bounding box.
#[derive(Debug, Clone)]
struct Area {
    id: i64,
    poly: Vec<WorldBev>,
    lo: [f64; 2],
    hi: [f64; 2],
}

impl Area {
    fn new(id: i64, points: &[[f64; 2]], anchor: &WorldAnchor) -> Area {
        let poly: Vec<WorldBev> = points.iter().map(|p| anchor.to_bev(*p)).collect();
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in &poly {
            lo = [lo[0].min(p.x()), lo[1].min(p.z())];
            hi = [hi[0].max(p.x()), hi[1].max(p.z())];
        }
        Area { id, poly, lo, hi }
    }

    /// Whether `p` lies within `margin` of the bounding box.
    fn near_box(&self, p: WorldBev, margin: f64) -> bool {
        p.x() >= self.lo[0] - margin
            && p.x() <= self.hi[0] + margin
            && p.z() >= self.lo[1] - margin
            && p.z() <= self.hi[1] + margin
    }

    /// Distance (m) from `p` to the polygon: 0 inside.
    fn distance(&self, p: WorldBev) -> f64 {
        if point_in_polygon(p, &self.poly) {
            return 0.0;
        }
        polygon_edge_distance(p, &self.poly)
    }
}

/// The smallest distance from `p` to an edge of the closed polygon `poly`.
pub(crate) fn polygon_edge_distance<P: BevPoint>(p: P, poly: &[P]) -> f64 {
    let n = poly.len();
    (0..n)
        .map(|i| point_segment_distance(p, poly[i], poly[(i + 1) % n]))
        .fold(f64::INFINITY, f64::min)
}

/// A lane segment in the facts' world frame.
#[derive(Debug, Clone)]
struct Lane {
    area: Area,
    kind: LaneKind,
    is_intersection: bool,
    /// The centre line, in the direction of travel.
    centre: Vec<WorldBev>,
    /// Indices (into [`MapPrep::lanes`]) of the segments that continue it.
    successors: Vec<u32>,
}

impl Lane {
    /// The direction of travel (KITTI-sense heading: 0 along +Z, growing
    /// turning right) at the centre line's segment nearest `p`, and the
    /// distance to that segment.
    fn direction_at(&self, p: WorldBev) -> (f64, f64) {
        let mut best = (0.0, f64::INFINITY);
        for w in self.centre.windows(2) {
            let d = point_segment_distance(p, w[0], w[1]);
            let v = w[1].0 - w[0].0;
            if d < best.1 && v.norm() > 0.0 {
                best = (v.x.atan2(v.y), d);
            }
        }
        best
    }
}

/// Where one sighting stands on the map: indices into [`MapPrep`]'s
/// layers, with distances in metres.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Spot {
    /// The lane it is on ([`MapPrep::lane_id`]).
    pub(crate) lane: Option<u32>,
    /// The nearest crossing within `near_crosswalk_m` and its distance.
    pub(crate) crosswalk: Option<(u32, f32)>,
    /// A drivable area holding its centre.
    pub(crate) drivable: Option<u32>,
    /// The nearest intersection lane within `near_intersection_m` and its
    /// distance (0: on it).
    pub(crate) intersection: Option<(u32, f32)>,
}

/// A sequence's map prepared for lookups in the facts' world frame.
#[derive(Debug, Clone)]
pub(crate) struct MapPrep {
    origin: String,
    lanes: Vec<Lane>,
    crosswalks: Vec<Area>,
    drivable: Vec<Area>,
}

impl MapPrep {
    /// The map of a sequence in the frame `anchor` defines.
    pub(crate) fn new(map: &SceneMap, anchor: &WorldAnchor) -> MapPrep {
        let index: BTreeMap<i64, u32> = map
            .lanes
            .iter()
            .enumerate()
            .map(|(i, l)| (l.id, i as u32))
            .collect();
        let lanes = map
            .lanes
            .iter()
            .map(|l| Lane {
                area: Area::new(l.id, &l.polygon(), anchor),
                kind: l.kind,
                is_intersection: l.is_intersection,
                centre: l.centerline().iter().map(|p| anchor.to_bev(*p)).collect(),
                // A successor the map does not hold is no lane to follow in.
                successors: l
                    .successors
                    .iter()
                    .filter_map(|s| index.get(s).copied())
                    .collect(),
            })
            .collect();
        let areas = |v: &[MapArea]| -> Vec<Area> {
            v.iter()
                .map(|a| Area::new(a.id, &a.polygon, anchor))
                .collect()
        };
        MapPrep {
            origin: map.origin.clone(),
            lanes,
            crosswalks: areas(&map.crosswalks),
            drivable: areas(&map.drivable_areas),
        }
    }

    /// Where a centre `p` with heading `heading` (if known) stands on the
    /// map. The lane is the one whose polygon holds `p`; when several do,
    /// the one whose direction of travel differs least from the heading,
    /// then the one whose centre line is nearest, then the smallest id.
    pub(crate) fn spot(&self, p: WorldBev, heading: Option<f64>, cfg: &AroundConfig) -> Spot {
        let mut spot = Spot::default();
        // (heading difference, centre-line distance, id, index)
        let mut lane: Option<(f64, f64, i64, u32)> = None;
        let mut inter: Option<(f64, u32)> = None;
        for (i, l) in self.lanes.iter().enumerate() {
            let margin = if l.is_intersection {
                cfg.near_intersection_m
            } else {
                0.0
            };
            if !l.area.near_box(p, margin) {
                continue;
            }
            let inside = point_in_polygon(p, &l.area.poly);
            if l.is_intersection {
                let d = if inside {
                    0.0
                } else {
                    polygon_edge_distance(p, &l.area.poly)
                };
                if d <= cfg.near_intersection_m && inter.is_none_or(|(b, _)| d < b) {
                    inter = Some((d, i as u32));
                }
            }
            if inside {
                let (dir, dist) = l.direction_at(p);
                let diff = heading.map_or(0.0, |h| wrap_angle(h - dir).abs());
                let key = (diff, dist, l.area.id, i as u32);
                if lane.is_none_or(|b| (key.0, key.1, key.2) < (b.0, b.1, b.2)) {
                    lane = Some(key);
                }
            }
        }
        spot.lane = lane.map(|l| l.3);
        spot.intersection = inter.map(|(d, i)| (i, d as f32));
        let mut cw: Option<(f64, u32)> = None;
        for (i, a) in self.crosswalks.iter().enumerate() {
            if !a.near_box(p, cfg.near_crosswalk_m) {
                continue;
            }
            let d = a.distance(p);
            if d <= cfg.near_crosswalk_m && cw.is_none_or(|(b, _)| d < b) {
                cw = Some((d, i as u32));
            }
        }
        spot.crosswalk = cw.map(|(d, i)| (i, d as f32));
        spot.drivable = self
            .drivable
            .iter()
            .position(|a| a.near_box(p, 0.0) && point_in_polygon(p, &a.poly))
            .map(|i| i as u32);
        spot
    }

    /// The map's name for provenance.
    pub(crate) fn origin(&self) -> &str {
        &self.origin
    }

    /// A lane's map id.
    pub(crate) fn lane_id(&self, lane: u32) -> i64 {
        self.lanes.get(lane as usize).map_or(0, |l| l.area.id)
    }

    /// A lane's constant: `lane_<id>`.
    pub(crate) fn lane_name(&self, lane: u32) -> String {
        format!("lane_{}", self.lane_id(lane))
    }

    /// A lane's kind.
    pub(crate) fn lane_kind(&self, lane: u32) -> LaneKind {
        self.lanes
            .get(lane as usize)
            .map_or(LaneKind::Vehicle, |l| l.kind)
    }

    /// Whether a lane lies inside an intersection.
    pub(crate) fn lane_in_intersection(&self, lane: u32) -> bool {
        self.lanes
            .get(lane as usize)
            .is_some_and(|l| l.is_intersection)
    }

    /// Whether `next` continues `lane` (is one of its successors).
    pub(crate) fn is_successor(&self, lane: u32, next: u32) -> bool {
        self.lanes
            .get(lane as usize)
            .is_some_and(|l| l.successors.contains(&next))
    }

    /// A crossing's map id.
    pub(crate) fn crosswalk_id(&self, i: u32) -> i64 {
        self.crosswalks.get(i as usize).map_or(0, |a| a.id)
    }

    /// A drivable area's map id.
    pub(crate) fn drivable_id(&self, i: u32) -> i64 {
        self.drivable.get(i as usize).map_or(0, |a| a.id)
    }
}

/// A single-object map fact decided over one object's window sightings.
#[derive(Debug, Clone, Copy)]
struct Tally {
    /// Sightings where it holds.
    n: usize,
    /// The smallest measured value where it holds, its frame and element.
    best: f64,
    frame: u32,
    element: i64,
}

impl Tally {
    const NONE: Tally = Tally {
        n: 0,
        best: f64::INFINITY,
        frame: 0,
        element: 0,
    };

    fn add(&mut self, value: f64, frame: u32, element: i64) {
        self.n += 1;
        if value < self.best {
            (self.best, self.frame, self.element) = (value, frame, element);
        }
    }
}

/// One map fact to emit: predicate, arguments, measured value, threshold
/// and note (the caller adds the window's provenance).
pub(crate) struct MapFact {
    pub(crate) predicate: &'static str,
    pub(crate) args: Vec<String>,
    pub(crate) measured: Option<f64>,
    pub(crate) threshold: Option<(&'static str, f64)>,
    pub(crate) note: String,
}

/// The map facts of one object over its window sightings: `spots` and
/// their `frames`. A fact holds when it holds in at least
/// `min_frame_fraction` of the sightings (and in one at least).
pub(crate) fn object_map_facts(
    map: &MapPrep,
    cfg: &AroundConfig,
    name: &str,
    spots: &[Spot],
    frames: &[u32],
    out: &mut Vec<MapFact>,
) {
    let total = spots.len();
    if total == 0 {
        return;
    }
    let need = (cfg.min_frame_fraction * total as f64).max(1.0);
    let holds = |t: &Tally| t.n > 0 && t.n as f64 >= need;
    let (mut on_cw, mut near_cw, mut drivable, mut in_int, mut near_int) = (
        Tally::NONE,
        Tally::NONE,
        Tally::NONE,
        Tally::NONE,
        Tally::NONE,
    );
    let mut lanes: BTreeMap<u32, Tally> = BTreeMap::new();
    for (s, &f) in spots.iter().zip(frames) {
        if let Some((i, d)) = s.crosswalk {
            let (d, id) = (f64::from(d), map.crosswalk_id(i));
            if d <= cfg.on_crosswalk_m {
                on_cw.add(d, f, id);
            }
            near_cw.add(d, f, id);
        }
        if let Some(i) = s.drivable {
            drivable.add(0.0, f, map.drivable_id(i));
        }
        if let Some(l) = s.lane {
            lanes
                .entry(l)
                .or_insert(Tally::NONE)
                .add(0.0, f, map.lane_id(l));
            if map.lane_in_intersection(l) {
                in_int.add(0.0, f, map.lane_id(l));
            }
        }
        if let Some((i, d)) = s.intersection {
            near_int.add(f64::from(d), f, map.lane_id(i));
        }
    }
    let share = |t: &Tally| {
        format!(
            "in {} of its {total} sightings in the window (min_frame_fraction {:.2})",
            t.n, cfg.min_frame_fraction
        )
    };
    let origin = map.origin();
    let mut push = |pred: &'static str,
                    args: Vec<String>,
                    t: &Tally,
                    threshold: Option<(&'static str, f64)>,
                    what: String| {
        out.push(MapFact {
            predicate: pred,
            args,
            measured: threshold.map(|_| t.best),
            threshold,
            note: format!("{what}, {} (map {origin})", share(t)),
        });
    };
    if holds(&on_cw) {
        push(
            "OnCrosswalk",
            vec![name.to_string()],
            &on_cw,
            Some(("around.on_crosswalk_m", cfg.on_crosswalk_m)),
            format!(
                "centre {:.1} m from pedestrian crossing {} in frame {} (at most on_crosswalk_m {:.1} m)",
                on_cw.best, on_cw.element, on_cw.frame, cfg.on_crosswalk_m
            ),
        );
    }
    if holds(&near_cw) {
        push(
            "NearCrosswalk",
            vec![name.to_string()],
            &near_cw,
            Some(("around.near_crosswalk_m", cfg.near_crosswalk_m)),
            format!(
                "centre {:.1} m from pedestrian crossing {} in frame {} (at most near_crosswalk_m {:.1} m)",
                near_cw.best, near_cw.element, near_cw.frame, cfg.near_crosswalk_m
            ),
        );
    }
    if holds(&drivable) {
        push(
            "InDrivableArea",
            vec![name.to_string()],
            &drivable,
            None,
            format!(
                "centre inside drivable area {} in frame {}",
                drivable.element, drivable.frame
            ),
        );
    }
    for (&l, t) in &lanes {
        if !holds(t) {
            continue;
        }
        let lane = map.lane_name(l);
        let what = |pred: &str| {
            format!(
                "{pred}: centre inside lane segment {} in frame {}",
                t.element, t.frame
            )
        };
        push(
            "OnLane",
            vec![name.to_string(), lane.clone()],
            t,
            None,
            what("on the lane"),
        );
        push(
            "Lane",
            vec![lane.clone()],
            t,
            None,
            what(&format!("{name} is on it")),
        );
        let kind = map.lane_kind(l).value().to_string();
        push(
            "LaneType",
            vec![lane, kind],
            t,
            None,
            what(&format!("the map's lane type; {name} is on it")),
        );
    }
    if holds(&in_int) {
        push(
            "InIntersection",
            vec![name.to_string()],
            &in_int,
            None,
            format!(
                "centre inside intersection lane segment {} in frame {}",
                in_int.element, in_int.frame
            ),
        );
    }
    if holds(&near_int) {
        push(
            "NearIntersection",
            vec![name.to_string()],
            &near_int,
            Some(("around.near_intersection_m", cfg.near_intersection_m)),
            format!(
                "centre {:.1} m from intersection lane segment {} in frame {} (at most near_intersection_m {:.1} m)",
                near_int.best, near_int.element, near_int.frame, cfg.near_intersection_m
            ),
        );
    }
}

#[cfg(test)]
mod tests {
    use crate::around::tests::{ObjSpec, facts_of, map_fixture, surround};

    fn keys(seq: &crate::Sequence) -> Vec<String> {
        facts_of(seq)
            .into_iter()
            .flat_map(|w| w.facts)
            .map(|f| f.to_kb_line())
            .collect()
    }

    #[test]
    fn a_pedestrian_on_the_crossing_is_on_it_and_near_it() {
        // The crossing spans ego-frame x 18..22 (ahead), y -6..6.
        let ped = ObjSpec::pedestrian(1, |_| [20.0, 3.0]);
        let far = ObjSpec::pedestrian(2, |_| [20.0, 9.0]);
        let seq = surround(vec![ped, far], Some(map_fixture()));
        let k = keys(&seq);
        assert!(k.contains(&"OnCrosswalk(pedestrian_1)".into()), "{k:?}");
        assert!(k.contains(&"NearCrosswalk(pedestrian_1)".into()), "{k:?}");
        assert!(!k.contains(&"OnCrosswalk(pedestrian_2)".into()), "{k:?}");
        assert!(k.contains(&"NearCrosswalk(pedestrian_2)".into()), "{k:?}");
        let far2 = ObjSpec::pedestrian(3, |_| [20.0, 15.0]);
        let k = keys(&surround(vec![far2], Some(map_fixture())));
        assert!(!k.iter().any(|f| f.contains("Crosswalk")), "{k:?}");
        // The provenance names the crossing.
        let w = &facts_of(&seq)[0];
        let f = w
            .facts
            .iter()
            .find(|f| f.to_kb_line() == "OnCrosswalk(pedestrian_1)")
            .unwrap();
        assert!(
            f.provenance.note.contains("pedestrian crossing 77"),
            "{}",
            f.provenance.note
        );
        assert_eq!(
            f.provenance.threshold.as_ref().map(|t| t.0.as_str()),
            Some("around.on_crosswalk_m")
        );
    }

    #[test]
    fn lanes_drivable_area_and_intersection() {
        // Lane 10 (Vehicle) along the ego's path y in -2..2, x -50..30;
        // lane 11 (Bus) y 2..6; intersection lane 12 x 30..50.
        let car = ObjSpec::car(1, |f| [5.0 + f64::from(f), 0.5], 0.0);
        let bus = ObjSpec::car(2, |_| [10.0, 4.0], 0.0);
        let off = ObjSpec::car(3, |_| [10.0, 40.0], 0.0);
        let inter = ObjSpec::car(4, |_| [40.0, 0.0], 0.0);
        let nearby = ObjSpec::car(5, |_| [27.0, -0.5], 0.0);
        let seq = surround(vec![car, bus, off, inter, nearby], Some(map_fixture()));
        let k = keys(&seq);
        for want in [
            "OnLane(car_1, lane_10)",
            "OnLane(ego, lane_10)",
            "Lane(lane_10)",
            "LaneType(lane_10, Vehicle)",
            "OnLane(car_2, lane_11)",
            "LaneType(lane_11, Bus)",
            "InDrivableArea(car_1)",
            "InDrivableArea(ego)",
            "SameLane(car_1, ego)",
            "SameLane(ego, car_1)",
            "InIntersection(car_4)",
            "NearIntersection(car_4)",
            "NearIntersection(car_5)",
        ] {
            assert!(k.contains(&want.to_string()), "{want} missing: {k:?}");
        }
        for not in [
            "InDrivableArea(car_3)",
            "OnLane(car_1, lane_11)",
            "SameLane(car_1, car_2)",
            "InIntersection(car_1)",
            "InIntersection(car_5)",
            "NearIntersection(car_1)",
        ] {
            assert!(!k.contains(&not.to_string()), "{not} present: {k:?}");
        }
        assert!(!k.iter().any(|f| f.contains("car_3") && f.contains("Lane")));
    }

    #[test]
    fn following_needs_the_same_lane_ahead_and_moving() {
        // Both drive along lane 10 at 5 m/s, car_2 12 m ahead of car_1.
        let a = ObjSpec::car(1, |f| [-20.0 + 0.5 * f64::from(f), 0.0], 0.0);
        let b = ObjSpec::car(2, |f| [-8.0 + 0.5 * f64::from(f), 0.0], 0.0);
        // car_3 in the bus lane alongside.
        let c = ObjSpec::car(3, |f| [-8.0 + 0.5 * f64::from(f), 4.0], 0.0);
        let k = keys(&surround(vec![a, b, c], Some(map_fixture())));
        assert!(k.contains(&"Following(car_1, car_2)".into()), "{k:?}");
        assert!(!k.contains(&"Following(car_2, car_1)".into()), "{k:?}");
        assert!(!k.contains(&"Following(car_1, car_3)".into()), "{k:?}");
        // Parked one behind the other: not following.
        let a = ObjSpec::car(1, |_| [-20.0, 0.0], 0.0);
        let b = ObjSpec::car(2, |_| [-8.0, 0.0], 0.0);
        let k = keys(&surround(vec![a, b], Some(map_fixture())));
        assert!(!k.iter().any(|f| f.starts_with("Following")), "{k:?}");
        assert!(k.contains(&"SameLane(car_1, car_2)".into()), "{k:?}");
    }

    #[test]
    fn no_map_no_map_facts() {
        let ped = ObjSpec::pedestrian(1, |_| [20.0, 3.0]);
        let k = keys(&surround(vec![ped], None));
        for p in [
            "OnCrosswalk",
            "NearCrosswalk",
            "InDrivableArea",
            "OnLane",
            "Lane(",
        ] {
            assert!(!k.iter().any(|f| f.starts_with(p)), "{p}: {k:?}");
        }
    }
}
