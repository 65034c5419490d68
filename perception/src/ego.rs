//! Ego-motion from anchors: the camera's pose in a world frame (= the camera
//! frame of frame 0) estimated frame to frame, so that object motion can be
//! measured in the world and not relative to a moving camera.
//!
//! Between frames `t−1` and `t` every object seen in both gives an anchor
//! pair on the bird's-eye plane. A *static* object satisfies
//! `p(t−1) = R(Δθ)·p(t) + T` for the camera's motion `(Δθ, T)`. Anchors are
//! the static classes (poles, signs, … weighted up) and every road user,
//! because KITTI labels hold few static objects but many parked cars. Moving
//! road users are rejected RANSAC-style: deterministic hypotheses (no motion,
//! the previous step's motion, one per anchor with a known yaw — a static
//! object's yaw turns by exactly `−Δθ` —, and one per anchor pair) are scored
//! with a truncated quadratic (MSAC) whose inlier radius grows with depth,
//! the best is refined by weighted least squares (2D Kabsch) on its inliers.
//! Implausible hypotheses (faster than `max_speed_mps`, turning faster than
//! `max_yaw_rate_rps`) are rejected; when the inliers weigh less than
//! `min_inlier_weight` the previous step is reused (constant velocity).
//!
//! Limits: when most anchors move together (a convoy, a single lead car) the
//! consensus can lock onto them and the camera is taken to move with them;
//! with no anchors the previous motion is extrapolated.

use nalgebra::{Isometry2, Point2, Translation2, Vector2};

use crate::config::EgoConfig;
use crate::coords::{CameraBev, WorldAnchor, WorldBev, yaw_axes, yaw_rotation};
use crate::geometry::{ground_point, wrap_angle};
use crate::model::Sequence;

/// The camera's pose on the ground plane at one frame: the rigid motion
/// that takes a [`CameraBev`] seen in that frame to the [`WorldBev`] of the
/// world frame (the camera frame of frame 0).
///
/// Invariant: `yaw` is finite (estimated poses keep it in `(−π, π]`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EgoPose {
    /// The camera's optical centre in the world.
    pub position: WorldBev,
    /// The camera's heading in the world, radians (KITTI sense, see
    /// [`yaw_axes`]): its forward axis is `(sin yaw, cos yaw)` in `(X, Z)`.
    pub yaw: f64,
}

impl EgoPose {
    /// The pose of frame 0: camera and world coincide.
    pub const IDENTITY: EgoPose = EgoPose {
        position: WorldBev(Point2::new(0.0, 0.0)),
        yaw: 0.0,
    };

    /// The pose as an nalgebra isometry from camera to world `(X, Z)`.
    pub fn isometry(&self) -> Isometry2<f64> {
        Isometry2::from_parts(
            Translation2::from(self.position.0.coords),
            yaw_rotation(self.yaw),
        )
    }

    /// Camera point of this frame → world point.
    pub fn to_world(&self, p: CameraBev) -> WorldBev {
        let (right, forward) = yaw_axes(self.yaw);
        WorldBev(self.position.0 + right * p.x() + forward * p.z())
    }

    /// World point → camera point of this frame.
    pub fn to_camera(&self, p: WorldBev) -> CameraBev {
        CameraBev(self.isometry().inverse_transform_point(&p.0))
    }

    /// The pose of the next frame, reached by `step`.
    pub fn then(&self, step: &EgoStep) -> EgoPose {
        EgoPose {
            position: self.to_world(CameraBev(step.translation.into())),
            yaw: wrap_angle(self.yaw + step.dyaw),
        }
    }
}

/// One frame-to-frame motion step: camera `t` expressed in camera `t−1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EgoStep {
    /// Heading change, radians.
    pub dyaw: f64,
    /// Translation `(X, Z)` of camera `t`'s origin in camera `t−1`, metres.
    pub translation: Vector2<f64>,
    /// Anchors available (objects seen in both frames).
    pub anchors: usize,
    /// Anchors accepted as static.
    pub inliers: usize,
    /// Whether the step was extrapolated from the previous one.
    pub fallback: bool,
}

