//! Relative positions of a pair: `LeftOf`/`RightOf` and `InFrontOf`/`Behind`
//! from one vote over the frames the pair shares.

use crate::coords::CameraBev;

use super::{EGO, TrackState, WindowCtx};

/// Per-frame offsets of one pair, reused across the pairs of a window.
/// Signs: positive when the pair's first object is left of (ahead of) the
/// second.
#[derive(Debug, Default)]
pub(super) struct RelativeScratch {
    /// `X_y − X_x` (m) per common frame with both ground points.
    pub(super) lateral: Vec<f64>,
    /// `Z_x − Z_y` (m), same frames as `lateral`.
    forward: Vec<f64>,
    /// Box-centre offset as a fraction of the image width, every common
    /// frame (filled only for the image fallback).
    image: Vec<f64>,
    /// Frame numbers of the common frames with both ground points, for the
    /// distance facts (cleared by `distance_facts` itself).
    pub(super) times: Vec<f64>,
    /// Gap (m) between the two footprints, same frames as `times`.
    pub(super) gaps: Vec<f64>,
    /// Variance (m²) of each gap from the measured position noise, same
    /// frames as `times`.
    pub(super) gap_vars: Vec<f64>,
}

impl RelativeScratch {
    pub(super) fn clear(&mut self) {
        self.lateral.clear();
        self.forward.clear();
        self.image.clear();
    }
}

/// Frames with ground points voting for each direction of each relation of
/// one pair.
#[derive(Debug, Default)]
pub(super) struct RelativeVotes {
    pub(super) x_left: usize,
    pub(super) y_left: usize,
    pub(super) x_ahead: usize,
    pub(super) y_ahead: usize,
    /// `y` is the ego (at the camera): "in front of" by bearing too.
    pub(super) ego: bool,
}

impl RelativeVotes {
    /// Counts one frame with `x` at ground point `pa` and `y` at `pb`, both
    /// in that frame's camera, and keeps its offsets in `s`.
    pub(super) fn add(
        &mut self,
        s: &mut RelativeScratch,
        rel: &crate::config::RelativeConfig,
        pa: CameraBev,
        pb: CameraBev,
    ) {
        let beyond = |d: f64, min: f64| d > 0.0 && d >= min;
        // Positive: x is left of y / x is ahead of y.
        let lateral = pb.x() - pa.x();
        let forward = pa.z() - pb.z();
        s.lateral.push(lateral);
        s.forward.push(forward);
        self.x_left += usize::from(beyond(lateral, rel.lateral_min_m));
        self.y_left += usize::from(beyond(-lateral, rel.lateral_min_m));
        // Between two objects, "in front of" is in the other's path (the
        // corridor); relative to the ego (`pb` at the camera) it is ahead
        // as a person looking out says it: within the corridor, or within
        // 45° of straight ahead (the truck overtaking in the next lane is
        // in front of us once it is ahead).
        let corridor =
            lateral.abs() <= rel.corridor_m || (self.ego && lateral.abs() <= forward.abs());
        self.x_ahead += usize::from(corridor && beyond(forward, rel.forward_min_m));
        self.y_ahead += usize::from(corridor && beyond(-forward, rel.forward_min_m));
    }
}

impl WindowCtx<'_, '_> {
    /// The doubts of a vote that no direction of a relation won: each
    /// direction, and its converse, with the posterior probability that
    /// its fraction of frames exceeds `min_frame_fraction` all the same.
    #[allow(clippy::too_many_arguments)]
    fn vote_doubts(
        &mut self,
        (pred, conv): (&str, &str),
        (x, y): (&str, &str),
        (x_votes, y_votes): (usize, usize),
        frames: usize,
        threshold: (&str, f64),
    ) {
        let f = self.a.config.relative.min_frame_fraction;
        for (first, second, votes) in [(x, y, x_votes), (y, x, y_votes)] {
            let q = crate::belief::majority(votes, frames, f);
            let note = format!(
                "{pred}({first}, {second}) in {votes} of {frames} common frames, not more than relative.min_frame_fraction {f:.2}"
            );
            for (p, args) in [(pred, [first, second]), (conv, [second, first])] {
                self.decide(false, p, &args, None, Some(threshold), |_| note.clone(), q);
            }
        }
    }

