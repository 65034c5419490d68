//! Motion facts: `Moving`, `SpeedUp`, `SpeedDown` from the smoothed speeds
//! (Kalman/RTS or Savitzky–Golay), with the provenance of the smoothing.

use crate::config::Smoother;
use crate::signal::slope_with_error;

use super::{TrackState, WindowCtx};

/// A window's change of speed as `WindowCtx::speed_change` measures it.
struct Change {
    /// Smoothed speed at the window's first and last sightings (m/s).
    v0: f64,
    v1: f64,
    /// Highest smoothed speed in the window (m/s).
    peak: f64,
    /// The change of speed (m/s) and its standard deviation.
    change: f64,
    sd: f64,
    /// How the speeds were smoothed, for provenance.
    smoothing: String,
}

impl WindowCtx<'_, '_> {
    pub(super) fn motion_facts(&mut self, t: &TrackState) {
        match self.a.config.smoother {
            Smoother::Savgol => self.motion_facts_savgol(t),
            Smoother::Kalman => self.motion_facts_kalman(t),
        }
    }

    /// `Moving`, `SpeedUp`, `SpeedDown` from the Kalman-smoothed speeds:
    /// the window's mean smoothed speed must clear the class threshold by
    /// `trend_significance` posterior standard deviations, and the change
    /// of smoothed speed across the window must clear `speed_change_*` by
    /// as many standard deviations of the difference.
    fn motion_facts_kalman(&mut self, t: &TrackState) {
        let cfg = self.a.config;
        let lo = t.w_frames.partition_point(|f| *f < f64::from(self.first));
        let hi = t.w_frames.partition_point(|f| *f <= f64::from(self.last));
        if hi < lo + cfg.min_observations as usize || hi < lo + 2 || t.kal_speed.len() < hi {
            return;
        }
        let k = cfg.trend_significance;
        let sp = &t.kal_speed[lo..hi];
        let sd = &t.kal_speed_sd[lo..hi];
        let n = sp.len() as f64;
        let speed = sp.iter().sum::<f64>() / n;
        let speed_sd = (sd.iter().map(|s| s * s).sum::<f64>() / n).sqrt();
        let smoothing = self.kalman_smoothing(t);
        let by = format!("{k:.1} sd; {smoothing}");
        let what = if t.ego {
            "smoothed world speed of the ego (its estimated camera trajectory)"
        } else {
            "smoothed world speed"
        };
        self.moving(t, what, speed, speed_sd, &by);
        self.speed_change(t, lo, hi);
    }

    /// `Moving` from a mean speed and its standard error: asserted when it
    /// clears the class threshold by `trend_significance` errors, else a
    /// doubt; one test and one probability for both smoothers. `what`
    /// names the speed, `by` how the margin was measured (for provenance).
    fn moving(&mut self, t: &TrackState, what: &str, speed: f64, se: f64, by: &str) {
        self.speeds.push((t.name.clone(), speed, se));
        let k = self.a.config.trend_significance;
        let (field, thr) = self.a.config.moving_threshold(t.class);
        self.decide(
            speed - k * se > thr,
            "Moving",
            &[t.name.as_str()],
            Some(speed),
            Some((field, thr)),
            |yes| {
                let verdict = if yes { ">" } else { "not >" };
                format!("{what} {speed:.2} ± {se:.2} m/s {verdict} {field} {thr:.2} m/s by {by}")
            },
            crate::belief::beyond(speed, thr + k * se, se),
        );
    }

    /// What the Kalman/RTS smoother did to a track, for provenance.
    fn kalman_smoothing(&self, t: &TrackState) -> String {
        let cfg = self.a.config;
        format!(
            "Kalman/RTS smoothed over the track's {} sightings (accel psd {:.1} m²/s³, {}), {} rejected as outliers",
            t.w_frames.len(),
            cfg.kalman_accel_psd,
            self.noise_text(t),
            t.kal_rejected
        )
    }

