//! 360° relations between the objects of a *surround* sequence
//! ([`Sequence::is_surround`]: some observation has no pixel box), the ego
//! included, in the facts' world frame ([`WorldBev`]), as Argoverse's
//! scenario-mining benchmark (RefAV) defines them: `Near`,
//! `InDirectionOf`, `SameDirection` / `Opposite` / `Perpendicular`,
//! `HeadingToward`, `CrossedBy`, `TurnLeft` / `TurnRight` of objects,
//! `Stationary`; and, with a map ([`crate::mapfacts`]), `SameLane`,
//! `Following` and the per-object map facts. Thresholds are the fields of
//! [`AroundConfig`]; docs/perception.md ("360° relations and map facts")
//! gives every definition.
//!
//! `Around::prepare` does the per-sequence work once: per object and
//! sighting its world centre, velocity, heading and place on the map.
//! `Around::window_facts` then measures each window's pairs frame by
//! frame, pruned by distance (a sweep over the frame's objects sorted by
//! world X), and keeps a relation that holds in at least
//! `min_frame_fraction` of the frames both objects are seen in.
//!
//! Camera sources (every observation with a box) never get here, so their
//! facts stay exactly as they were.

use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;

use crate::config::{AroundConfig, FactConfig};
use crate::coords::WorldBev;
use crate::ego::EgoMotion;
use crate::facts::{EGO, TrackState};
use crate::geometry::wrap_angle;
use crate::mapfacts::{MapFact, MapPrep, Spot, object_map_facts};
use crate::model::{Fact, Provenance, Sequence};

/// The ego's box length (m) for the relations in its own frame: a
/// nominal mid-size car (AV2's logs do not give the recording vehicle's
/// size). Its centre is taken at the pose's position.
pub const EGO_LENGTH_M: f64 = 4.9;
/// The ego's box width (m); see [`EGO_LENGTH_M`].
pub const EGO_WIDTH_M: f64 = 2.0;

/// Frames either side of a sighting whose positions give its velocity
/// (a central difference over ±0.2 s at 10 Hz: annotation jitter of a few
/// centimetres then turns a 1 m/s walker's heading by a few degrees).
const VELOCITY_HALF_SPAN: u32 = 2;

/// An object's turn (`TurnLeft`/`TurnRight`) is one run of same-sign yaw
/// rate; a step turning the other way more slowly than this (°/s) is
/// jitter and does not end the run.
const TURN_RATE_DEADBAND_DPS: f64 = 5.0;

/// One object (or the ego) with its per-sighting world state.
#[derive(Debug, Clone)]
struct Actor {
    name: String,
    ego: bool,
    /// Frames seen, ascending.
    frames: Vec<u32>,
    /// World centre per sighting.
    pos: Vec<WorldBev>,
    /// World velocity `(X, Z)` per sighting, m/s.
    vel: Vec<[f64; 2]>,
    /// World heading per sighting (KITTI sense: 0 along +Z, growing as it
    /// turns right): the box's when labelled, else the direction of
    /// motion when at least `heading_min_speed_mps`; `None` when neither
    /// is known or the class never moves (a cone's box points nowhere).
    heading: Vec<Option<f64>>,
    /// Half length and half width of the box (m; 0 when unknown).
    half: [f64; 2],
    /// How far (m) any centre lies from the first one, over the whole log.
    travel: f64,
    /// Place on the map per sighting (empty without a map).
    spots: Vec<Spot>,
}

impl Actor {
    fn speed(&self, k: usize) -> f64 {
        let v = self.vel[k];
        v[0].hypot(v[1])
    }

    /// The sightings inside `first..=last`.
    fn range(&self, first: u32, last: u32) -> Range<usize> {
        self.frames.partition_point(|f| *f < first)..self.frames.partition_point(|f| *f <= last)
    }

    /// The sighting just before `k` when it is in the frame before.
    fn previous(&self, k: usize, frame: u32) -> Option<usize> {
        (k > 0 && frame > 0 && self.frames[k - 1] == frame - 1).then(|| k - 1)
    }
}

/// `p` in the frame of an object at `origin` with heading `h`: (forward,
/// right) in metres.
fn local(origin: WorldBev, h: f64, p: WorldBev) -> (f64, f64) {
    let d = p.0 - origin.0;
    let (s, c) = h.sin_cos();
    (d.x * s + d.y * c, d.x * c - d.y * s)
}