impl EgoStep {
    const IDENTITY: EgoStep = EgoStep {
        dyaw: 0.0,
        translation: Vector2::new(0.0, 0.0),
        anchors: 0,
        inliers: 0,
        fallback: true,
    };

    /// The step as a rigid motion: a point of camera `t` to camera `t−1`.
    pub fn isometry(&self) -> Isometry2<f64> {
        Isometry2::from_parts(
            Translation2::from(self.translation),
            yaw_rotation(self.dyaw),
        )
    }

    /// Where a point of camera `t` lies in camera `t−1`. Both are camera
    /// points, of two different frames: the caller keeps track of which.
    pub fn apply(&self, p: CameraBev) -> CameraBev {
        let (right, forward) = yaw_axes(self.dyaw);
        CameraBev(Point2::from(self.translation) + right * p.x() + forward * p.z())
    }
}

/// The camera trajectory of a sequence.
#[derive(Debug, Clone, PartialEq)]
pub struct EgoMotion {
    /// Pose of the camera at each frame in the world (camera of frame 0),
    /// `frame_count` entries.
    pub poses: Vec<EgoPose>,
    /// Step into each frame (`steps[0]` is the identity).
    pub steps: Vec<EgoStep>,
    /// The position noise measured on the sequence (zero when ego-motion
    /// or its noise adaptation is off).
    pub noise: MeasuredNoise,
    /// Where the poses came from the source (its `ego_poses`), the change
    /// from the source's world frame to this one; `None`: estimated.
    pub anchor: Option<WorldAnchor>,
}

impl EgoMotion {
    /// A camera that does not move (used when ego-motion is disabled).
    pub fn stationary(frame_count: u32) -> EgoMotion {
        EgoMotion {
            poses: vec![EgoPose::IDENTITY; frame_count as usize],
            steps: vec![EgoStep::IDENTITY; frame_count as usize],
            noise: MeasuredNoise::default(),
            anchor: None,
        }
    }

    /// The trajectory a source measured (`Sequence::ego_poses`, in its own
    /// world frame), re-anchored on frame 0 ([`WorldAnchor`]); `None` when
    /// the sequence has no poses. The steps are the poses' differences
    /// (never fallbacks), the noise is measured on the objects as for an
    /// estimated path.
    pub fn known(seq: &Sequence) -> Option<EgoMotion> {
        let src = seq.ego_poses.as_ref()?;
        let first = src.first()?;
        let anchor = WorldAnchor {
            x0: first.x,
            y0: first.y,
            yaw0: first.yaw,
        };
        let poses: Vec<EgoPose> = src
            .iter()
            .map(|p| EgoPose {
                position: anchor.to_bev([p.x, p.y]),
                yaw: anchor.heading_to_bev(p.yaw),
            })
            .collect();
        let mut steps = Vec::with_capacity(poses.len());
        steps.push(EgoStep::IDENTITY);
        for w in poses.windows(2) {
            let rel = relative_step(&w[0], &w[1]);
            steps.push(EgoStep {
                fallback: false,
                ..rel
            });
        }
        Some(EgoMotion {
            poses,
            steps,
            noise: MeasuredNoise::of(seq),
            anchor: Some(anchor),
        })
    }

    /// World bird's-eye point of a camera bird's-eye point seen at `frame`;
    /// `None` for a frame outside the trajectory.
    pub fn to_world(&self, frame: u32, p: CameraBev) -> Option<WorldBev> {
        self.poses.get(frame as usize).map(|pose| pose.to_world(p))
    }

    /// Camera speed (m/s) into `frame` at `fps`.
    pub fn speed(&self, frame: u32, fps: f64) -> f64 {
        self.steps
            .get(frame as usize)
            .map_or(0.0, |s| s.translation.norm() * fps)
    }
}

/// Anchors (in label order) that seed pair hypotheses; beyond this a
/// crowded frame's pairs cost more than they add.
const MAX_PAIR_ANCHORS: usize = 16;

