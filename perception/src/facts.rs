//! Window facts: the one place every source's [`Sequence`] becomes positive
//! facts with provenance.
//!
//! [`Analysis::new`] does the per-sequence work once: ego-motion
//! ([`crate::ego`]), world-frame trajectories per track with Hampel outlier
//! rejection and Savitzky–Golay smoothing, per-frame speeds. Each window then
//! measures, per object and per pair, the quantities behind the vocabulary
//! and compares them with the named [`FactConfig`] thresholds; every fact's
//! [`Provenance`] carries the measured value and the threshold's field name.
//!
//! Closed world: only positive facts are emitted; `¬Moving(x)` is the
//! absence of `Moving(x)`.

use std::collections::BTreeMap;

use crate::config::FactConfig;
use crate::ego::{self, EgoMotion};
use crate::error::PerceptionError;
use crate::geometry::{
    Bev, convex_gap, covered_fraction, ground_point, observation_footprint, point_in_polygon,
};
use crate::model::{Fact, ObjectClass, Observation, Provenance, Sequence, WindowFacts, WindowSpec};
use crate::signal::{hampel, linear_fit, savgol, slope_with_error};

/// `TypeOf` values the vocabulary declares; other types become `Other`.
pub const TYPE_VALUES: [&str; 19] = [
    "Car",
    "Van",
    "Truck",
    "Tram",
    "Bus",
    "Motorcycle",
    "Bicycle",
    "SUV",
    "Sedan",
    "Coupe",
    "Hatchback",
    "Wagon",
    "Minivan",
    "Cab",
    "Convertible",
    "PoliceCar",
    "Pedestrian",
    "Cyclist",
    "Other",
];

/// `ColorOf` values the vocabulary declares; other colours become `Other`.
pub const COLOR_VALUES: [&str; 13] = [
    "Black", "Blue", "Brown", "Cyan", "Green", "Grey", "Orange", "Red", "Violet", "White",
    "Yellow", "Silver", "Other",
];

/// Footprint side (m) assumed for objects without a labelled size.
const DEFAULT_FOOTPRINT_M: f64 = 0.6;

/// Facts for every window of `seq`: the entry point every source goes through.
pub fn window_facts(
    seq: &Sequence,
    windows: WindowSpec,
    config: &FactConfig,
) -> Result<Vec<WindowFacts>, PerceptionError> {
    // Validate first: the spans are one entry per window of `frame_count`,
    // which must be checked against MAX_FRAMES before it sizes anything.
    let analysis = Analysis::new(seq, config)?;
    let spans = windows.windows(seq.frame_count)?;
    Ok(spans
        .into_iter()
        .map(|(i, a, b)| analysis.window(i, a, b))
        .collect())
}

/// Facts for the single window `first..=last` (index 0), with look-back and
/// look-ahead into the rest of the sequence.
pub fn range_facts(
    seq: &Sequence,
    first: u32,
    last: u32,
    config: &FactConfig,
) -> Result<WindowFacts, PerceptionError> {
    if first > last || last >= seq.frame_count {
        return Err(PerceptionError::InvalidWindow(format!(
            "frames {first}-{last} are not a range inside the sequence's {} frames",
            seq.frame_count
        )));
    }
    Ok(Analysis::new(seq, config)?.window(0, first, last))
}

/// Per-track state prepared once per sequence.
#[derive(Debug, Clone)]
struct TrackState {
    name: String,
    class: ObjectClass,
    type_value: Option<String>,
    color_value: Option<String>,
    /// Indices into the sequence's observations, ascending frame.
    obs: Vec<usize>,
    /// Frames of `obs`.
    frames: Vec<u32>,
    /// Camera bird's-eye ground point per observation.
    cam: Vec<Option<Bev>>,
    /// Whether this track is a ground surface (has footprints).
    surface: bool,
    /// Frames with a world position, and the Savitzky–Golay speeds (m/s) there.
    w_frames: Vec<f64>,
    /// World positions after outlier rejection, before smoothing (slopes
    /// and their standard errors are measured on these).
    raw_x: Vec<f64>,
    raw_z: Vec<f64>,
    speed: Vec<f64>,
}

