//! The per-sequence work done once: trajectories smoothed (Kalman/RTS,
//! Hampel, Savitzky–Golay), the ego's own track and heading, and
//! [`Analysis`] itself, which then measures each window.

use std::collections::BTreeMap;

use crate::config::FactConfig;
use crate::coords::CameraBev;
use crate::ego::{self, EgoMotion};
use crate::error::PerceptionError;
use crate::geometry::ground_point;
use crate::model::{ObjectClass, Sequence, WindowFacts};
use crate::signal::{CaSmoothed, ca_rts, cv_rts, hampel};

use super::{Analysis, COLOR_VALUES, EGO, TrackState, WindowCtx, type_value, vocab_value};

/// What the smoothers make of one trajectory of world positions (a
/// track's, or the ego's own).
struct Smoothed {
    kal_speed: Vec<f64>,
    kal_speed_sd: Vec<f64>,
    ca: [CaSmoothed; 2],
    kal_rejected: usize,
    hampel_replaced: usize,
}

impl Smoothed {
    /// Smooths the world positions `(w_x, w_z)` at frames `w_frames` with
    /// measurement variances `(r_x, r_z)`: the constant-velocity and
    /// constant-acceleration Kalman/RTS smoothers on the positions as
    /// given, then the Hampel filter replaces outliers in `w_x`, `w_z` in
    /// place (for the least-squares slopes).
    fn of(
        config: &FactConfig,
        fps: f64,
        w_frames: &[f64],
        w_x: &mut [f64],
        w_z: &mut [f64],
        r_x: &[f64],
        r_z: &[f64],
    ) -> Smoothed {
        let (mut kal_speed, mut kal_speed_sd, mut kal_rejected) = (Vec::new(), Vec::new(), 0);
        let mut ca = [CaSmoothed::default(), CaSmoothed::default()];
        if !w_frames.is_empty() {
            let secs: Vec<f64> = w_frames.iter().map(|f| f / fps).collect();
            let kx = cv_rts(
                &secs,
                w_x,
                r_x,
                config.kalman_accel_psd,
                config.kalman_gate_sd,
            );
            let kz = cv_rts(
                &secs,
                w_z,
                r_z,
                config.kalman_accel_psd,
                config.kalman_gate_sd,
            );
            kal_rejected = kx.rejected.max(kz.rejected);
            // A sighting is an outlier when either axis's gate says so.
            let outliers: Vec<bool> = kx
                .outliers
                .iter()
                .zip(&kz.outliers)
                .map(|(a, b)| *a || *b)
                .collect();
            let q = config.kalman_jerk_psd;
            ca = [
                ca_rts(&secs, w_x, r_x, q, &outliers),
                ca_rts(&secs, w_z, r_z, q, &outliers),
            ];
            for i in 0..secs.len() {
                let (vx, vz) = (kx.velocity[i], kz.velocity[i]);
                let (ax, az) = (kx.velocity_var[i], kz.velocity_var[i]);
                let sp = (vx * vx + vz * vz).sqrt();
                // Delta method on |v|; at rest, the larger axis.
                let var = if sp > 1e-9 {
                    (vx * vx * ax + vz * vz * az) / (sp * sp)
                } else {
                    ax.max(az)
                };
                kal_speed.push(sp);
                kal_speed_sd.push(var.sqrt());
            }
        }
        // Outliers out before the least-squares slopes (a single bad
        // box would bend them).
        let hw = config.savgol_window as usize / 2 + 1;
        let hampel_replaced =
            hampel(w_x, hw, config.outlier_mad_k, 0.2) + hampel(w_z, hw, config.outlier_mad_k, 0.2);
        Smoothed {
            kal_speed,
            kal_speed_sd,
            ca,
            kal_rejected,
            hampel_replaced,
        }
    }
}

/// Median absolute value → standard deviation of a normal variable.
const MAD_TO_SD: f64 = 1.0 / 0.674_489_75;

/// The standard deviation of per-sample noise on a smooth series, from the
/// median absolute second difference (`y(t−1) − 2y(t) + y(t+1)` is about
/// `√6·σ` for independent noise σ on a smooth curve, as
/// [`crate::ego::MeasuredNoise`] measures object positions); 0 for fewer
/// than three samples.
fn second_difference_sd(y: &[f64]) -> f64 {
    let mut d: Vec<f64> = y
        .windows(3)
        .map(|w| (w[0] - 2.0 * w[1] + w[2]).abs())
        .collect();
    crate::signal::median_in_place(&mut d).map_or(0.0, |m| m * MAD_TO_SD / 6f64.sqrt())
}