#[derive(Clone, Copy)]
struct Anchor {
    /// The object in camera `t`.
    a: CameraBev,
    /// The same object in camera `t−1`.
    b: CameraBev,
    yaw_a: Option<f64>,
    yaw_b: Option<f64>,
    weight: f64,
    radius: f64,
}

/// Position noise measured on a sequence itself, from the second
/// differences of every track's camera-frame ground points over three
/// consecutive frames: for smooth motion (the camera's and the object's)
/// `p(t−1) − 2p(t) + p(t+1)` is about `acceleration × dt²`, a few
/// centimetres, while independent per-frame noise of σ gives `√6·σ`.
/// Medians make it robust to id switches, swerves and the odd bad box.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct MeasuredNoise {
    /// Lateral (camera X) standard deviation, metres.
    pub lateral_m: f64,
    /// Depth (camera Z) standard deviation as a fraction of depth, at
    /// depth 0 ...
    pub depth_fraction: f64,
    /// ... growing by this much per metre of depth (monocular depth errors
    /// grow faster than linearly with distance).
    pub depth_fraction_per_m: f64,
    /// Second differences the estimate rests on (0: nothing measured).
    pub samples: usize,
}

/// Fewer second differences than this measure nothing.
const MIN_NOISE_SAMPLES: usize = 8;
/// Median absolute value → standard deviation of a normal variable.
const MAD_TO_SD: f64 = 1.0 / 0.674_489_75;

impl MeasuredNoise {
    /// Measures the noise of `seq` (sorted by `(frame, track_id)`).
    pub fn of(seq: &Sequence) -> MeasuredNoise {
        let mut by_track: std::collections::BTreeMap<u32, Vec<(u32, CameraBev)>> =
            std::collections::BTreeMap::new();
        for o in &seq.observations {
            if o.footprint.is_some() {
                continue;
            }
            if let Some(p) = ground_point(o, &seq.camera) {
                by_track.entry(o.track_id).or_default().push((o.frame, p));
            }
        }
        let (mut dx, mut dz, mut zs) = (Vec::new(), Vec::new(), Vec::new());
        for pts in by_track.values() {
            for w in pts.windows(3) {
                let [(f0, a), (f1, b), (f2, c)] = [w[0], w[1], w[2]];
                if f1 != f0 + 1 || f2 != f1 + 1 || b.z() < 1.0 {
                    continue;
                }
                dx.push((a.x() - 2.0 * b.x() + c.x()).abs());
                dz.push(((a.z() - 2.0 * b.z() + c.z()) / b.z()).abs());
                zs.push(b.z());
            }
        }
        if dx.len() < MIN_NOISE_SAMPLES {
            return MeasuredNoise::default();
        }
        let scale = MAD_TO_SD / 6f64.sqrt();
        // Relative depth noise near and far (split at the median depth): a
        // line through the two medians, never falling with depth.
        let mut zsorted = zs.clone();
        let split = crate::signal::median_in_place(&mut zsorted).unwrap_or(0.0);
        let (mut near, mut far, mut near_z, mut far_z) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for (&z, &d) in zs.iter().zip(&dz) {
            if z < split {
                near.push(d);
                near_z.push(z);
            } else {
                far.push(d);
                far_z.push(z);
            }
        }
        let all = crate::signal::median_in_place(&mut dz).unwrap_or(0.0) * scale;
        let (mut depth_fraction, mut depth_fraction_per_m) = (all, 0.0);
        if near.len() >= MIN_NOISE_SAMPLES && far.len() >= MIN_NOISE_SAMPLES {
            let med = |v: &mut Vec<f64>| crate::signal::median_in_place(v).unwrap_or(0.0);
            let (mn, mf) = (med(&mut near) * scale, med(&mut far) * scale);
            let (zn, zf) = (med(&mut near_z), med(&mut far_z));
            if zf > zn + 1.0 && mf > mn {
                depth_fraction_per_m = (mf - mn) / (zf - zn);
                depth_fraction = (mn - depth_fraction_per_m * zn).max(0.0);
            }
        }
        MeasuredNoise {
            lateral_m: crate::signal::median_in_place(&mut dx).unwrap_or(0.0) * scale,
            depth_fraction,
            depth_fraction_per_m,
            samples: dx.len(),
        }
    }