    /// `SpeedUp`, `SpeedDown` for frames `lo..hi` of the track, from its
    /// RTS-smoothed velocities whichever `smoother` is set: a change of
    /// speed compares the window's first and last velocities, and
    /// Savitzky–Golay derivatives are at their noisiest exactly there, at
    /// the window's edges. The velocities come from the
    /// constant-acceleration smoother where its model holds around the
    /// window ([`Self::ca_change`]), else from the constant-velocity one.
    fn speed_change(&mut self, t: &TrackState, lo: usize, hi: usize) {
        let cfg = self.a.config;
        let fps = self.a.seq.fps;
        if t.kal_speed.len() < hi || hi < lo + 2 {
            return;
        }
        let k = cfg.trend_significance;
        let (_, thr) = cfg.moving_threshold(t.class);
        let name = t.name.as_str();
        let ts = &t.w_frames[lo..hi];
        let span = (ts[ts.len() - 1] - ts[0]) / fps;
        if span <= 0.0 {
            return;
        }
        let Change {
            v0,
            v1,
            peak,
            change,
            sd: change_sd,
            smoothing,
        } = match self.ca_change(t, lo, hi) {
            Some(c) => c,
            None => {
                // Constant velocity: the two ends' speeds, taken as
                // independent (their covariance is not kept).
                let sp = &t.kal_speed[lo..hi];
                let sd = &t.kal_speed_sd[lo..hi];
                let (v0, v1) = (sp[0], sp[sp.len() - 1]);
                Change {
                    v0,
                    v1,
                    peak: sp.iter().copied().fold(0.0, f64::max),
                    change: v1 - v0,
                    sd: (sd[0] * sd[0] + sd[sd.len() - 1] * sd[sd.len() - 1]).sqrt(),
                    smoothing: self.kalman_smoothing(t),
                }
            }
        };
        if peak <= thr {
            return;
        }
        let accel = change / span;
        let margin = k * change_sd;
        // Both conditions must hold; the less certain one bounds the fact.
        let (min, mps2) = (cfg.speed_change_min_mps, cfg.speed_change_mps2);
        let p_up = crate::belief::beyond(change, min + margin, change_sd)
            .min(crate::belief::beyond(accel, mps2, change_sd / span));
        let p_down = crate::belief::beyond(-change, min + margin, change_sd)
            .min(crate::belief::beyond(-accel, mps2, change_sd / span));
        let threshold = Some(("speed_change_mps2", mps2));
        let up = change - margin > min && accel > mps2;
        let down = !up && change + margin < -min && accel < -mps2;
        self.decide(up, "SpeedUp", &[name], Some(accel), threshold, |yes| {
            let verdict = if yes { ">" } else { "does not clear" };
            format!("acceleration {accel:.2} m/s² {verdict} speed_change_mps2 {mps2:.2} (speed change {change:.2} ± {change_sd:.2} m/s, smoothed speed {v0:.1} → {v1:.1} m/s); {smoothing}")
        }, p_up);
        self.decide(down, "SpeedDown", &[name], Some(accel), threshold, |yes| {
            let verdict = if yes { "<" } else { "does not clear" };
            format!("acceleration {accel:.2} m/s² {verdict} -speed_change_mps2 {mps2:.2} (speed change {change:.2} ± {change_sd:.2} m/s, smoothed speed {v0:.1} → {v1:.1} m/s); {smoothing}")
        }, p_down);
    }