/// What a surround sequence needs for its 360° relations and map facts,
/// prepared once per sequence.
#[derive(Debug, Clone)]
pub(crate) struct Around {
    cfg: AroundConfig,
    source: Arc<str>,
    /// The ego first, then the tracks in track order.
    actors: Vec<Actor>,
    /// Per frame `f`, `entries[offsets[f]..offsets[f + 1]]` are the
    /// `(actor, sighting)` seen in it, sorted by world X.
    offsets: Vec<usize>,
    entries: Vec<(u32, u32)>,
    /// Seconds since frame 0, per frame.
    times: Vec<f64>,
    /// Pairs farther apart than this (m) in a frame relate in nothing
    /// but `SameLane`.
    radius: f64,
    map: Option<MapPrep>,
}

/// Slots of a pair's per-window tally.
const NEAR: usize = 0;
const SAME: usize = 1;
const OPPOSITE: usize = 2;
const PERPENDICULAR: usize = 3;
const SAME_LANE: usize = 4;
const FORWARD: usize = 5;
const BACKWARD: usize = 6;
const LEFT: usize = 7;
const RIGHT: usize = 8;
const TOWARD: usize = 9;
const FOLLOWING: usize = 10;
const CROSSED: usize = 11;
const SLOTS: usize = 12;

/// The frames a relation held in, the sum of its measured values there,
/// and the first such frame with its map element.
#[derive(Debug, Clone, Copy, Default)]
struct Slot {
    n: u32,
    frame: u32,
    sum: f64,
    element: i64,
}

impl Slot {
    fn add(&mut self, frame: u32, value: f64, element: i64) {
        if self.n == 0 {
            (self.frame, self.element) = (frame, element);
        }
        self.n += 1;
        self.sum += value;
    }

    fn mean(&self) -> f64 {
        self.sum / f64::from(self.n.max(1))
    }
}

type Tally = [Slot; SLOTS];

impl Around {
    /// The prepared state of `seq`, `None` unless it is a surround
    /// sequence. `tracks` are the analysis' tracks (ground surfaces take
    /// no part); `ego` its ego-motion, whose anchor places the map.
    pub(crate) fn prepare(
        seq: &Sequence,
        config: &FactConfig,
        ego: &EgoMotion,
        tracks: &[TrackState],
        source: Arc<str>,
    ) -> Option<Around> {
        if !seq.is_surround() {
            return None;
        }
        let cfg = config.around.clone();
        let frame_count = ego.poses.len();
        let times: Vec<f64> = match &seq.timestamps_ns {
            Some(ts) if ts.len() == frame_count && !ts.is_empty() => {
                ts.iter().map(|t| (t - ts[0]) as f64 * 1e-9).collect()
            }
            _ => (0..frame_count).map(|f| f as f64 / seq.fps).collect(),
        };
        let mut actors = Vec::with_capacity(tracks.len() + 1);
        actors.push(Actor::new(
            EGO,
            true,
            true,
            (0..frame_count as u32).collect(),
            ego.poses.iter().map(|p| p.position).collect(),
            ego.poses.iter().map(|p| Some(p.yaw)).collect(),
            [EGO_LENGTH_M / 2.0, EGO_WIDTH_M / 2.0],
            &cfg,
            &times,
        ));
        for t in tracks {
            if t.surface || t.class.is_ground_surface() {
                continue;
            }
            let headed = !t.class.is_static();
            let (mut frames, mut pos, mut boxed) = (Vec::new(), Vec::new(), Vec::new());
            let mut half = None;
            for (k, (&f, c)) in t.frames.iter().zip(&t.cam).enumerate() {
                let (Some(c), Some(pose)) = (c, ego.poses.get(f as usize)) else {
                    continue;
                };
                let o = &seq.observations[t.obs[k]];
                frames.push(f);
                pos.push(pose.to_world(*c));
                // rotation_y turns the box's length axis to (cos ry, −sin
                // ry): heading ry + π/2 in the camera, plus the camera's.
                boxed.push(
                    o.yaw
                        .filter(|_| headed)
                        .map(|ry| wrap_angle(pose.yaw + ry + std::f64::consts::FRAC_PI_2)),
                );
                if half.is_none()
                    && let Some([_, w, l]) = o.size
                {
                    half = Some([l.abs() / 2.0, w.abs() / 2.0]);
                }
            }
            if frames.is_empty() {
                continue;
            }
            actors.push(Actor::new(
                &t.name,
                false,
                headed,
                frames,
                pos,
                boxed,
                half.unwrap_or([0.0, 0.0]),
                &cfg,
                &times,
            ));
        }
        let map = match (&seq.map, ego.anchor) {
            (Some(m), Some(anchor)) => Some(MapPrep::new(m, &anchor)),
            _ => None,
        };
        if let Some(m) = &map {
            for a in &mut actors {
                a.spots = a
                    .pos
                    .iter()
                    .zip(&a.heading)
                    .map(|(p, h)| m.spot(*p, *h, &cfg))
                    .collect();
            }
        }
        let mut per_frame: Vec<Vec<(u32, u32)>> = vec![Vec::new(); frame_count];
        for (ai, a) in actors.iter().enumerate() {
            for (k, f) in a.frames.iter().enumerate() {
                if let Some(v) = per_frame.get_mut(*f as usize) {
                    v.push((ai as u32, k as u32));
                }
            }
        }
        let mut offsets = Vec::with_capacity(frame_count + 1);
        let mut entries = Vec::new();
        offsets.push(0);
        for mut v in per_frame {
            v.sort_by(|a, b| {
                let pa = actors[a.0 as usize].pos[a.1 as usize].x();
                let pb = actors[b.0 as usize].pos[b.1 as usize].x();
                pa.total_cmp(&pb).then(a.0.cmp(&b.0))
            });
            entries.extend(v);
            offsets.push(entries.len());
        }
        let (hl, hw) = actors.iter().fold((0.0f64, 0.0f64), |(l, w), a| {
            (l.max(a.half[0]), w.max(a.half[1]))
        });
        let radius = [
            cfg.near_m,
            cfg.direction_within_m,
            cfg.heading_toward_max_m,
            cfg.following_max_m + 2.0 * hl,
            (hl + cfg.crossing_forward_m).hypot(hw + cfg.crossing_lateral_m),
        ]
        .into_iter()
        .fold(0.0, f64::max);
        Some(Around {
            cfg,
            source,
            actors,
            offsets,
            entries,
            times,
            radius,
            map,
        })
    }

