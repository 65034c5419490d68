//! Distance facts of a pair: `DistanceZero*`, `TooClose`, the distance
//! trends, and the noise variances of gaps and ranges behind them.

use crate::coords::CameraBev;
use crate::ego;
use crate::geometry::{convex_gap, observation_footprint};
use crate::signal::{slope_noise_var, slope_with_error};

use super::relative::RelativeScratch;
use super::{DEFAULT_FOOTPRINT_M, TrackState, WindowCtx};

impl WindowCtx<'_, '_> {
    pub(super) fn distance_facts(
        &mut self,
        scratch: &mut RelativeScratch,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let cfg = self.a.config;
        // Buffers shared by every pair of the window: the pair loop is
        // O(n²), so per-pair vectors would allocate n² times.
        let RelativeScratch {
            times: ts,
            gaps,
            gap_vars,
            ..
        } = scratch;
        ts.clear();
        gaps.clear();
        gap_vars.clear();
        let noise = self.a.ego.noise;
        for (a, b) in Self::common(x, rx, y, ry) {
            let (Some(pa), Some(pb)) = (x.cam[a], y.cam[b]) else {
                continue;
            };
            let fa = observation_footprint(pa, self.obs(x, a), DEFAULT_FOOTPRINT_M);
            let fb = observation_footprint(pb, self.obs(y, b), DEFAULT_FOOTPRINT_M);
            ts.push(f64::from(x.frames[a]));
            gaps.push(convex_gap(&fa, &fb));
            gap_vars.push(gap_noise_var(&noise, pa, pb));
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
        let closer = self.gap_trend((xn, yn), ts, gaps, gap_vars, "gap");
        if closer && g1 <= cfg.touch_distance_m && g0 > cfg.touch_distance_m {
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
    }

    /// `SharesFrames`, `DistanceDecrease`, `DistanceIncrease` (both ways,
    /// asserted or doubted) for the pair `(xn, yn)` from its distance `gaps`
    /// at frames `ts` with their noise variances `gap_vars`; `noun` names
    /// the distance in the notes. Returns whether `DistanceDecrease` was
    /// asserted. Shared by object pairs (footprint gaps) and the relations
    /// to the ego (ground distance to the camera).
    pub(super) fn gap_trend(
        &mut self,
        (xn, yn): (&str, &str),
        ts: &[f64],
        gaps: &[f64],
        gap_vars: &[f64],
        noun: &str,
    ) -> bool {
        let cfg = self.a.config;
        let fps = self.a.seq.fps;
        let noise = self.a.ego.noise;
        let both =
            |s: &mut Self, pred: &str, m: Option<f64>, th: Option<(&str, f64)>, note: String| {
                s.push(pred, &[xn, yn], m, th, note.clone());
                s.push(pred, &[yn, xn], m, th, note);
            };
        let both_p = |s: &mut Self,
                      asserted: bool,
                      pred: &str,
                      m: Option<f64>,
                      th: Option<(&str, f64)>,
                      note: String,
                      p: f64| {
            s.decide(asserted, pred, &[xn, yn], m, th, |_| note.clone(), p);
            s.decide(asserted, pred, &[yn, xn], m, th, |_| note.clone(), p);
        };
        let (Some(&g0), Some(&g1)) = (gaps.first(), gaps.last()) else {
            return false;
        };
        if gaps.len() < cfg.min_observations as usize {
            return false;
        }
        let Some((slope, resid_se)) = slope_with_error(ts, gaps) else {
            return false;
        };
        let noise_se = slope_noise_var(ts, gap_vars).map_or(0.0, f64::sqrt);
        // The pair's gap trend was measured: rules such as ConstantDistance
        // need a positive atom that binds both objects before they may say
        // "neither closer nor farther" under negation.
        both(
            self,
            "SharesFrames",
            Some(gaps.len() as f64),
            Some(("min_observations", f64::from(cfg.min_observations))),
            format!(
                "{noun} measured in {} common frames >= min_observations {}",
                gaps.len(),
                cfg.min_observations
            ),
        );
        let rate = slope * fps;
        let rate_se = resid_se.max(noise_se) * fps;
        let k = cfg.distance_significance;
        let margin = k * rate_se;
        let change = slope * (ts[ts.len() - 1] - ts[0]);
        let test = format!(
            "by distance_significance {k:.1} se of {rate_se:.2} m/s (the larger of the residuals' {:.2} and the measured noise's {:.2}: σ {:.2} m lateral, {:.1} % depth + {:.2} %/m)",
            resid_se * fps,
            noise_se * fps,
            noise.lateral_m,
            100.0 * noise.depth_fraction,
            100.0 * noise.depth_fraction_per_m
        );
        // Both conditions must hold; the less certain bounds the fact. The
        // fitted change's standard error is the slope's over the span.
        let (dr, dmin) = (cfg.distance_rate_mps, cfg.distance_change_min_m);
        let change_se = rate_se / fps * (ts[ts.len() - 1] - ts[0]);
        let p_closer = crate::belief::beyond(-rate, dr + margin, rate_se)
            .min(crate::belief::beyond(-change, dmin, change_se));
        let p_farther = crate::belief::beyond(rate, dr + margin, rate_se)
            .min(crate::belief::beyond(change, dmin, change_se));
        let closer = rate + margin < -dr && change < -dmin;
        let farther = !closer && rate - margin > dr && change > dmin;
        let rate_thr = Some(("distance_rate_mps", dr));
        if !closer {
            both_p(
                self,
                false,
                "DistanceDecrease",
                Some(rate),
                rate_thr,
                format!(
                    "{noun} changes at {rate:.2} ± {rate_se:.2} m/s ({g0:.1} → {g1:.1} m), not shrinking faster than distance_rate_mps {dr:.2} {test}"
                ),
                p_closer,
            );
        }
        if !farther {
            both_p(
                self,
                false,
                "DistanceIncrease",
                Some(rate),
                rate_thr,
                format!(
                    "{noun} changes at {rate:.2} ± {rate_se:.2} m/s ({g0:.1} → {g1:.1} m), not growing faster than distance_rate_mps {dr:.2} {test}"
                ),
                p_farther,
            );
        }
        if closer {
            both_p(
                self,
                true,
                "DistanceDecrease",
                Some(rate),
                rate_thr,
                format!(
                    "{noun} shrinks at {:.2} ± {rate_se:.2} m/s ({g0:.1} → {g1:.1} m), faster than distance_rate_mps {:.2} {test}",
                    -rate, cfg.distance_rate_mps
                ),
                p_closer,
            );
        } else if farther {
            both_p(
                self,
                true,
                "DistanceIncrease",
                Some(rate),
                rate_thr,
                format!(
                    "{noun} grows at {rate:.2} ± {rate_se:.2} m/s ({g0:.1} → {g1:.1} m), faster than distance_rate_mps {:.2} {test}",
                    cfg.distance_rate_mps
                ),
                p_farther,
            );
        }
        closer
    }
}

/// Variance (m²) of a sighting's ground distance to the camera at camera
/// ground point `p`: its lateral (camera X) and depth (camera Z) noise
/// projected on its line of sight.
pub(super) fn range_noise_var(noise: &ego::MeasuredNoise, p: CameraBev) -> f64 {
    let len = p.0.coords.norm();
    let (ux, uz) = if len > f64::EPSILON {
        (p.x() / len, p.z() / len)
    } else {
        (0.0, 1.0)
    };
    let sz = noise.depth_sd(p.z().max(0.0));
    noise.lateral_m * noise.lateral_m * ux * ux + sz * sz * uz * uz
}

/// Variance (m²) of the gap between two sightings at camera ground points
/// `a` and `b` from the measured noise: each sighting's lateral (camera X)
/// and depth (camera Z) noise projected on the line between them, the two
/// sightings independent.
fn gap_noise_var(noise: &ego::MeasuredNoise, a: CameraBev, b: CameraBev) -> f64 {
    let (dx, dz) = (b.x() - a.x(), b.z() - a.z());
    let len = (dx * dx + dz * dz).sqrt();
    let (ux, uz) = if len > f64::EPSILON {
        (dx / len, dz / len)
    } else {
        (
            std::f64::consts::FRAC_1_SQRT_2,
            std::f64::consts::FRAC_1_SQRT_2,
        )
    };
    let one = |p: CameraBev| {
        let sz = noise.depth_sd(p.z().max(0.0));
        noise.lateral_m * noise.lateral_m * ux * ux + sz * sz * uz * uz
    };
    one(a) + one(b)
}
