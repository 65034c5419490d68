//! The ego's facts: `Ego(ego)`, its motion and turns, and its relations to
//! every object of the window.

use crate::coords::CameraBev;

use super::distance::range_noise_var;
use super::relative::{RelativeScratch, RelativeVotes};
use super::{EGO, TrackState, WindowCtx};

impl WindowCtx<'_, '_> {
    /// The ego's own facts and its relations to every object of the
    /// window: `Ego(ego)`; `Moving`/`SpeedUp`/`SpeedDown` from its
    /// estimated trajectory by the tests and thresholds of a vehicle;
    /// `TurnLeft`/`TurnRight`; and per object the relative positions and
    /// distance trends to the ego (see [`Self::ego_relations`]). `Near` is
    /// measured with the locations ([`Self::near_fact`]). Never
    /// `DistanceZero*`, `DistanceDecreasesToZero` or `TooClose` with the
    /// ego: its footprint is not known, and the collision rules rest on them.
    pub(super) fn ego_facts(&mut self, present: &[(usize, std::ops::Range<usize>)]) {
        let a = self.a;
        self.push("Ego", &[EGO], None, None, "the recording vehicle".into());
        self.motion_facts(&a.ego_track);
        self.turn_facts();
        let mut scratch = RelativeScratch::default();
        for (ti, r) in present {
            let t = &a.tracks[*ti];
            if t.surface || t.class.is_ground_surface() {
                continue;
            }
            self.ego_relations(&mut scratch, t, r.clone());
        }
    }

    /// `TurnRight(ego)` / `TurnLeft(ego)`: the ego's heading change from the
    /// window's first to its last frame, in degrees (positive: clockwise
    /// seen from above, towards camera +X, i.e. a right turn), beyond
    /// `turn_min_deg` by `trend_significance` standard deviations of the
    /// change (two headings' noise, measured on the trajectory).
    fn turn_facts(&mut self) {
        let cfg = self.a.config;
        let yaw = &self.a.ego_yaw;
        let (a, b) = (self.first as usize, self.last as usize);
        let (Some(&y0), Some(&y1)) = (yaw.get(a), yaw.get(b)) else {
            return;
        };
        if b <= a {
            return;
        }
        let change = (y1 - y0).to_degrees();
        let sd = (self.a.ego_yaw_sd * std::f64::consts::SQRT_2).to_degrees();
        let (k, thr) = (cfg.trend_significance, cfg.turn_min_deg);
        let margin = k * sd;
        let threshold = Some(("turn_min_deg", thr));
        let (first, last) = (self.first, self.last);
        let note = move |dir: &str, yes: bool| {
            let verdict = if yes { "beyond" } else { "not beyond" };
            format!(
                "the ego's heading turns {change:.1}° (positive: right) from frame {first} to {last}, {verdict} turn_min_deg {thr:.1}° to the {dir} by trend_significance {k:.1} sd of {sd:.2}° (heading noise measured on the estimated camera trajectory)"
            )
        };
        let right = change - margin > thr;
        let left = change + margin < -thr;
        let p_right = crate::belief::beyond(change, thr + margin, sd);
        let p_left = crate::belief::beyond(-change, thr + margin, sd);
        self.decide(
            right,
            "TurnRight",
            &[EGO],
            Some(change),
            threshold,
            |yes| note("right", yes),
            p_right,
        );
        self.decide(
            left,
            "TurnLeft",
            &[EGO],
            Some(change),
            threshold,
            |yes| note("left", yes),
            p_left,
        );
    }

    /// Relations between object `t` (sightings `r`) and the ego, which
    /// stands at the origin of every frame's camera: `LeftOf`/`RightOf`/
    /// `InFrontOf`/`Behind` by the object-pair rule and thresholds
    /// (`FactConfig::relative`) with the ego as the other object, each with
    /// its converse (`InFrontOf(car_3, ego)` with `Behind(ego, car_3)`);
    /// and `SharesFrames`/`DistanceDecrease`/`DistanceIncrease` both ways
    /// from the object's ground distance to the camera, by the significance
    /// test of object pairs. Needs `min_observations` sightings with a
    /// ground point; no image fallback (the ego has no box).
    fn ego_relations(
        &mut self,
        s: &mut RelativeScratch,
        t: &TrackState,
        r: std::ops::Range<usize>,
    ) {
        let cfg = self.a.config;
        let noise = self.a.ego.noise;
        s.clear();
        s.times.clear();
        s.gaps.clear();
        s.gap_vars.clear();
        let mut v = RelativeVotes {
            ego: true,
            ..RelativeVotes::default()
        };
        let origin = CameraBev::new(0.0, 0.0);
        for k in r {
            let Some(p) = t.cam[k] else {
                continue;
            };
            v.add(s, &cfg.relative, p, origin);
            s.times.push(f64::from(t.frames[k]));
            s.gaps.push(p.0.coords.norm());
            s.gap_vars.push(range_noise_var(&noise, p));
        }
        if s.lateral.len() < cfg.min_observations as usize {
            return;
        }
        self.relative_decide(s, &v, &t.name, EGO);
        let RelativeScratch {
            times,
            gaps,
            gap_vars,
            ..
        } = s;
        self.gap_trend(
            (&t.name, EGO),
            times,
            gaps,
            gap_vars,
            "ground distance to the ego",
        );
    }
}