    fn fact(
        &self,
        (index, first, last): (u32, u32, u32),
        predicate: &str,
        args: Vec<String>,
        measured: Option<f64>,
        threshold: Option<(&str, f64)>,
        note: String,
    ) -> Fact {
        Fact {
            predicate: predicate.to_string(),
            args,
            provenance: Arc::new(Provenance {
                window: index,
                frames: (first, last),
                source: self.source.clone(),
                measured,
                threshold: threshold.map(|(n, v)| (n.to_string(), v)),
                note,
                probability: None,
            }),
        }
    }

    /// The 360° relations and map facts of the window `first..=last`
    /// (index `index`), unsorted.
    /// `in_range` names the objects within `pair_range_m` of the ego in
    /// the window (decided by `facts.rs` for the camera-style pair facts
    /// too): only they, and the ego, take part in pair relations.
    pub(crate) fn window_facts(
        &self,
        index: u32,
        first: u32,
        last: u32,
        in_range: &std::collections::HashSet<&str>,
    ) -> Vec<Fact> {
        let w = (index, first, last);
        let mut out = Vec::new();
        self.object_facts(w, &mut out);
        let in_range: Vec<bool> = self
            .actors
            .iter()
            .map(|a| a.ego || in_range.contains(a.name.as_str()))
            .collect();
        let mut tally: HashMap<(u32, u32), Tally> = HashMap::new();
        for f in first..=last {
            self.frame_pairs(f, first, &in_range, &mut tally);
        }
        let mut keys: Vec<(u32, u32)> = tally.keys().copied().collect();
        keys.sort_unstable();
        for key in keys {
            if let Some(t) = tally.get(&key) {
                self.pair_facts(w, key, t, &mut out);
            }
        }
        out
    }

