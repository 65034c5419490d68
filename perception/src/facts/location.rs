//! Location facts: where an object is relative to the ego (image side or
//! bearing, near/far bands, `Near`).

use crate::coords::CameraBev;
use crate::model::Observation;
use crate::signal::theil_sen_at;

use super::{EGO, TrackState, WindowCtx};

impl WindowCtx<'_, '_> {
    /// The box centre's share of the image width; `None` for an
    /// observation without a pixel box (a 360° log's cuboid).
    pub(super) fn x_fraction(&self, o: &Observation) -> Option<f64> {
        o.bbox
            .map(|b| b.center_x() / f64::from(self.a.seq.camera.intrinsics.image_width))
    }

    /// The side of the ego an object is on by its bearing (the angle from
    /// the ego's forward axis, positive to the right): `Front` within
    /// `bearing_front_deg`, `Behind` beyond `bearing_behind_deg`, `Left` or
    /// `Right` between; with the threshold field and value in degrees.
    fn bearing_side(&self, bearing_deg: f64) -> (&'static str, &'static str, f64) {
        let c = &self.a.config.around;
        let b = bearing_deg.abs();
        if b <= c.bearing_front_deg {
            ("Front", "bearing_front_deg", c.bearing_front_deg)
        } else if b >= c.bearing_behind_deg {
            ("Behind", "bearing_behind_deg", c.bearing_behind_deg)
        } else if bearing_deg < 0.0 {
            ("Left", "bearing_front_deg", c.bearing_front_deg)
        } else {
            ("Right", "bearing_front_deg", c.bearing_front_deg)
        }
    }

    /// How far an object is for the `Near*`/`Far*` bands and `Near`: the
    /// camera depth for a boxed sighting (what the thresholds were tuned
    /// on), the ground range for one without a box (it may be beside or
    /// behind the ego, where depth is zero or negative).
    fn band_distance(&self, t: &TrackState, k: usize, g: CameraBev) -> f64 {
        if self.obs(t, k).bbox.is_some() {
            g.z()
        } else {
            g.0.coords.norm()
        }
    }

    /// `InitialLocation` / `LastLocation` of a sighting without a pixel
    /// box, by bearing and ground range (360° logs): `pred(x, Side)` and
    /// `pred(x, NearSide)` or `pred(x, FarSide)`; returns the range.
    fn bearing_location(&mut self, pred: &str, t: &TrackState, k: usize) -> Option<f64> {
        let cfg = self.a.config;
        let g = t.cam[k]?;
        let frame = t.frames[k];
        let bearing = g.x().atan2(g.z()).to_degrees();
        let (side, field, thr) = self.bearing_side(bearing);
        self.push(
            pred,
            &[&t.name, side],
            Some(bearing),
            Some((field, thr)),
            format!("bearing {bearing:.0}° from the ego's heading in frame {frame} (no camera box: 360° placement)"),
        );
        let range = g.0.coords.norm();
        let near = range < cfg.near_far_m;
        let value = format!("{}{side}", if near { "Near" } else { "Far" });
        let cmp = if near { "<" } else { ">=" };
        self.push(
            pred,
            &[&t.name, &value],
            Some(range),
            Some(("near_far_m", cfg.near_far_m)),
            format!(
                "ground range {range:.1} m {cmp} near_far_m {:.1} m in frame {frame}",
                cfg.near_far_m
            ),
        );
        Some(range)
    }

    pub(super) fn side(&self, frac: f64) -> (&'static str, &'static str, f64) {
        let c = self.a.config;
        if frac < c.left_fraction {
            ("Left", "left_fraction", c.left_fraction)
        } else if frac > c.right_fraction {
            ("Right", "right_fraction", c.right_fraction)
        } else {
            ("Front", "left_fraction", c.left_fraction)
        }
    }