/// The ego as a track: the estimated camera positions of every frame,
/// smoothed as an object's world positions are, with their measurement
/// noise measured on their own second differences (floored at
/// `kalman_min_sigma_m`); and its unwrapped heading per frame with that
/// heading's noise.
fn ego_track(
    fps: f64,
    config: &FactConfig,
    ego: &EgoMotion,
) -> (TrackState, Vec<f64>, f64, [f64; 2]) {
    let w_frames: Vec<f64> = (0..ego.poses.len()).map(|f| f as f64).collect();
    let mut w_x: Vec<f64> = ego.poses.iter().map(|p| p.position.x()).collect();
    let mut w_z: Vec<f64> = ego.poses.iter().map(|p| p.position.z()).collect();
    let floor = config.kalman_min_sigma_m;
    let sd = [
        second_difference_sd(&w_x).max(floor),
        second_difference_sd(&w_z).max(floor),
    ];
    let r_x = vec![sd[0] * sd[0]; w_x.len()];
    let r_z = vec![sd[1] * sd[1]; w_z.len()];
    let sm = Smoothed::of(config, fps, &w_frames, &mut w_x, &mut w_z, &r_x, &r_z);
    let mut yaw: Vec<f64> = Vec::with_capacity(ego.poses.len());
    for p in &ego.poses {
        let next = match yaw.last() {
            // Each step's wrapped turn added on: a heading that passes ±π
            // keeps counting instead of jumping by 2π.
            Some(&prev) => prev + crate::geometry::wrap_angle(p.yaw - prev),
            None => p.yaw,
        };
        yaw.push(next);
    }
    let yaw_sd = second_difference_sd(&yaw);
    let track = TrackState {
        name: EGO.to_string(),
        track_id: u32::MAX,
        class: ObjectClass::Vehicle,
        type_value: None,
        color_value: None,
        obs: Vec::new(),
        frames: Vec::new(),
        cam: Vec::new(),
        footprints: Vec::new(),
        surface: false,
        w_frames,
        raw_x: w_x,
        raw_z: w_z,
        kal_speed: sm.kal_speed,
        kal_speed_sd: sm.kal_speed_sd,
        ca: sm.ca,
        kal_rejected: sm.kal_rejected,
        hampel_replaced: sm.hampel_replaced,
        ego: true,
    };
    (track, yaw, yaw_sd, sd)
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
            let cam: Vec<Option<CameraBev>> = obs
                .iter()
                .map(|&i| ground_point(&seq.observations[i], &seq.camera))
                .collect();
            let footprints: Vec<Option<Vec<CameraBev>>> = obs
                .iter()
                .map(|&i| seq.observations[i].camera_footprint())
                .collect();
            let surface = footprints.iter().any(Option::is_some);
            let (mut w_frames, mut w_x, mut w_z) = (Vec::new(), Vec::new(), Vec::new());
            // Measurement variances in world X and Z: the measured camera
            // lateral and depth noise, turned by the camera's heading.
            let (mut r_x, mut r_z) = (Vec::new(), Vec::new());
            let floor = config.kalman_min_sigma_m;
            if !surface {
                for (f, c) in frames.iter().zip(&cam) {
                    if let Some((c, w)) = c.and_then(|c| Some((c, ego.to_world(*f, c)?))) {
                        w_frames.push(f64::from(*f));
                        w_x.push(w.x());
                        w_z.push(w.z());
                        let lat = ego.noise.lateral_m.max(floor).powi(2);
                        let dep = ego.noise.depth_sd(c.z().abs()).max(floor).powi(2);
                        let yaw = ego.poses.get(*f as usize).map_or(0.0, |p| p.yaw);
                        let (sn, cs) = yaw.sin_cos();
                        r_x.push(cs * cs * lat + sn * sn * dep);
                        r_z.push(sn * sn * lat + cs * cs * dep);
                    }
                }
            }
            let sm = Smoothed::of(config, seq.fps, &w_frames, &mut w_x, &mut w_z, &r_x, &r_z);
            tracks.push(TrackState {
                name: seq.name_for(type_name, o0.class, id),
                class: o0.class,
                track_id: id,
                type_value: type_name.map(type_value),
                color_value: color.map(|c| vocab_value(c, &COLOR_VALUES)),
                obs,
                frames,
                cam,
                footprints,
                surface,
                w_frames,
                raw_x: w_x,
                raw_z: w_z,
                kal_speed: sm.kal_speed,
                kal_speed_sd: sm.kal_speed_sd,
                ca: sm.ca,
                kal_rejected: sm.kal_rejected,
                hampel_replaced: sm.hampel_replaced,
                ego: false,
            });
        }
        let (ego_track, ego_yaw, ego_yaw_sd, ego_pos_sd) = ego_track(seq.fps, config, &ego);
        let source: std::sync::Arc<str> = seq.source_label().into();
        let around = crate::around::Around::prepare(seq, config, &ego, &tracks, source.clone());
        Ok(Analysis {
            seq,
            config,
            ego,
            tracks,
            source,
            ego_track,
            ego_yaw,
            ego_yaw_sd,
            ego_pos_sd,
            around,
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
            doubts: Vec::new(),
            speeds: Vec::new(),
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
        w.ego_facts(&present);
        // A surround log relates objects near the ego only
        // (`around.pair_range_m`); a camera's objects are all in view.
        // The names in range, for the 360° relations of `around` too: one
        // rule, decided here once.
        let mut in_range: std::collections::HashSet<&str> = Default::default();
        let paired: Vec<(usize, std::ops::Range<usize>)> = if self.around.is_some() {
            let range = self.config.around.pair_range_m;
            let near = |(ti, r): &&(usize, std::ops::Range<usize>)| {
                self.tracks[*ti].cam[r.clone()]
                    .iter()
                    .flatten()
                    .any(|g| g.0.coords.norm() <= range)
            };
            let paired: Vec<_> = present.iter().filter(near).cloned().collect();
            in_range = paired
                .iter()
                .map(|(ti, _)| self.tracks[*ti].name.as_str())
                .collect();
            w.speeds
                .retain(|(n, _, _)| n == EGO || in_range.contains(n.as_str()));
            paired
        } else {
            present
        };
        w.pair_facts(&paired);
        w.faster_facts();
        if let Some(around) = &self.around {
            w.facts
                .extend(around.window_facts(index, first, last, &in_range));
        }
        let mut out = WindowFacts {
            index,
            first_frame: first,
            last_frame: last,
            facts: w.facts,
            doubts: w.doubts,
        };
        out.normalize();
        out
    }
}