    /// `Stationary`, object turns and the map facts of each actor seen in
    /// the window.
    fn object_facts(&self, w: (u32, u32, u32), out: &mut Vec<Fact>) {
        let cfg = &self.cfg;
        let (_, first, last) = w;
        let mut map_facts: Vec<MapFact> = Vec::new();
        for a in &self.actors {
            let r = a.range(first, last);
            if r.is_empty() {
                continue;
            }
            if a.travel < cfg.stationary_max_travel_m {
                out.push(self.fact(
                    w,
                    "Stationary",
                    vec![a.name.clone()],
                    Some(a.travel),
                    Some(("around.stationary_max_travel_m", cfg.stationary_max_travel_m)),
                    format!(
                        "its centre stays within {:.2} m of where it was first seen (frame {}) over the whole log, < stationary_max_travel_m {:.1} m",
                        a.travel, a.frames[0], cfg.stationary_max_travel_m
                    ),
                ));
            }
            if !a.ego {
                self.turn_facts(w, a, r.clone(), out);
            }
            if let Some(m) = &self.map {
                map_facts.clear();
                object_map_facts(
                    m,
                    cfg,
                    &a.name,
                    &a.spots[r.clone()],
                    &a.frames[r],
                    &mut map_facts,
                );
                for f in map_facts.drain(..) {
                    out.push(self.fact(w, f.predicate, f.args, f.measured, f.threshold, f.note));
                }
            }
        }
    }

    /// Tallies frame `f`'s pairs: the distance-pruned ones (a sweep over
    /// the frame's actors sorted by world X) and those sharing a lane.
    fn frame_pairs(
        &self,
        f: u32,
        first: u32,
        in_range: &[bool],
        tally: &mut HashMap<(u32, u32), Tally>,
    ) {
        let (Some(&lo), Some(&hi)) = (
            self.offsets.get(f as usize),
            self.offsets.get(f as usize + 1),
        ) else {
            return;
        };
        let ents = &self.entries[lo..hi];
        let r = self.radius;
        let ranged = |a: u32| in_range.get(a as usize).copied().unwrap_or(false);
        for (i, &(a, ka)) in ents.iter().enumerate() {
            if !ranged(a) {
                continue;
            }
            let pa = self.actors[a as usize].pos[ka as usize];
            for &(b, kb) in &ents[i + 1..] {
                let pb = self.actors[b as usize].pos[kb as usize];
                if pb.x() - pa.x() > r {
                    break;
                }
                if !ranged(b) {
                    continue;
                }
                let d = (pb.0 - pa.0).norm();
                if d > r {
                    continue;
                }
                let (x, y) = if a < b {
                    ((a, ka), (b, kb))
                } else {
                    ((b, kb), (a, ka))
                };
                self.symmetric(f, x, y, d, tally.entry((x.0, y.0)).or_default());
                self.directed(f, first, x, y, d, tally.entry((x.0, y.0)).or_default());
                self.directed(f, first, y, x, d, tally.entry((y.0, x.0)).or_default());
            }
        }
        let Some(map) = &self.map else {
            return;
        };
        let mut on: Vec<(u32, u32)> = ents
            .iter()
            .filter(|&&(a, _)| ranged(a))
            .filter_map(|&(a, k)| Some((self.actors[a as usize].spots[k as usize].lane?, a)))
            .collect();
        on.sort_unstable();
        for group in on.chunk_by(|p, q| p.0 == q.0) {
            for (i, &(lane, a)) in group.iter().enumerate() {
                for &(_, b) in &group[i + 1..] {
                    let key = (a.min(b), a.max(b));
                    tally.entry(key).or_default()[SAME_LANE].add(f, 0.0, map.lane_id(lane));
                }
            }
        }
    }

    /// `Near` and the heading relations of `x` and `y` (sightings `kx`,
    /// `ky`, centres `d` apart) in frame `f`.
    fn symmetric(&self, f: u32, (x, kx): (u32, u32), (y, ky): (u32, u32), d: f64, t: &mut Tally) {
        let cfg = &self.cfg;
        let (ax, ay) = (&self.actors[x as usize], &self.actors[y as usize]);
        // Near(x, ego) is the location rule's (facts.rs), not repeated.
        if d <= cfg.near_m && !ax.ego && !ay.ego {
            t[NEAR].add(f, d, 0);
        }
        if let (Some(hx), Some(hy)) = (ax.heading[kx as usize], ay.heading[ky as usize]) {
            let diff = wrap_angle(hx - hy).abs().to_degrees();
            let slot = if diff <= cfg.same_direction_max_deg {
                SAME
            } else if diff >= cfg.opposite_min_deg {
                OPPOSITE
            } else {
                PERPENDICULAR
            };
            t[slot].add(f, diff, 0);
        }
    }

