//! Comparisons between movers: `Closer` (by distance to the ego) and
//! `Faster` (by window speed, the ego included).

use super::distance::range_noise_var;
use super::{TrackState, WindowCtx};

impl WindowCtx<'_, '_> {
    /// `Closer(x, y)` or `Closer(y, x)`: over the frames where both have a
    /// ground point, the mean ground distance to the ego (the camera) of
    /// one is smaller than the other's by more than `closer_margin_m` and
    /// by `comparison_significance` standard deviations of the difference
    /// (each sighting's lateral and depth noise projected on its line of
    /// sight, independent sightings). The mean over the shared frames, not
    /// one frame: it is the window's answer, and noise on a single
    /// sighting does not decide it.
    pub(super) fn closer_facts(
        &mut self,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let cfg = self.a.config;
        let noise = self.a.ego.noise;
        let (mut n, mut sum_x, mut sum_y, mut var_x, mut var_y) = (0usize, 0.0, 0.0, 0.0, 0.0);
        for (a, b) in Self::common(x, rx, y, ry) {
            let (Some(pa), Some(pb)) = (x.cam[a], y.cam[b]) else {
                continue;
            };
            n += 1;
            sum_x += pa.0.coords.norm();
            sum_y += pb.0.coords.norm();
            var_x += range_noise_var(&noise, pa);
            var_y += range_noise_var(&noise, pb);
        }
        if n == 0 {
            return;
        }
        let nf = n as f64;
        let (dx, dy) = (sum_x / nf, sum_y / nf);
        let (sx, sy) = (var_x.sqrt() / nf, var_y.sqrt() / nf);
        let sd = sx.hypot(sy);
        let (k, margin) = (cfg.comparison_significance, cfg.closer_margin_m);
        let threshold = Some(("closer_margin_m", margin));
        for (near, d_near, s_near, far, d_far, s_far) in [
            (&x.name, dx, sx, &y.name, dy, sy),
            (&y.name, dy, sy, &x.name, dx, sx),
        ] {
            let diff = d_far - d_near;
            let note = |yes: bool| {
                let verdict = if yes { ">" } else { "not >" };
                format!(
                    "mean ground distance to the ego over {n} common frames: {near} {d_near:.2} ± {s_near:.2} m, {far} {d_far:.2} ± {s_far:.2} m; {near} is {diff:.2} m nearer, {verdict} closer_margin_m {margin:.2} m by comparison_significance {k:.1} sd of {sd:.2} m"
                )
            };
            self.decide(
                diff - k * sd > margin,
                "Closer",
                &[near, far],
                Some(diff),
                threshold,
                note,
                crate::belief::beyond(diff, margin + k * sd, sd),
            );
        }
    }

    /// `Faster(x, y)` for every ordered pair of the window's movers whose
    /// speed was measured (the ego included): `x`'s window speed (the one
    /// `Moving` tests) exceeds `y`'s by more than `faster_margin_mps` and by
    /// `comparison_significance` standard errors of the difference.
    pub(super) fn faster_facts(&mut self) {
        let cfg = self.a.config;
        let (k, margin) = (cfg.comparison_significance, cfg.faster_margin_mps);
        let threshold = Some(("faster_margin_mps", margin));
        let speeds = std::mem::take(&mut self.speeds);
        for (i, (xn, vx, sx)) in speeds.iter().enumerate() {
            for (yn, vy, sy) in &speeds[i + 1..] {
                let sd = sx.hypot(*sy);
                for (fast, v_fast, s_fast, slow, v_slow, s_slow) in
                    [(xn, vx, sx, yn, vy, sy), (yn, vy, sy, xn, vx, sx)]
                {
                    let diff = v_fast - v_slow;
                    let note = |yes: bool| {
                        let verdict = if yes { ">" } else { "not >" };
                        format!(
                            "window speed {fast} {v_fast:.2} ± {s_fast:.2} m/s, {slow} {v_slow:.2} ± {s_slow:.2} m/s; {fast} is {diff:.2} m/s faster, {verdict} faster_margin_mps {margin:.2} by comparison_significance {k:.1} se of {sd:.2} m/s"
                        )
                    };
                    self.decide(
                        diff - k * sd > margin,
                        "Faster",
                        &[fast, slow],
                        Some(diff),
                        threshold,
                        note,
                        crate::belief::beyond(diff, margin + k * sd, sd),
                    );
                }
            }
        }
    }
}