    /// Standard deviation (m) of a single sighting's depth at `depth`.
    pub fn depth_sd(&self, depth: f64) -> f64 {
        (self.depth_fraction + self.depth_fraction_per_m * depth) * depth
    }

    /// Standard deviation (m) of one coordinate of the difference of two
    /// independent noisy sightings at `depth` (the residual of a static
    /// anchor under the true motion), the two axes pooled.
    pub fn residual_sd(&self, depth: f64) -> f64 {
        let dz = self.depth_sd(depth);
        (self.lateral_m * self.lateral_m + dz * dz).sqrt() * std::f64::consts::SQRT_2
    }
}

/// Inlier radius of an anchor at `depth`: the configured base and depth
/// terms, widened to `inlier_noise_k` residual standard deviations when
/// the measured noise calls for it.
fn inlier_radius(cfg: &EgoConfig, noise: &MeasuredNoise, depth: f64) -> f64 {
    let base = cfg.inlier_base_m + cfg.inlier_depth_fraction * depth;
    if cfg.noise_adaptive {
        base.max(cfg.inlier_noise_k * noise.residual_sd(depth))
    } else {
        base
    }
}

/// Anchors between the observations of two frames (both sorted by track
/// id): every object seen in both with a ground point, surfaces excepted.
fn collect_anchors(
    seq: &Sequence,
    prev: &[crate::model::Observation],
    cur: &[crate::model::Observation],
    cfg: &EgoConfig,
    noise: &MeasuredNoise,
    anchors: &mut Vec<Anchor>,
) {
    anchors.clear();
    // Merge-join on track id (both sorted).
    let (mut x, mut y) = (0, 0);
    while x < prev.len() && y < cur.len() {
        let (o_prev, o_cur) = (&prev[x], &cur[y]);
        match o_prev.track_id.cmp(&o_cur.track_id) {
            std::cmp::Ordering::Less => x += 1,
            std::cmp::Ordering::Greater => y += 1,
            std::cmp::Ordering::Equal => {
                x += 1;
                y += 1;
                if o_cur.footprint.is_some() {
                    continue;
                }
                let (Some(a), Some(b)) = (
                    ground_point(o_cur, &seq.camera),
                    ground_point(o_prev, &seq.camera),
                ) else {
                    continue;
                };
                let depth = a.z().abs().max(b.z().abs());
                anchors.push(Anchor {
                    a,
                    b,
                    yaw_a: o_cur.yaw,
                    yaw_b: o_prev.yaw,
                    weight: if o_cur.class.is_static() {
                        cfg.static_anchor_weight
                    } else {
                        1.0
                    },
                    radius: inlier_radius(cfg, noise, depth),
                });
            }
        }
    }
}

/// The step that takes pose `from` to pose `to` (camera `to` in camera `from`).
fn relative_step(from: &EgoPose, to: &EgoPose) -> EgoStep {
    EgoStep {
        dyaw: wrap_angle(to.yaw - from.yaw),
        translation: from.to_camera(to.position).0.coords,
        anchors: 0,
        inliers: 0,
        fallback: false,
    }
}