    /// The relations of `x` to `y` in frame `f`: `InDirectionOf(x, y, D)`
    /// (x in y's frame), `HeadingToward(x, y)`, `Following(x, y)` and
    /// `CrossedBy(x, y)` (y crosses x's path ahead, from the frame before,
    /// when that is in the window).
    fn directed(
        &self,
        f: u32,
        first: u32,
        (x, kx): (u32, u32),
        (y, ky): (u32, u32),
        d: f64,
        t: &mut Tally,
    ) {
        let cfg = &self.cfg;
        let (ax, ay) = (&self.actors[x as usize], &self.actors[y as usize]);
        let (kx, ky) = (kx as usize, ky as usize);
        let (px, py) = (ax.pos[kx], ay.pos[ky]);
        if let Some(hy) = ay.heading[ky]
            && d <= cfg.direction_within_m
        {
            let (fwd, right) = local(py, hy, px);
            let [hl, hw] = ay.half;
            let lat = cfg.direction_lateral_m.unwrap_or(f64::INFINITY);
            let along = right.abs() <= hw + lat;
            let beside = fwd.abs() <= hl + lat;
            if fwd > hl && along {
                t[FORWARD].add(f, d, 0);
            }
            if fwd < -hl && along {
                t[BACKWARD].add(f, d, 0);
            }
            if right > hw && beside {
                t[RIGHT].add(f, d, 0);
            }
            if right < -hw && beside {
                t[LEFT].add(f, d, 0);
            }
        }
        let speed = ax.speed(kx);
        if speed >= cfg.heading_toward_min_speed_mps && d <= cfg.heading_toward_max_m && d > 0.0 {
            let to = py.0 - px.0;
            let v = ax.vel[kx];
            let cos = ((v[0] * to.x + v[1] * to.y) / (speed * d)).clamp(-1.0, 1.0);
            let angle = cos.acos().to_degrees();
            if angle <= cfg.heading_toward_max_deg {
                t[TOWARD].add(f, angle, 0);
            }
        }
        let Some(hx) = ax.heading[kx] else {
            return;
        };
        if let (Some(map), Some(hy)) = (&self.map, ay.heading[ky])
            && let (Some(lx), Some(ly)) = (ax.spots[kx].lane, ay.spots[ky].lane)
            && (lx == ly || map.is_successor(lx, ly))
            && speed >= cfg.heading_min_speed_mps
            && wrap_angle(hx - hy).abs().to_degrees() <= cfg.same_direction_max_deg
        {
            let (fwd, _) = local(px, hx, py);
            let gap = (fwd - ax.half[0] - ay.half[0]).max(0.0);
            if fwd > 0.0 && gap <= cfg.following_max_m {
                t[FOLLOWING].add(f, gap, map.lane_id(ly));
            }
        }
        if f > first
            && let (Some(jx), Some(jy)) = (ax.previous(kx, f), ay.previous(ky, f))
            && let Some(hx0) = ax.heading[jx]
        {
            let (f0, l0) = local(ax.pos[jx], hx0, ay.pos[jy]);
            let (f1, l1) = local(px, hx, py);
            let [hl, hw] = ax.half;
            let band = hw + cfg.crossing_lateral_m;
            if (l0 < 0.0) != (l1 < 0.0) && l0.abs() <= band && l1.abs() <= band {
                let s = l0 / (l0 - l1);
                let at = f0 + s * (f1 - f0);
                if at > hl && at <= hl + cfg.crossing_forward_m {
                    t[CROSSED].add(f, at - hl, 0);
                }
            }
        }
    }

    /// The frames in `first..=last` both actors are seen in.
    fn common(&self, x: u32, y: u32, first: u32, last: u32) -> usize {
        let (ax, ay) = (&self.actors[x as usize], &self.actors[y as usize]);
        let (a, b) = (
            &ax.frames[ax.range(first, last)],
            &ay.frames[ay.range(first, last)],
        );
        let (mut i, mut j, mut n) = (0, 0, 0);
        while i < a.len() && j < b.len() {
            match a[i].cmp(&b[j]) {
                std::cmp::Ordering::Less => i += 1,
                std::cmp::Ordering::Greater => j += 1,
                std::cmp::Ordering::Equal => {
                    n += 1;
                    i += 1;
                    j += 1;
                }
            }
        }
        n
    }