    /// `LeftOf`/`RightOf`/`InFrontOf`/`Behind` for one unordered pair.
    ///
    /// Per common frame, in that frame's ego camera coordinates (X right,
    /// Z forward) on the ground points: `x` is left of `y` when
    /// `X_y − X_x >= relative.lateral_min_m`; `x` is in front of `y` when
    /// `Z_x − Z_y >= relative.forward_min_m` and `|X_x − X_y| <=
    /// relative.corridor_m`. A relation holds over the window when more than
    /// `relative.min_frame_fraction` of the frames with both ground points
    /// satisfy it, and there are at least `min_observations` such frames
    /// (the rule of the other pair facts). A pair with fewer such frames
    /// falls back to the box centres for `LeftOf`/`RightOf` only: depth order
    /// cannot be read from a flat image. Offsets must also be strictly
    /// positive, so that a zero threshold cannot make a tie vote both ways.
    pub(super) fn relative_facts(
        &mut self,
        s: &mut RelativeScratch,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let cfg = self.a.config;
        let rel = &cfg.relative;
        let beyond = |d: f64, min: f64| d > 0.0 && d >= min;
        s.clear();
        let mut v = RelativeVotes::default();
        for (a, b) in Self::common(x, rx.clone(), y, ry.clone()) {
            let (Some(pa), Some(pb)) = (x.cam[a], y.cam[b]) else {
                continue;
            };
            v.add(s, rel, pa, pb);
        }
        let min_frames = cfg.min_observations as usize;
        let wins = |votes: usize, n: usize| votes as f64 > rel.min_frame_fraction * n as f64;
        let belief =
            |votes: usize, n: usize| crate::belief::majority(votes, n, rel.min_frame_fraction);
        let (xn, yn) = (x.name.as_str(), y.name.as_str());
        if s.lateral.len() >= min_frames {
            self.relative_decide(s, &v, xn, yn);
            return;
        }
        // Too few frames with ground points: a second walk over the common
        // frames reads the boxes. Only then, because the observations are
        // scattered in memory and metric sources (KITTI, the simulator)
        // never need it.
        let width = f64::from(self.a.seq.camera.intrinsics.image_width);
        let (mut x_left, mut y_left) = (0usize, 0usize);
        for (a, b) in Self::common(x, rx, y, ry) {
            // Positive: x's box centre is left of y's.
            let (Some(bx), Some(by)) = (&self.obs(x, a).bbox, &self.obs(y, b).bbox) else {
                continue;
            };
            let du = (by.center_x() - bx.center_x()) / width;
            s.image.push(du);
            x_left += usize::from(beyond(du, rel.lateral_min_image_fraction));
            y_left += usize::from(beyond(-du, rel.lateral_min_image_fraction));
        }
        let n = s.image.len();
        if n < min_frames {
            return;
        }
        let side = if wins(x_left, n) {
            Some((xn, yn, x_left, 1.0))
        } else if wins(y_left, n) {
            Some((yn, xn, y_left, -1.0))
        } else {
            None
        };
        if let Some((left, right, k, sign)) = side {
            let m = sign * crate::signal::median_in_place(&mut s.image).unwrap_or(0.0);
            let thr = rel.lateral_min_image_fraction;
            let why = format!(
                "box-centre offset >= relative.lateral_min_image_fraction {thr:.3} of the image width in {k} of {n} common frames (too few frames with ground points: image geometry)"
            );
            self.push_with_converse(
                ("LeftOf", "RightOf"),
                (left, right),
                m,
                ("relative.lateral_min_image_fraction", thr),
                format!("{left}'s box centre is {m:.3} (median) of the image width left of {right}'s: {why}"),
                format!("{right}'s box centre is {m:.3} (median) of the image width right of {left}'s: {why}"),
                belief(k, n),
            );
        } else {
            self.vote_doubts(
                ("LeftOf", "RightOf"),
                (xn, yn),
                (x_left, y_left),
                n,
                (
                    "relative.lateral_min_image_fraction",
                    rel.lateral_min_image_fraction,
                ),
            );
        }
    }