/// A sequence prepared for window fact extraction.
#[derive(Debug, Clone)]
pub struct Analysis<'a> {
    seq: &'a Sequence,
    config: &'a FactConfig,
    /// The estimated camera trajectory.
    pub ego: EgoMotion,
    tracks: Vec<TrackState>,
    source: String,
}

fn vocab_value(value: &str, list: &[&str]) -> String {
    list.iter()
        .find(|v| v.eq_ignore_ascii_case(value))
        .map_or_else(|| "Other".to_string(), |v| (*v).to_string())
}

impl<'a> Analysis<'a> {
    /// Validates the inputs, estimates ego-motion and smooths trajectories.
    pub fn new(seq: &'a Sequence, config: &'a FactConfig) -> Result<Analysis<'a>, PerceptionError> {
        seq.validate()?;
        config.validate()?;
        let ego = ego::estimate(seq, &config.ego);
        let mut by_id: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
        for (i, o) in seq.observations.iter().enumerate() {
            by_id.entry(o.track_id).or_default().push(i);
        }
        let half = f64::from(config.savgol_window / 2);
        let order = config.savgol_order as usize;
        let mut tracks = Vec::with_capacity(by_id.len());
        for (id, obs) in by_id {
            let Some(&first) = obs.first() else { continue };
            let o0 = &seq.observations[first];
            let type_name = obs
                .iter()
                .find_map(|&i| seq.observations[i].type_name.as_deref());
            let color = obs
                .iter()
                .find_map(|&i| seq.observations[i].color.as_deref());
            let frames: Vec<u32> = obs.iter().map(|&i| seq.observations[i].frame).collect();
            let cam: Vec<Option<Bev>> = obs
                .iter()
                .map(|&i| ground_point(&seq.observations[i], &seq.camera))
                .collect();
            let surface = obs.iter().any(|&i| seq.observations[i].footprint.is_some());
            let (mut w_frames, mut w_x, mut w_z) = (Vec::new(), Vec::new(), Vec::new());
            if !surface {
                for (f, c) in frames.iter().zip(&cam) {
                    if let Some(c) = c {
                        let w = ego.to_world(*f, *c);
                        w_frames.push(f64::from(*f));
                        w_x.push(w[0]);
                        w_z.push(w[1]);
                    }
                }
            }
            // Outliers first (a single bad box would bend the slopes), then
            // the Savitzky–Golay derivative for per-frame speeds.
            let hw = config.savgol_window as usize / 2 + 1;
            hampel(&mut w_x, hw, config.outlier_mad_k, 0.2);
            hampel(&mut w_z, hw, config.outlier_mad_k, 0.2);
            let vx = savgol(&w_frames, &w_x, half, order, 1);
            let vz = savgol(&w_frames, &w_z, half, order, 1);
            let speed = vx
                .iter()
                .zip(&vz)
                .map(|(a, b)| (a * a + b * b).sqrt() * seq.fps)
                .collect();
            tracks.push(TrackState {
                name: crate::model::object_name_for(type_name, o0.class, id),
                class: o0.class,
                type_value: type_name.map(|t| vocab_value(t, &TYPE_VALUES)),
                color_value: color.map(|c| vocab_value(c, &COLOR_VALUES)),
                obs,
                frames,
                cam,
                surface,
                w_frames,
                raw_x: w_x,
                raw_z: w_z,
                speed,
            });
        }
        Ok(Analysis {
            seq,
            config,
            ego,
            tracks,
            source: seq.source_label(),
        })
    }

    /// Facts of the window `first..=last` with index `index`.
    pub fn window(&self, index: u32, first: u32, last: u32) -> WindowFacts {
        let mut w = WindowCtx {
            a: self,
            index,
            first,
            last,
            facts: Vec::new(),
        };
        let mut present: Vec<(usize, std::ops::Range<usize>)> = Vec::new();
        for (ti, t) in self.tracks.iter().enumerate() {
            let lo = t.frames.partition_point(|f| *f < first);
            let hi = t.frames.partition_point(|f| *f <= last);
            if lo < hi {
                present.push((ti, lo..hi));
            }
        }
        for (ti, r) in &present {
            w.object_facts(&self.tracks[*ti], r.clone());
        }
        w.pair_facts(&present);
        let mut out = WindowFacts {
            index,
            first_frame: first,
            last_frame: last,
            facts: w.facts,
        };
        out.normalize();
        out
    }
}