    /// The facts a pair's window tally supports: each relation that held
    /// in at least `min_frame_fraction` of the frames both are seen in
    /// (`CrossedBy`: once).
    fn pair_facts(&self, w: (u32, u32, u32), (x, y): (u32, u32), t: &Tally, out: &mut Vec<Fact>) {
        let cfg = &self.cfg;
        let common = self.common(x, y, w.1, w.2);
        let need = (cfg.min_frame_fraction * common as f64).max(1.0);
        let holds = |s: &Slot| s.n > 0 && f64::from(s.n) >= need;
        let (nx, ny) = (
            self.actors[x as usize].name.as_str(),
            self.actors[y as usize].name.as_str(),
        );
        let share = |s: &Slot| {
            format!(
                "in {} of the {common} frames both are seen in (min_frame_fraction {:.2}), first in frame {}",
                s.n, cfg.min_frame_fraction, s.frame
            )
        };
        let mut emit = |pred: &str,
                        args: &[&str],
                        s: &Slot,
                        threshold: Option<(&str, f64)>,
                        measured: Option<f64>,
                        what: String| {
            let args = args.iter().map(|a| (*a).to_string()).collect();
            out.push(self.fact(
                w,
                pred,
                args,
                measured,
                threshold,
                format!("{what} {}", share(s)),
            ));
        };
        // Symmetric relations are tallied once, under (lower, higher).
        if x < y {
            let sym: [(usize, &str, &str, f64, String); 5] = [
                (
                    NEAR,
                    "Near",
                    "around.near_m",
                    cfg.near_m,
                    format!(
                        "centres {:.1} m apart on average, at most near_m {:.1} m,",
                        t[NEAR].mean(),
                        cfg.near_m
                    ),
                ),
                (
                    SAME,
                    "SameDirection",
                    "around.same_direction_max_deg",
                    cfg.same_direction_max_deg,
                    format!(
                        "headings {:.0}° apart on average, at most same_direction_max_deg {:.0}°,",
                        t[SAME].mean(),
                        cfg.same_direction_max_deg
                    ),
                ),
                (
                    OPPOSITE,
                    "Opposite",
                    "around.opposite_min_deg",
                    cfg.opposite_min_deg,
                    format!(
                        "headings {:.0}° apart on average, at least opposite_min_deg {:.0}°,",
                        t[OPPOSITE].mean(),
                        cfg.opposite_min_deg
                    ),
                ),
                (
                    PERPENDICULAR,
                    "Perpendicular",
                    "around.opposite_min_deg",
                    cfg.opposite_min_deg,
                    format!(
                        "headings {:.0}° apart on average, between same_direction_max_deg {:.0}° and opposite_min_deg {:.0}°,",
                        t[PERPENDICULAR].mean(),
                        cfg.same_direction_max_deg,
                        cfg.opposite_min_deg
                    ),
                ),
                (
                    SAME_LANE,
                    "SameLane",
                    "around.min_frame_fraction",
                    cfg.min_frame_fraction,
                    format!(
                        "both centres inside lane segment {} (first shared lane),",
                        t[SAME_LANE].element
                    ),
                ),
            ];
            for (slot, pred, field, thr, what) in sym {
                let s = &t[slot];
                if holds(s) {
                    let measured = if slot == SAME_LANE {
                        Some(f64::from(s.n) / common.max(1) as f64)
                    } else {
                        Some(s.mean())
                    };
                    emit(
                        pred,
                        &[nx, ny],
                        s,
                        Some((field, thr)),
                        measured,
                        what.clone(),
                    );
                    emit(pred, &[ny, nx], s, Some((field, thr)), measured, what);
                }
            }
        }
        for (slot, dir) in [
            (FORWARD, "Forward"),
            (BACKWARD, "Backward"),
            (LEFT, "Left"),
            (RIGHT, "Right"),
        ] {
            let s = &t[slot];
            if holds(s) {
                let lateral = cfg
                    .direction_lateral_m
                    .map_or("unlimited".to_string(), |l| format!("{l:.1} m"));
                emit(
                    "InDirectionOf",
                    &[nx, ny, dir],
                    s,
                    Some(("around.direction_within_m", cfg.direction_within_m)),
                    Some(s.mean()),
                    format!(
                        "{nx}'s centre lies {} of {ny} in {ny}'s own frame (beyond its box, direction_lateral_m {lateral}), {:.1} m away on average (at most direction_within_m {:.1} m),",
                        dir.to_lowercase(),
                        s.mean(),
                        cfg.direction_within_m
                    ),
                );
            }
        }
        let s = &t[TOWARD];
        if holds(s) {
            emit(
                "HeadingToward",
                &[nx, ny],
                s,
                Some(("around.heading_toward_max_deg", cfg.heading_toward_max_deg)),
                Some(s.mean()),
                format!(
                    "{nx}'s velocity (at least heading_toward_min_speed_mps {:.1} m/s) points {:.1}° on average from the direction to {ny} (at most heading_toward_max_deg {:.1}°, within heading_toward_max_m {:.0} m),",
                    cfg.heading_toward_min_speed_mps,
                    s.mean(),
                    cfg.heading_toward_max_deg,
                    cfg.heading_toward_max_m
                ),
            );
        }
        let s = &t[FOLLOWING];
        if holds(s) {
            emit(
                "Following",
                &[nx, ny],
                s,
                Some(("around.following_max_m", cfg.following_max_m)),
                Some(s.mean()),
                format!(
                    "{nx} moves behind {ny} in the same direction in lane segment {} (or {ny} in its successor), gap {:.1} m on average (at most following_max_m {:.1} m),",
                    s.element,
                    s.mean(),
                    cfg.following_max_m
                ),
            );
        }
        let s = &t[CROSSED];
        if s.n > 0 {
            out.push(self.fact(
                w,
                "CrossedBy",
                vec![nx.to_string(), ny.to_string()],
                Some(s.mean()),
                Some(("around.crossing_forward_m", cfg.crossing_forward_m)),
                format!(
                    "{ny}'s centre crosses the line ahead of {nx} along its heading between frames {} and {}, {:.1} m beyond its front (at most crossing_forward_m {:.1} m; within crossing_lateral_m {:.1} m of its sides on both frames)",
                    s.frame.saturating_sub(1),
                    s.frame,
                    s.mean(),
                    cfg.crossing_forward_m,
                    cfg.crossing_lateral_m
                ),
            ));
        }
    }
}