    /// The change of speed over frames `lo..hi` from the track's
    /// constant-acceleration RTS smoothing, or `None` where that model does
    /// not hold around the window.
    ///
    /// That smoother pools a sustained acceleration over the whole
    /// manoeuvre, where the constant-velocity one takes it for noise (a
    /// far car pulling away from rest read 0.9 → 1.2 m/s ± 0.85 where it
    /// went 0 → 1.8; docs/history.md). But it spreads an abrupt change
    /// (a crash, a hard stop) over seconds, into windows where the speed
    /// was steady. So it is used only when its forward innovations over
    /// the window and as many sightings either side (about the reach of
    /// its smoothing) pass a χ² test at `kalman_ca_min_p`; an abrupt
    /// change leaves it far behind its sightings and fails the test.
    ///
    /// The change's variance takes the two ends' covariance (delta method
    /// on the speeds): they share most of their data.
    fn ca_change(&self, t: &TrackState, lo: usize, hi: usize) -> Option<Change> {
        let cfg = self.a.config;
        let [cx, cz] = &t.ca;
        let reach = hi - lo;
        let around = lo.saturating_sub(reach)..(hi + reach).min(cx.nis.len());
        let (mut nis, mut dof) = (0.0, 0usize);
        for c in [cx, cz] {
            for v in c.nis.get(around.clone())?.iter().flatten() {
                nis += v;
                dof += 1;
            }
        }
        let p = crate::signal::chi2_tail(nis, dof);
        if p < cfg.kalman_ca_min_p {
            return None;
        }
        let (a, b) = (lo, hi - 1);
        let velocity = |i: usize| Some((cx.velocity(i)?, cz.velocity(i)?));
        let ((x0, z0), (x1, z1)) = (velocity(a)?, velocity(b)?);
        let (v0, v1) = (x0.hypot(z0), x1.hypot(z1));
        // d|v| = (v/|v|)·dv; at rest the direction is the noise's, and
        // either unit vector will do.
        let unit = |x: f64, z: f64, n: f64| if n > 0.0 { (x / n, z / n) } else { (1.0, 0.0) };
        let ((e0x, e0z), (e1x, e1z)) = (unit(x0, z0, v0), unit(x1, z1, v1));
        let (p0x, p1x, cxx) = cx.velocity_cov(a, b)?;
        let (p0z, p1z, czz) = cz.velocity_cov(a, b)?;
        let var = e1x * e1x * p1x + e0x * e0x * p0x - 2.0 * e1x * e0x * cxx
            + e1z * e1z * p1z
            + e0z * e0z * p0z
            - 2.0 * e1z * e0z * czz;
        let peak = (a..=b)
            .filter_map(velocity)
            .map(|(x, z)| x.hypot(z))
            .fold(0.0, f64::max);
        Some(Change {
            v0,
            v1,
            peak,
            change: v1 - v0,
            sd: var.max(0.0).sqrt(),
            smoothing: format!(
                "constant-acceleration Kalman/RTS smoothed over the track's {} sightings (jerk psd {:.1} m²/s⁵; its innovations around the window: χ² {nis:.1} on {dof} degrees of freedom, p {p:.2} ≥ kalman_ca_min_p {:.2}; {}), {} rejected as outliers",
                t.w_frames.len(),
                cfg.kalman_jerk_psd,
                cfg.kalman_ca_min_p,
                self.noise_text(t),
                cx.rejected.max(cz.rejected)
            ),
        })
    }

    /// What the least-squares path did to a track, for provenance.
    fn savgol_smoothing(&self, t: &TrackState) -> String {
        let cfg = self.a.config;
        format!(
            "Hampel (outlier_mad_k {:.1}, savgol_window {}) replaced {} of {} world coordinates, least-squares slope over the window; {}",
            cfg.outlier_mad_k,
            cfg.savgol_window,
            t.hampel_replaced,
            2 * t.w_frames.len(),
            self.noise_text(t)
        )
    }

    /// The position noise a track's smoothing assumed, for provenance: the
    /// sequence's measured sighting noise for an object, the noise of the
    /// estimated camera positions for the ego.
    fn noise_text(&self, t: &TrackState) -> String {
        if t.ego {
            let [x, z] = self.a.ego_pos_sd;
            return format!(
                "the ego's position noise σ {x:.2} m (X), {z:.2} m (Z), measured on its trajectory's second differences and floored at kalman_min_sigma_m {:.2} m",
                self.a.config.kalman_min_sigma_m
            );
        }
        let n = &self.a.ego.noise;
        format!(
            "measured noise σ {:.2} m lateral, {:.1} % depth + {:.2} %/m",
            n.lateral_m,
            100.0 * n.depth_fraction,
            100.0 * n.depth_fraction_per_m
        )
    }

    fn motion_facts_savgol(&mut self, t: &TrackState) {
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
        let by = format!("trend_significance {k:.1} se; {}", self.savgol_smoothing(t));
        let what = if t.ego {
            "world speed of the ego (its estimated camera trajectory)"
        } else {
            "world speed"
        };
        self.moving(t, what, speed, speed_se, &by);
        self.speed_change(t, lo, hi);
    }
}