struct WindowCtx<'w, 'a> {
    a: &'w Analysis<'a>,
    index: u32,
    first: u32,
    last: u32,
    facts: Vec<Fact>,
}

impl WindowCtx<'_, '_> {
    fn push(
        &mut self,
        predicate: &str,
        args: &[&str],
        measured: Option<f64>,
        threshold: Option<(&str, f64)>,
        note: String,
    ) {
        self.facts.push(Fact {
            predicate: predicate.to_string(),
            args: args.iter().map(|s| (*s).to_string()).collect(),
            provenance: Provenance {
                window: self.index,
                frames: (self.first, self.last),
                source: self.a.source.clone(),
                measured,
                threshold: threshold.map(|(n, v)| (n.to_string(), v)),
                note,
            },
        });
    }

    fn obs(&self, t: &TrackState, k: usize) -> &Observation {
        &self.a.seq.observations[t.obs[k]]
    }

    fn x_fraction(&self, o: &Observation) -> f64 {
        o.bbox.center_x() / f64::from(self.a.seq.camera.intrinsics.image_width)
    }

    fn side(&self, frac: f64) -> (&'static str, &'static str, f64) {
        let c = self.a.config;
        if frac < c.left_fraction {
            ("Left", "left_fraction", c.left_fraction)
        } else if frac > c.right_fraction {
            ("Right", "right_fraction", c.right_fraction)
        } else {
            ("Front", "left_fraction", c.left_fraction)
        }
    }

    fn location(&mut self, pred: &str, t: &TrackState, k: usize) {
        let o = self.obs(t, k);
        let frac = self.x_fraction(o);
        let frame = o.frame;
        let (side, field, thr) = self.side(frac);
        self.push(
            pred,
            &[&t.name, side],
            Some(frac),
            Some((field, thr)),
            format!("box centre at {frac:.2} of the image width in frame {frame}"),
        );
        if let Some(g) = t.cam[k] {
            let c = self.a.config;
            let near = g[1] < c.near_far_m;
            let value = format!("{}{side}", if near { "Near" } else { "Far" });
            self.push(
                pred,
                &[&t.name, &value],
                Some(g[1]),
                Some(("near_far_m", c.near_far_m)),
                format!(
                    "depth {:.1} m {} near_far_m {:.1} m in frame {frame}",
                    g[1],
                    if near { "<" } else { ">=" },
                    c.near_far_m
                ),
            );
        }
    }