/// Estimates the camera trajectory of `seq` (observations must be sorted by
/// `(frame, track_id)`, see [`Sequence::validate`]).
///
/// A sequence that carries its poses (`Sequence::ego_poses`) is not
/// estimated: its poses are used as measured ([`EgoMotion::known`]).
pub fn estimate(seq: &Sequence, cfg: &EgoConfig) -> EgoMotion {
    if let Some(known) = EgoMotion::known(seq) {
        return known;
    }
    let n = seq.frame_count as usize;
    if !cfg.enabled || n == 0 {
        return EgoMotion::stationary(seq.frame_count);
    }
    // Frame ranges into the sorted observations.
    let mut ranges = vec![(0usize, 0usize); n];
    let mut i = 0;
    let obs = &seq.observations;
    while i < obs.len() {
        let f = obs[i].frame as usize;
        let mut j = i;
        while j < obs.len() && obs[j].frame as usize == f {
            j += 1;
        }
        if let Some(r) = ranges.get_mut(f) {
            *r = (i, j);
        }
        i = j;
    }
    let noise = if cfg.noise_adaptive {
        MeasuredNoise::of(seq)
    } else {
        MeasuredNoise::default()
    };
    // Averaging over earlier frames only where the noise widened some
    // anchor's radius: noise-free input keeps the frame-to-frame chain.
    let widened = cfg.noise_adaptive
        && obs.iter().filter_map(|o| o.position).any(|p| {
            let d = p[2].abs();
            cfg.inlier_noise_k * noise.residual_sd(d)
                > cfg.inlier_base_m + cfg.inlier_depth_fraction * d
        });
    let span = if widened {
        cfg.averaging_frames.max(1) as usize
    } else {
        1
    };
    let dt = 1.0 / seq.fps;
    let mut steps = Vec::with_capacity(n);
    steps.push(EgoStep::IDENTITY);
    let mut poses = Vec::with_capacity(n);
    poses.push(EgoPose::IDENTITY);
    let mut prior = EgoStep::IDENTITY;
    let mut has_prior = false;
    let mut anchors: Vec<Anchor> = Vec::new();
    for t in 1..n {
        let (c0, c1) = ranges[t];
        let cur = &obs[c0..c1];
        let (p0, p1) = ranges[t - 1];
        collect_anchors(seq, &obs[p0..p1], cur, cfg, &noise, &mut anchors);
        let step = fit_step(&anchors, &prior, has_prior, dt, cfg);
        let last = poses[t - 1];
        let chained = last.then(&step);
        let mut pose = chained;
        let mut recorded = step;
        if span > 1 && !step.fallback {
            // The pose as seen from each of the earlier frames, weighted by
            // its inliers; the frame-to-frame fit is the first of them.
            let w = step.inliers.max(1) as f64;
            let (mut sw, mut sx, mut sz, mut ss, mut sc) = (
                w,
                w * chained.position.x(),
                w * chained.position.z(),
                w * chained.yaw.sin(),
                w * chained.yaw.cos(),
            );
            for k in 2..=span.min(t) {
                let from = poses[t - k];
                let (q0, q1) = ranges[t - k];
                collect_anchors(seq, &obs[q0..q1], cur, cfg, &noise, &mut anchors);
                let predicted = relative_step(&from, &chained);
                let s = fit_step(&anchors, &predicted, true, dt * k as f64, cfg);
                if s.fallback {
                    continue;
                }
                let p = from.then(&s);
                let w = s.inliers.max(1) as f64;
                sw += w;
                sx += w * p.position.x();
                sz += w * p.position.z();
                ss += w * p.yaw.sin();
                sc += w * p.yaw.cos();
            }
            pose = EgoPose {
                position: WorldBev::new(sx / sw, sz / sw),
                yaw: ss.atan2(sc),
            };
            recorded = EgoStep {
                anchors: step.anchors,
                inliers: step.inliers,
                ..relative_step(&last, &pose)
            };
        }
        if !step.fallback {
            has_prior = true;
        }
        prior = recorded;
        steps.push(recorded);
        poses.push(pose);
    }
    EgoMotion {
        poses,
        steps,
        noise,
        anchor: None,
    }
}