impl Actor {
    /// An actor from its sightings' world centres and box headings:
    /// velocities by central differences over ±[`VELOCITY_HALF_SPAN`]
    /// frames, headings of motion where fast enough.
    #[allow(clippy::too_many_arguments)]
    fn new(
        name: &str,
        ego: bool,
        headed: bool,
        frames: Vec<u32>,
        pos: Vec<WorldBev>,
        boxed: Vec<Option<f64>>,
        half: [f64; 2],
        cfg: &AroundConfig,
        times: &[f64],
    ) -> Actor {
        let n = frames.len();
        let time = |f: u32| times.get(f as usize).copied().unwrap_or(0.0);
        let mut vel = Vec::with_capacity(n);
        let mut heading = Vec::with_capacity(n);
        for k in 0..n {
            let f = frames[k];
            let lo = frames[..k].partition_point(|g| *g + VELOCITY_HALF_SPAN < f);
            let hi = k + frames[k..].partition_point(|g| *g <= f + VELOCITY_HALF_SPAN) - 1;
            let dt = time(frames[hi]) - time(frames[lo]);
            let v = if hi > lo && dt > 0.0 {
                let d = pos[hi].0 - pos[lo].0;
                [d.x / dt, d.y / dt]
            } else {
                [0.0, 0.0]
            };
            let speed = v[0].hypot(v[1]);
            // The box's heading when labelled: the velocity of a slow or
            // partly seen object swings (an annotated parked car drifting
            // 0.5 m/s sideways), and switching between the two at the
            // speed threshold made 90° turns out of nothing.
            heading.push(if !headed {
                None
            } else {
                boxed[k].or((speed >= cfg.heading_min_speed_mps).then(|| v[0].atan2(v[1])))
            });
            vel.push(v);
        }
        let travel = pos.first().map_or(0.0, |p0| {
            pos.iter().map(|p| (p.0 - p0.0).norm()).fold(0.0, f64::max)
        });
        Actor {
            name: name.to_string(),
            ego,
            frames,
            pos,
            vel,
            heading,
            half,
            travel,
            spots: Vec::new(),
        }
    }
}

mod turns;

#[cfg(test)]
pub(crate) mod tests;