    fn object_facts(&mut self, t: &TrackState, r: std::ops::Range<usize>) {
        let cfg = self.a.config;
        let name = t.name.as_str();
        let class = t.class.predicate();
        self.push(
            class,
            &[name],
            None,
            None,
            format!("class of track {}", t.name),
        );
        if let Some(v) = &t.type_value {
            self.push(
                "TypeOf",
                &[name, v],
                None,
                None,
                "type from the source".into(),
            );
        }
        if let Some(v) = &t.color_value {
            self.push(
                "ColorOf",
                &[name, v],
                None,
                None,
                "colour from the source".into(),
            );
        }
        // Appear / Disappear with look-back / look-ahead beyond the window.
        let k0 = r.start;
        let k1 = r.end - 1;
        let f_in = t.frames[k0];
        let seen_before = k0 > 0 && f_in - t.frames[k0 - 1] <= cfg.appear_lookback_frames;
        if f_in > 0 && !seen_before {
            self.push(
                "Appear",
                &[name],
                Some(f64::from(f_in)),
                Some((
                    "appear_lookback_frames",
                    f64::from(cfg.appear_lookback_frames),
                )),
                format!(
                    "first seen in frame {f_in}, not in the {} frames before",
                    cfg.appear_lookback_frames
                ),
            );
        }
        let f_out = t.frames[k1];
        let seen_after =
            k1 + 1 < t.frames.len() && t.frames[k1 + 1] - f_out <= cfg.disappear_lookahead_frames;
        if f_out + 1 < self.a.seq.frame_count && !seen_after {
            self.push(
                "Disappear",
                &[name],
                Some(f64::from(f_out)),
                Some((
                    "disappear_lookahead_frames",
                    f64::from(cfg.disappear_lookahead_frames),
                )),
                format!(
                    "last seen in frame {f_out}, not in the {} frames after",
                    cfg.disappear_lookahead_frames
                ),
            );
        }
        self.location("InitialLocation", t, k0);
        self.location("LastLocation", t, k1);
        // AtLeft / AtRight / AtCenter from the median box centre.
        let fracs: Vec<f64> = (k0..=k1).map(|k| self.x_fraction(self.obs(t, k))).collect();
        if let Some(m) = crate::signal::median(&fracs) {
            let (side, field, thr) = self.side(m);
            let pred = match side {
                "Left" => "AtLeft",
                "Right" => "AtRight",
                _ => "AtCenter",
            };
            self.push(
                pred,
                &[name],
                Some(m),
                Some((field, thr)),
                format!("median box centre at {m:.2} of the image width"),
            );
        }
        // CloseToCamera from the nearest ground distance.
        let nearest = (k0..=k1)
            .filter_map(|k| t.cam[k])
            .map(|g| (g[0] * g[0] + g[1] * g[1]).sqrt())
            .fold(f64::INFINITY, f64::min);
        // A surface reaches under the car whenever it is in view; nearness
        // says nothing about it.
        if nearest < cfg.close_to_camera_m && !t.surface {
            self.push(
                "CloseToCamera",
                &[name],
                Some(nearest),
                Some(("close_to_camera_m", cfg.close_to_camera_m)),
                format!(
                    "nearest ground distance {nearest:.1} m < close_to_camera_m {:.1} m",
                    cfg.close_to_camera_m
                ),
            );
        }
        if !t.class.is_static() && !t.surface {
            self.motion_facts(t);
        }
    }

    fn motion_facts(&mut self, t: &TrackState) {
        let cfg = self.a.config;
        let fps = self.a.seq.fps;
        let lo = t.w_frames.partition_point(|f| *f < f64::from(self.first));
        let hi = t.w_frames.partition_point(|f| *f <= f64::from(self.last));
        if hi < lo + cfg.min_observations as usize || hi < lo + 2 {
            return;
        }
        let ts = &t.w_frames[lo..hi];
        let (Some((vx, ex)), Some((vz, ez))) = (
            slope_with_error(ts, &t.raw_x[lo..hi]),
            slope_with_error(ts, &t.raw_z[lo..hi]),
        ) else {
            return;
        };
        let k = cfg.trend_significance;
        let speed = (vx * vx + vz * vz).sqrt() * fps;
        // Standard error of the speed (delta method on |v|).
        let speed_se = if speed > 0.0 {
            ((vx * ex).powi(2) + (vz * ez).powi(2)).sqrt() / (vx * vx + vz * vz).sqrt() * fps
        } else {
            ex.max(ez) * fps
        };
        let (field, thr) = cfg.moving_threshold(t.class);
        let name = t.name.as_str();
        if speed - k * speed_se > thr {
            self.push(
                "Moving",
                &[name],
                Some(speed),
                Some((field, thr)),
                format!("world speed {speed:.2} ± {speed_se:.2} m/s > {field} {thr:.2} m/s"),
            );
        }
        let sp = &t.speed[lo..hi];
        let Some((slope, slope_se)) = slope_with_error(ts, sp) else {
            return;
        };
        let accel = slope * fps;
        let margin = k * slope_se * fps;
        let span = ts[ts.len() - 1] - ts[0];
        let change = slope * span;
        let peak = sp.iter().copied().fold(0.0, f64::max);
        if peak <= thr {
            return;
        }
        if accel - margin > cfg.speed_change_mps2 && change > cfg.speed_change_min_mps {
            self.push("SpeedUp", &[name], Some(accel), Some(("speed_change_mps2", cfg.speed_change_mps2)),
                format!("acceleration {accel:.2} m/s² > speed_change_mps2 {:.2} (speed {:.1} → {:.1} m/s)", cfg.speed_change_mps2, sp[0], sp[sp.len() - 1]));
        } else if accel + margin < -cfg.speed_change_mps2 && change < -cfg.speed_change_min_mps {
            self.push("SpeedDown", &[name], Some(accel), Some(("speed_change_mps2", cfg.speed_change_mps2)),
                format!("acceleration {accel:.2} m/s² < -speed_change_mps2 {:.2} (speed {:.1} → {:.1} m/s)", cfg.speed_change_mps2, sp[0], sp[sp.len() - 1]));
        }
    }