fn cost(step: &EgoStep, anchors: &[Anchor], prior: &EgoStep, has_prior: bool) -> f64 {
    let mut c = 0.0;
    let (right, forward) = yaw_axes(step.dyaw);
    let origin = Point2::from(step.translation);
    for an in anchors {
        let p = origin + right * an.a.x() + forward * an.a.z();
        let r2 = (p - an.b.0).norm_squared();
        c += an.weight * (r2 / (an.radius * an.radius)).min(1.0);
    }
    if has_prior {
        // Ego motion is smooth: a small, bounded preference for the previous
        // step breaks ties between equally supported hypotheses.
        let d2 = (step.translation - prior.translation).norm_squared();
        c += 0.5 * (d2 / 0.25).min(1.0);
    }
    c
}

fn plausible(step: &EgoStep, dt: f64, cfg: &EgoConfig) -> bool {
    let speed = step.translation.norm() / dt;
    speed <= cfg.max_speed_mps
        && step.dyaw.abs() / dt <= cfg.max_yaw_rate_rps
        && step.dyaw.is_finite()
        && speed.is_finite()
}

/// Weighted least-squares rigid fit `b ≈ R(θ)·a + T` (2D Kabsch).
fn kabsch(anchors: &[Anchor], mask: &[bool]) -> Option<EgoStep> {
    let mut w = 0.0;
    let (mut ma, mut mb) = (Vector2::zeros(), Vector2::zeros());
    for (an, &m) in anchors.iter().zip(mask) {
        if m {
            w += an.weight;
            ma += an.a.0.coords * an.weight;
            mb += an.b.0.coords * an.weight;
        }
    }
    if w <= 0.0 {
        return None;
    }
    ma /= w;
    mb /= w;
    // Cosine and sine sums of the rotation taking centred `a` onto
    // centred `b` (in the heading sense of `yaw_rotation`).
    let (mut sa, mut sb) = (0.0, 0.0);
    for (an, &m) in anchors.iter().zip(mask) {
        if m {
            let a = an.a.0.coords - ma;
            let b = an.b.0.coords - mb;
            sa += an.weight * a.dot(&b);
            sb += an.weight * b.perp(&a);
        }
    }
    let dyaw = if sa.abs() + sb.abs() > 1e-12 {
        sb.atan2(sa)
    } else {
        0.0
    };
    Some(EgoStep {
        dyaw,
        translation: mb - yaw_rotation(dyaw) * ma,
        anchors: anchors.len(),
        inliers: 0,
        fallback: false,
    })
}

fn from_point_and_yaw(an: &Anchor, dyaw: f64) -> EgoStep {
    EgoStep {
        dyaw,
        translation: an.b.0.coords - yaw_rotation(dyaw) * an.a.0.coords,
        anchors: 0,
        inliers: 0,
        fallback: false,
    }
}