    /// `InitialLocation` / `LastLocation` at sighting `k`, the first or last
    /// of the window's sightings `r`. The box centre and depth of that
    /// sighting are checked against a Theil–Sen line through the
    /// `location_sightings` sightings at that end of the window: one that
    /// lies off the line by more than `location_outlier_fraction` of the
    /// image width (`location_outlier_depth_fraction` of the depth) — a bad
    /// box, a one-frame id switch — is replaced by the line's value there.
    pub(super) fn location(
        &mut self,
        pred: &str,
        t: &TrackState,
        k: usize,
        r: std::ops::Range<usize>,
    ) -> Option<f64> {
        let cfg = self.a.config;
        let o = self.obs(t, k);
        let Some(observed) = self.x_fraction(o) else {
            return self.bearing_location(pred, t, k);
        };
        let frame = o.frame;
        let at = f64::from(frame);
        let n = (cfg.location_sightings as usize).min(r.len());
        let ends = if k == r.start {
            r.start..r.start + n
        } else {
            r.end - n..r.end
        };
        let times: Vec<f64> = ends.clone().map(|i| f64::from(t.frames[i])).collect();
        let (frac, frac_note) = {
            // Sightings without a box (mixed sources) sit out the line fit.
            let (times, ys): (Vec<f64>, Vec<f64>) = ends
                .clone()
                .zip(&times)
                .filter_map(|(i, at)| Some((*at, self.x_fraction(self.obs(t, i))?)))
                .unzip();
            robust_end(observed, theil_sen_at(&times, &ys, at), |_| {
                cfg.location_outlier_fraction
            })
        };
        let (side, field, thr) = self.side(frac);
        let note = match frac_note {
            None => format!("box centre at {frac:.2} of the image width in frame {frame}"),
            Some(fit) => format!(
                "box centre at {fit:.2} of the image width in frame {frame}: the sighting's {observed:.2} lies more than location_outlier_fraction {:.2} off the Theil–Sen line through the {n} sightings at this end of the window, so the line's value is used",
                cfg.location_outlier_fraction
            ),
        };
        self.push(pred, &[&t.name, side], Some(frac), Some((field, thr)), note);
        if let Some(g) = t.cam[k] {
            let zs: Vec<(f64, f64)> = ends
                .filter_map(|i| t.cam[i].map(|p| (f64::from(t.frames[i]), p.z())))
                .collect();
            let (zt, zy): (Vec<f64>, Vec<f64>) = zs.into_iter().unzip();
            let (z, z_note) = robust_end(g.z(), theil_sen_at(&zt, &zy, at), |fit| {
                cfg.location_outlier_depth_fraction * fit.abs()
            });
            let near = z < cfg.near_far_m;
            let value = format!("{}{side}", if near { "Near" } else { "Far" });
            let cmp = if near { "<" } else { ">=" };
            let note = match z_note {
                None => format!(
                    "depth {z:.1} m {cmp} near_far_m {:.1} m in frame {frame}",
                    cfg.near_far_m
                ),
                Some(fit) => format!(
                    "depth {fit:.1} m {cmp} near_far_m {:.1} m in frame {frame}: the sighting's {:.1} m lies more than location_outlier_depth_fraction {:.2} off the Theil–Sen line through the sightings at this end of the window, so the line's value is used",
                    cfg.near_far_m,
                    g.z(),
                    cfg.location_outlier_depth_fraction
                ),
            };
            self.push(
                pred,
                &[&t.name, &value],
                Some(z),
                Some(("near_far_m", cfg.near_far_m)),
                note,
            );
            return Some(z);
        }
        None
    }

    /// `Near(x, ego)` and `Near(ego, x)`: the object's depth (camera Z, the
    /// measure of the `Near*`/`Far*` locations) falls below `near_far_m`
    /// somewhere in the window. The ends are the depths the locations used
    /// (`z0`, `z1`, robust to a bad first or last sighting), so that
    /// `InitialLocation(x, NearLeft)` or `LastLocation(x, NearFront)`
    /// always comes with `Near(x, ego)`; in between, each sighting's depth
    /// is the median of it and its two neighbours (one bad box does not
    /// bring an object near).
    pub(super) fn near_fact(
        &mut self,
        t: &TrackState,
        r: std::ops::Range<usize>,
        z0: Option<f64>,
        z1: Option<f64>,
    ) {
        let cfg = self.a.config;
        let mut best: Option<(f64, u32)> = None;
        let mut keep = |z: f64, frame: u32| {
            if best.is_none_or(|(b, _)| z < b) {
                best = Some((z, frame));
            }
        };
        if let Some(z) = z0 {
            keep(z, t.frames[r.start]);
        }
        if let Some(z) = z1 {
            keep(z, t.frames[r.end - 1]);
        }
        for k in r.start + 1..r.end.saturating_sub(1) {
            let Some(here) = t.cam[k] else {
                continue;
            };
            // Median of up to three depths, without allocating (this runs
            // for every sighting of every window).
            let d = |k: usize, g: CameraBev| self.band_distance(t, k, g);
            let z = match (t.cam[k - 1], t.cam[k + 1]) {
                (Some(a), Some(b)) => {
                    let (a, b, c) = (d(k - 1, a), d(k, here), d(k + 1, b));
                    a.max(b).min(a.min(b).max(c))
                }
                (Some(o), None) => 0.5 * (d(k - 1, o) + d(k, here)),
                (None, Some(o)) => 0.5 * (d(k + 1, o) + d(k, here)),
                (None, None) => d(k, here),
            };
            keep(z, t.frames[k]);
        }
        let Some((z, frame)) = best else {
            return;
        };
        if z < cfg.near_far_m {
            let note = format!(
                "depth {z:.1} m < near_far_m {:.1} m in frame {frame} (the depth that separates Near and Far locations)",
                cfg.near_far_m
            );
            let threshold = Some(("near_far_m", cfg.near_far_m));
            self.push("Near", &[&t.name, EGO], Some(z), threshold, note.clone());
            self.push("Near", &[EGO, &t.name], Some(z), threshold, note);
        }
    }
}

/// The value of a first/last sighting, or the robust line's `fit` at its
/// frame when the sighting lies farther than `tolerance(fit)` off it; the
/// second item is `Some(fit)` when the fit replaced the sighting.
fn robust_end(
    observed: f64,
    fit: Option<f64>,
    tolerance: impl Fn(f64) -> f64,
) -> (f64, Option<f64>) {
    match fit {
        Some(f) if f.is_finite() && (observed - f).abs() > tolerance(f) => (f, Some(f)),
        _ => (observed, None),
    }
}