    fn pair_facts(&mut self, present: &[(usize, std::ops::Range<usize>)]) {
        let tracks = &self.a.tracks;
        for (i, (ti, ri)) in present.iter().enumerate() {
            let x = &tracks[*ti];
            if x.surface {
                continue;
            }
            for (tj, rj) in present.iter().skip(i + 1) {
                let y = &tracks[*tj];
                if y.surface {
                    continue;
                }
                if x.class.is_static() && y.class.is_static() {
                    continue;
                }
                self.distance_facts(x, ri.clone(), y, rj.clone());
            }
        }
        // On(x, y): road users on surfaces, people on vehicles.
        for (ti, ri) in present {
            let x = &tracks[*ti];
            if x.surface || x.class.is_static() {
                continue;
            }
            for (tj, rj) in present {
                if ti == tj {
                    continue;
                }
                let y = &tracks[*tj];
                if y.surface {
                    self.on_surface(x, ri.clone(), y, rj.clone());
                } else if x.class.is_person_like() && y.class == ObjectClass::Vehicle {
                    self.on_vehicle(x, ri.clone(), y, rj.clone());
                }
            }
        }
    }

    /// Frames where both are observed: pairs of observation indices.
    fn common(
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) -> Vec<(usize, usize)> {
        let (mut a, mut b) = (rx.start, ry.start);
        let mut out = Vec::new();
        while a < rx.end && b < ry.end {
            match x.frames[a].cmp(&y.frames[b]) {
                std::cmp::Ordering::Less => a += 1,
                std::cmp::Ordering::Greater => b += 1,
                std::cmp::Ordering::Equal => {
                    out.push((a, b));
                    a += 1;
                    b += 1;
                }
            }
        }
        out
    }