fn fit_step(
    anchors: &[Anchor],
    prior: &EgoStep,
    has_prior: bool,
    dt: f64,
    cfg: &EgoConfig,
) -> EgoStep {
    let fallback = EgoStep {
        anchors: anchors.len(),
        inliers: 0,
        fallback: true,
        ..*prior
    };
    if anchors.is_empty() {
        return fallback;
    }
    let mut best: Option<(f64, EgoStep)> = None;
    let mut consider = |h: EgoStep| {
        if !plausible(&h, dt, cfg) {
            return;
        }
        let c = cost(&h, anchors, prior, has_prior);
        if best.as_ref().is_none_or(|(bc, _)| c < *bc - 1e-12) {
            best = Some((c, h));
        }
    };
    consider(EgoStep {
        fallback: false,
        ..EgoStep::IDENTITY
    });
    consider(EgoStep {
        fallback: false,
        ..*prior
    });
    for an in anchors {
        if let (Some(ya), Some(yb)) = (an.yaw_a, an.yaw_b) {
            consider(from_point_and_yaw(an, wrap_angle(yb - ya)));
        }
    }
    // Pair hypotheses; bounded so a crowded frame stays cheap.
    let m = anchors.len().min(MAX_PAIR_ANCHORS);
    for i in 0..m {
        for j in i + 1..m {
            if let Some(h) = kabsch(&[anchors[i], anchors[j]], &[true, true]) {
                consider(h);
            }
        }
    }
    let Some((_, mut step)) = best else {
        return fallback;
    };
    // Refine on the inliers, twice (inliers may change after the first refit).
    let mut mask = vec![false; anchors.len()];
    for _ in 0..2 {
        let mut weight = 0.0;
        let mut count = 0;
        for (k, an) in anchors.iter().enumerate() {
            let r = (step.apply(an.a).0 - an.b.0).norm();
            mask[k] = r <= an.radius;
            if mask[k] {
                weight += an.weight;
                count += 1;
            }
        }
        if weight < cfg.min_inlier_weight {
            return fallback;
        }
        step.inliers = count;
        if count >= 2
            && let Some(refit) = kabsch(anchors, &mask)
            && plausible(&refit, dt, cfg)
        {
            step = EgoStep {
                inliers: count,
                ..refit
            };
        }
    }
    step.anchors = anchors.len();
    step.fallback = false;
    step
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::coords::{CameraPoint, WorldBev, WorldPoint};
    use crate::model::{
        BBox2D, CameraConfig, CameraIntrinsics, CameraPose, ObjectClass, Observation,
    };

    fn obs(frame: u32, id: u32, p: [f64; 2], yaw: f64) -> Observation {
        Observation {
            frame,
            track_id: id,
            class: ObjectClass::Vehicle,
            type_name: Some("Car".into()),
            color: None,
            bbox: Some(BBox2D {
                left: 0.0,
                top: 0.0,
                right: 10.0,
                bottom: 10.0,
            }),
            position: Some([p[0], 1.65, p[1]]),
            size: Some([1.5, 1.6, 4.0]),
            yaw: Some(yaw),
            confidence: 1.0,
            truncation: None,
            occlusion: None,
            footprint: None,
            depth_source: None,
        }
    }

    /// Camera drives forward at 1 m/frame while turning slightly, past four
    /// parked cars; one car drives along with the camera. The fit recovers
    /// the camera motion and rejects the mover.
    #[test]
    fn recovers_motion_and_rejects_a_mover() {
        let parked = [[-4.0, 10.0], [4.0, 15.0], [-4.0, 25.0], [5.0, 30.0]];
        let mut observations = Vec::new();
        let mut pose = CameraPose {
            position: [0.0, -1.65, 0.0],
            yaw: 0.0,
        };
        for f in 0..8u32 {
            for (k, p) in parked.iter().enumerate() {
                let c = pose.world_to_camera(WorldPoint::new(p[0], 0.0, p[1])).bev();
                observations.push(obs(f, k as u32, c.xz(), -1.5 - pose.yaw));
            }
            // Mover: 8 m ahead of the camera at all times.
            observations.push(obs(f, 9, [0.0, 8.0], -1.57));
            pose = CameraPose {
                position: pose
                    .camera_to_world(CameraPoint::new(0.0, 0.0, 1.0))
                    .to_array(),
                yaw: pose.yaw + 0.02,
            };
        }
        let seq = Sequence {
            name: "t".into(),
            source: "test".into(),
            camera: CameraConfig {
                intrinsics: CameraIntrinsics {
                    fx: 700.0,
                    fy: 700.0,
                    cx: 600.0,
                    cy: 180.0,
                    image_width: 1200,
                    image_height: 370,
                },
                height_m: 1.65,
            },
            frame_count: 8,
            fps: 10.0,
            observations,
            timestamps_ns: None,
            ego_poses: None,
            map: None,
            track_keys: Default::default(),
            skipped: Vec::new(),
        };
        seq.validate().unwrap();
        let ego = estimate(&seq, &EgoConfig::default());
        for s in &ego.steps[1..] {
            assert!(!s.fallback);
            assert!((s.translation[1] - 1.0).abs() < 1e-6, "{s:?}");
            assert!((s.dyaw - 0.02).abs() < 1e-6, "{s:?}");
            assert_eq!(s.inliers, 4);
        }
        assert!((ego.poses[7].yaw - 0.14).abs() < 1e-6);
    }

    #[test]
    fn measured_noise_is_near_zero_without_noise_and_near_the_truth_with_it() {
        use crate::sim::{NoisePreset, Scenario, simulate};
        let mut s = Scenario::builtin("urban_crossing").unwrap();
        let clean = MeasuredNoise::of(&simulate(&s, 0).unwrap().sequence);
        assert!(clean.samples > 100, "{clean:?}");
        assert!(
            clean.lateral_m < 0.02 && clean.depth_sd(20.0) < 0.05,
            "{clean:?}"
        );
        // Noise-free: the radius is the configured one, nothing widens.
        let cfg = EgoConfig::default();
        assert_eq!(inlier_radius(&cfg, &clean, 20.0), 0.15 + 0.01 * 20.0);
        s.noise = NoisePreset::High.spec();
        let high = MeasuredNoise::of(&simulate(&s, 0).unwrap().sequence);
        // The preset: σ 0.3 m laterally, 3 % of depth.
        assert!((high.lateral_m - 0.3).abs() < 0.08, "{high:?}");
        assert!((high.depth_sd(20.0) - 0.6).abs() < 0.2, "{high:?}");
        assert!(inlier_radius(&cfg, &high, 20.0) > 1.5);
    }

    /// High noise drifted the frame-to-frame chain by metres per window;
    /// the noise-adaptive fit keeps it within a metre on average.
    #[test]
    fn noisy_ego_motion_drifts_little_over_a_window() {
        use crate::sim::{NoisePreset, Scenario, simulate};
        let mut s = Scenario::builtin("urban_crossing").unwrap();
        s.noise = NoisePreset::High.spec();
        let drift = |cfg: &EgoConfig| {
            let (mut sum, mut n) = (0.0, 0);
            for seed in 0..2 {
                let run = simulate(&s, seed).unwrap();
                let est = estimate(&run.sequence, cfg);
                let t0 = run.states[0].camera_pose;
                let rel = |f: usize| {
                    let p = run.states[f].camera_pose.position;
                    t0.world_to_camera(WorldPoint::new(p[0], p[1], p[2])).bev()
                };
                for f in (0..run.states.len() - 9).step_by(10) {
                    let truth = rel(f + 9).0 - rel(f).0;
                    let got = est.poses[f + 9].position.0 - est.poses[f].position.0;
                    sum += (got - truth).norm();
                    n += 1;
                }
            }
            sum / f64::from(n)
        };
        let fixed = EgoConfig {
            noise_adaptive: false,
            ..EgoConfig::default()
        };
        let (before, after) = (drift(&fixed), drift(&EgoConfig::default()));
        assert!(after < 1.0 && after < 0.5 * before, "{before} -> {after}");
    }

    #[test]
    fn a_pose_maps_camera_points_into_the_world_and_back() {
        let pose = EgoPose {
            position: WorldBev::new(3.0, 7.0),
            yaw: 0.4,
        };
        let p = CameraBev::new(1.0, -2.0);
        let w = pose.to_world(p);
        assert!((pose.isometry() * p.0 - w.0).norm() < 1e-12);
        assert!((pose.to_camera(w).0 - p.0).norm() < 1e-12);
        // The camera looks along (sin yaw, cos yaw).
        let ahead = pose.to_world(CameraBev::new(0.0, 1.0));
        let want = WorldBev::new(3.0 + 0.4f64.sin(), 7.0 + 0.4f64.cos());
        assert!((ahead.0 - want.0).norm() < 1e-12, "{ahead:?}");
        // Chaining a step is composing the isometries.
        let step = EgoStep {
            dyaw: -0.1,
            translation: Vector2::new(0.3, 1.2),
            ..EgoStep::IDENTITY
        };
        let next = pose.then(&step);
        let composed = pose.isometry() * step.isometry();
        assert!((next.isometry().translation.vector - composed.translation.vector).norm() < 1e-12);
        assert!((next.yaw - 0.3).abs() < 1e-12);
        assert!((step.apply(p).0 - step.isometry() * p.0).norm() < 1e-12);
    }
}
