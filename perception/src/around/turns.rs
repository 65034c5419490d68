//! Object turns (`TurnLeft`/`TurnRight` of objects): runs of same-sign
//! yaw rate over a whole track, read on headings cleared of one-frame
//! label flips.

use super::{Actor, Around, TURN_RATE_DEADBAND_DPS};
use crate::geometry::wrap_angle;
use crate::model::Fact;
use std::ops::Range;

impl Around {
    /// `TurnLeft(x)` / `TurnRight(x)`: a run of same-sign yaw rate over
    /// the whole track (a quarter turn takes several seconds, longer than a
    /// window) whose heading change exceeds `object_turn_min_deg`, while
    /// the object moves; the fact holds in every window the run overlaps.
    pub(super) fn turn_facts(
        &self,
        w: (u32, u32, u32),
        a: &Actor,
        r: Range<usize>,
        out: &mut Vec<Fact>,
    ) {
        let cfg = &self.cfg;
        if r.is_empty() {
            return;
        }
        let (first, last) = (w.1, w.2);
        let min = cfg.object_turn_min_deg;
        for (change, f0, f1) in self.turn_runs(a) {
            if f1 < first || f0 > last || change.abs() <= min {
                continue;
            }
            let (pred, dir) = if change > 0.0 {
                ("TurnRight", "right")
            } else {
                ("TurnLeft", "left")
            };
            let change = change.abs();
            out.push(self.fact(
                w,
                pred,
                vec![a.name.clone()],
                Some(change),
                Some(("around.object_turn_min_deg", min)),
                format!(
                    "its heading turns {change:.1}° to the {dir} from frame {f0} to {f1} in one run of same-sign yaw rate (steps slower than {TURN_RATE_DEADBAND_DPS}°/s the other way do not end it), > object_turn_min_deg {min:.1}°"
                ),
            ));
        }
    }

    /// The runs of same-sign yaw rate of a track while it moves: (heading
    /// change in degrees at the run's peak, positive to the right; first
    /// frame; frame of the peak). A step slower than the dead band does not
    /// end a run; a gap in the headings or a halt does.
    fn turn_runs(&self, a: &Actor) -> Vec<(f64, u32, u32)> {
        let cfg = &self.cfg;
        let heading = despiked_headings(&a.heading);
        let mut runs = Vec::new();
        // (sum, sign, start frame, peak (sum, frame))
        let mut cur: Option<(f64, i8, u32, (f64, u32))> = None;
        let close = |cur: &mut Option<(f64, i8, u32, (f64, u32))>,
                     runs: &mut Vec<(f64, u32, u32)>| {
            if let Some((_, _, from, (peak, at))) = cur.take()
                && peak != 0.0
            {
                runs.push((peak, from, at));
            }
        };
        for k in 1..a.frames.len() {
            let (f0, f1) = (a.frames[k - 1], a.frames[k]);
            let moving = a.speed(k) >= cfg.heading_min_speed_mps;
            let (Some(h0), Some(h1), true) = (heading[k - 1], heading[k], moving) else {
                close(&mut cur, &mut runs);
                continue;
            };
            let dt = self.times[f1 as usize] - self.times[f0 as usize];
            if dt <= 0.0 {
                continue;
            }
            let step = wrap_angle(h1 - h0).to_degrees();
            let rate = step / dt;
            let s: i8 = if rate > TURN_RATE_DEADBAND_DPS {
                1
            } else if rate < -TURN_RATE_DEADBAND_DPS {
                -1
            } else {
                0
            };
            if let Some((_, sign, _, _)) = cur
                && s != 0
                && sign != 0
                && s != sign
            {
                close(&mut cur, &mut runs);
            }
            let run = cur.get_or_insert((0.0, 0, f0, (0.0, f0)));
            if s != 0 {
                run.1 = s;
            }
            run.0 += step;
            if run.0.abs() > run.3.0.abs() {
                run.3 = (run.0, f1);
            }
        }
        close(&mut cur, &mut runs);
        runs
    }
}

/// Headings with one-frame spikes removed: each run of consecutive known
/// headings is unwrapped and replaced by its running median over five
/// sightings. Labels flip a box's yaw for a single frame now and then (the
/// AV2 log `3b3570b4` turns a car by 68° at frame 83 and back at 84, again
/// at 85), which would read as a left turn inside a right one; two such
/// spikes one frame apart still leave three good headings of five.
pub(super) fn despiked_headings(heading: &[Option<f64>]) -> Vec<Option<f64>> {
    let mut out = heading.to_vec();
    let mut k = 0;
    while k < heading.len() {
        if heading[k].is_none() {
            k += 1;
            continue;
        }
        let start = k;
        let mut unwrapped: Vec<f64> = Vec::new();
        while let Some(Some(h)) = heading.get(k) {
            let u = match unwrapped.last() {
                Some(&prev) => prev + wrap_angle(h - prev),
                None => *h,
            };
            unwrapped.push(u);
            k += 1;
        }
        let n = unwrapped.len();
        let mut w: Vec<f64> = Vec::with_capacity(5);
        for i in 0..n {
            w.clear();
            w.extend_from_slice(&unwrapped[i.saturating_sub(2)..(i + 3).min(n)]);
            w.sort_by(f64::total_cmp);
            out[start + i] = Some(w[w.len() / 2]);
        }
    }
    out
}