    fn distance_facts(
        &mut self,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let cfg = self.a.config;
        let fps = self.a.seq.fps;
        let mut ts = Vec::new();
        let mut gaps = Vec::new();
        for (a, b) in Self::common(x, rx, y, ry) {
            let (Some(pa), Some(pb)) = (x.cam[a], y.cam[b]) else {
                continue;
            };
            let fa = observation_footprint(pa, self.obs(x, a), DEFAULT_FOOTPRINT_M);
            let fb = observation_footprint(pb, self.obs(y, b), DEFAULT_FOOTPRINT_M);
            ts.push(f64::from(x.frames[a]));
            gaps.push(convex_gap(&fa, &fb));
        }
        if gaps.is_empty() {
            return;
        }
        let (xn, yn) = (x.name.as_str(), y.name.as_str());
        let both =
            |s: &mut Self, pred: &str, m: Option<f64>, th: Option<(&str, f64)>, note: String| {
                s.push(pred, &[xn, yn], m, th, note.clone());
                s.push(pred, &[yn, xn], m, th, note);
            };
        let (g0, g1) = (gaps[0], gaps[gaps.len() - 1]);
        let min_gap = gaps.iter().copied().fold(f64::INFINITY, f64::min);
        if min_gap < cfg.too_close_distance_m {
            both(
                self,
                "TooClose",
                Some(min_gap),
                Some(("too_close_distance_m", cfg.too_close_distance_m)),
                format!(
                    "smallest gap {min_gap:.2} m < too_close_distance_m {:.2} m",
                    cfg.too_close_distance_m
                ),
            );
        }
        if g0 <= cfg.touch_distance_m {
            both(
                self,
                "DistanceZeroStart",
                Some(g0),
                Some(("touch_distance_m", cfg.touch_distance_m)),
                format!(
                    "gap {g0:.2} m <= touch_distance_m {:.2} m at frame {}",
                    cfg.touch_distance_m, ts[0]
                ),
            );
        }
        if g1 <= cfg.touch_distance_m {
            both(
                self,
                "DistanceZeroEnd",
                Some(g1),
                Some(("touch_distance_m", cfg.touch_distance_m)),
                format!(
                    "gap {g1:.2} m <= touch_distance_m {:.2} m at frame {}",
                    cfg.touch_distance_m,
                    ts[ts.len() - 1]
                ),
            );
        }
        if gaps.len() < cfg.min_observations as usize {
            return;
        }
        let Some((slope, _)) = linear_fit(&ts, &gaps) else {
            return;
        };
        // The pair's gap trend was measured: rules such as ConstantDistance
        // need a positive atom that binds both objects before they may say
        // "neither closer nor farther" under negation.
        both(
            self,
            "SharesFrames",
            Some(gaps.len() as f64),
            Some(("min_observations", f64::from(cfg.min_observations))),
            format!(
                "gap measured in {} common frames >= min_observations {}",
                gaps.len(),
                cfg.min_observations
            ),
        );
        let rate = slope * fps;
        let change = slope * (ts[ts.len() - 1] - ts[0]);
        if rate < -cfg.distance_rate_mps && change < -cfg.distance_change_min_m {
            both(
                self,
                "DistanceDecrease",
                Some(rate),
                Some(("distance_rate_mps", cfg.distance_rate_mps)),
                format!(
                    "gap shrinks at {:.2} m/s ({g0:.1} → {g1:.1} m), faster than distance_rate_mps {:.2}",
                    -rate, cfg.distance_rate_mps
                ),
            );
            if g1 <= cfg.touch_distance_m && g0 > cfg.touch_distance_m {
                both(
                    self,
                    "DistanceDecreasesToZero",
                    Some(g1),
                    Some(("touch_distance_m", cfg.touch_distance_m)),
                    format!(
                        "gap closes from {g0:.1} m to {g1:.2} m <= touch_distance_m {:.2}",
                        cfg.touch_distance_m
                    ),
                );
            }
        } else if rate > cfg.distance_rate_mps && change > cfg.distance_change_min_m {
            both(
                self,
                "DistanceIncrease",
                Some(rate),
                Some(("distance_rate_mps", cfg.distance_rate_mps)),
                format!(
                    "gap grows at {rate:.2} m/s ({g0:.1} → {g1:.1} m), faster than distance_rate_mps {:.2}",
                    cfg.distance_rate_mps
                ),
            );
        }
    }

    fn on_surface(
        &mut self,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let frames = rx.len();
        let on = Self::common(x, rx, y, ry)
            .into_iter()
            .filter(
                |&(a, b)| match (x.cam[a], self.obs(y, b).footprint.as_ref()) {
                    (Some(p), Some(poly)) => point_in_polygon(p, poly),
                    _ => false,
                },
            )
            .count();
        self.on_fact(x, y, on, frames, "ground point inside the surface");
    }

    fn on_vehicle(
        &mut self,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let frames = rx.len();
        let on = Self::common(x, rx, y, ry)
            .into_iter()
            .filter(|&(a, b)| match (x.cam[a], y.cam[b]) {
                (Some(pa), Some(pb)) => {
                    let fa = observation_footprint(pa, self.obs(x, a), DEFAULT_FOOTPRINT_M);
                    let fb = observation_footprint(pb, self.obs(y, b), DEFAULT_FOOTPRINT_M);
                    covered_fraction(&fa, &fb) >= 0.5
                }
                _ => false,
            })
            .count();
        self.on_fact(x, y, on, frames, "footprint mostly over the vehicle's");
    }

    fn on_fact(&mut self, x: &TrackState, y: &TrackState, on: usize, frames: usize, what: &str) {
        if on == 0 || frames == 0 {
            return;
        }
        let cfg = self.a.config;
        let frac = on as f64 / frames as f64;
        if frac >= cfg.on_min_fraction {
            self.push(
                "On",
                &[&x.name, &y.name],
                Some(frac),
                Some(("on_min_fraction", cfg.on_min_fraction)),
                format!("{what} in {on} of {frames} frames"),
            );
        }
    }
}