    /// Decides `LeftOf`/`RightOf`/`InFrontOf`/`Behind` for the pair `(xn,
    /// yn)` from the per-frame offsets in `s` (x's lateral offset left of
    /// y, x's forward offset ahead of y) and their votes `v`: the metric
    /// half of [`Self::relative_facts`], shared with the relations to the
    /// ego. The caller has checked that there are `min_observations` frames.
    pub(super) fn relative_decide(
        &mut self,
        s: &mut RelativeScratch,
        v: &RelativeVotes,
        xn: &str,
        yn: &str,
    ) {
        let cfg = self.a.config;
        let rel = &cfg.relative;
        let wins = |votes: usize, n: usize| votes as f64 > rel.min_frame_fraction * n as f64;
        let belief =
            |votes: usize, n: usize| crate::belief::majority(votes, n, rel.min_frame_fraction);
        let n = s.lateral.len();
        // Votes first, medians after: sorting for a median breaks the
        // pairing of `lateral` and `forward` frame by frame.
        let lateral_thr = ("relative.lateral_min_m", rel.lateral_min_m);
        let side = if wins(v.x_left, n) {
            Some((xn, yn, v.x_left, 1.0))
        } else if wins(v.y_left, n) {
            Some((yn, xn, v.y_left, -1.0))
        } else {
            None
        };
        let ahead = if wins(v.x_ahead, n) {
            Some((xn, yn, v.x_ahead, 1.0))
        } else if wins(v.y_ahead, n) {
            Some((yn, xn, v.y_ahead, -1.0))
        } else {
            None
        };
        // When no direction won, both are doubts; when one did, its
        // opposite is not (a relation and its opposite cannot both
        // hold), and the winner's own doubt is its probability.
        if side.is_none() {
            self.vote_doubts(
                ("LeftOf", "RightOf"),
                (xn, yn),
                (v.x_left, v.y_left),
                n,
                lateral_thr,
            );
        }
        if ahead.is_none() {
            self.vote_doubts(
                ("InFrontOf", "Behind"),
                (xn, yn),
                (v.x_ahead, v.y_ahead),
                n,
                ("relative.forward_min_m", rel.forward_min_m),
            );
        }
        let lateral_median = if side.is_some() || ahead.is_some() {
            crate::signal::median_in_place(&mut s.lateral).unwrap_or(0.0)
        } else {
            0.0
        };
        if let Some((left, right, k, sign)) = side {
            let m = sign * lateral_median;
            let (thr_name, thr) = lateral_thr;
            let why = format!(
                "lateral offset (camera X) >= {thr_name} {thr:.2} m in {k} of {n} common frames with ground points"
            );
            self.push_with_converse(
                ("LeftOf", "RightOf"),
                (left, right),
                m,
                lateral_thr,
                format!("{left} is {m:.2} m (median) left of {right}: {why}"),
                format!("{right} is {m:.2} m (median) right of {left}: {why}"),
                belief(k, n),
            );
        }
        if let Some((front, back, k, sign)) = ahead {
            let m = sign * crate::signal::median_in_place(&mut s.forward).unwrap_or(0.0);
            let within = if yn == EGO {
                format!(
                    "within relative.corridor_m {:.2} m laterally or 45° of straight ahead",
                    rel.corridor_m
                )
            } else {
                format!(
                    "within relative.corridor_m {:.2} m laterally",
                    rel.corridor_m
                )
            };
            let why = format!(
                "forward offset (camera Z) >= relative.forward_min_m {:.2} m {within} in {k} of {n} common frames with ground points (|median lateral offset| {:.2} m)",
                rel.forward_min_m,
                lateral_median.abs()
            );
            self.push_with_converse(
                ("InFrontOf", "Behind"),
                (front, back),
                m,
                ("relative.forward_min_m", rel.forward_min_m),
                format!("{front} is {m:.2} m (median) ahead of {back}: {why}"),
                format!("{back} is {m:.2} m (median) behind {front}: {why}"),
                belief(k, n),
            );
        }
    }
}
