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

use crate::config::EgoConfig;
use crate::geometry::{Bev, ground_point, wrap_angle};
use crate::model::{CameraPose, Sequence};

/// One frame-to-frame motion step: camera `t` expressed in camera `t−1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EgoStep {
    /// Heading change, radians.
    pub dyaw: f64,
    /// Translation `(X, Z)` of camera `t`'s origin in camera `t−1`, metres.
    pub translation: Bev,
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
        translation: [0.0, 0.0],
        anchors: 0,
        inliers: 0,
        fallback: true,
    };

    fn apply(&self, p: Bev) -> Bev {
        let (s, c) = self.dyaw.sin_cos();
        [
            self.translation[0] + c * p[0] + s * p[1],
            self.translation[1] - s * p[0] + c * p[1],
        ]
    }
}

/// The camera trajectory of a sequence.
#[derive(Debug, Clone, PartialEq)]
pub struct EgoMotion {
    /// Pose of the camera at each frame in the world (camera of frame 0),
    /// `frame_count` entries.
    pub poses: Vec<CameraPose>,
    /// Step into each frame (`steps[0]` is the identity).
    pub steps: Vec<EgoStep>,
}

impl EgoMotion {
    /// A camera that does not move (used when ego-motion is disabled).
    pub fn stationary(frame_count: u32, height_m: f64) -> EgoMotion {
        let pose = CameraPose {
            position: [0.0, -height_m, 0.0],
            yaw: 0.0,
        };
        EgoMotion {
            poses: vec![pose; frame_count as usize],
            steps: vec![EgoStep::IDENTITY; frame_count as usize],
        }
    }

    /// World bird's-eye point of a camera bird's-eye point seen at `frame`.
    pub fn to_world(&self, frame: u32, p: Bev) -> Bev {
        match self.poses.get(frame as usize) {
            Some(pose) => {
                let w = pose.camera_to_world([p[0], 0.0, p[1]]);
                [w[0], w[2]]
            }
            None => p,
        }
    }

    /// Camera speed (m/s) into `frame` at `fps`.
    pub fn speed(&self, frame: u32, fps: f64) -> f64 {
        self.steps.get(frame as usize).map_or(0.0, |s| {
            (s.translation[0].powi(2) + s.translation[1].powi(2)).sqrt() * fps
        })
    }
}

/// Anchors (in label order) that seed pair hypotheses; beyond this a
/// crowded frame's pairs cost more than they add.
const MAX_PAIR_ANCHORS: usize = 16;

#[derive(Clone, Copy)]
struct Anchor {
    a: Bev,
    b: Bev,
    yaw_a: Option<f64>,
    yaw_b: Option<f64>,
    weight: f64,
    radius: f64,
}

/// Estimates the camera trajectory of `seq` (observations must be sorted by
/// `(frame, track_id)`, see [`Sequence::validate`]).
pub fn estimate(seq: &Sequence, cfg: &EgoConfig) -> EgoMotion {
    let n = seq.frame_count as usize;
    if !cfg.enabled || n == 0 {
        return EgoMotion::stationary(seq.frame_count, seq.camera.height_m);
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
    let dt = 1.0 / seq.fps;
    let mut steps = Vec::with_capacity(n);
    steps.push(EgoStep::IDENTITY);
    let mut prior = EgoStep::IDENTITY;
    let mut has_prior = false;
    let mut anchors: Vec<Anchor> = Vec::new();
    for t in 1..n {
        anchors.clear();
        let (p0, p1) = ranges[t - 1];
        let (c0, c1) = ranges[t];
        let (prev, cur) = (&obs[p0..p1], &obs[c0..c1]);
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
                    let depth = a[1].abs().max(b[1].abs());
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
                        radius: cfg.inlier_base_m + cfg.inlier_depth_fraction * depth,
                    });
                }
            }
        }
        let step = fit_step(&anchors, &prior, has_prior, dt, cfg);
        if !step.fallback {
            has_prior = true;
        }
        prior = step;
        steps.push(step);
    }
    let mut poses = Vec::with_capacity(n);
    let mut pose = CameraPose {
        position: [0.0, -seq.camera.height_m, 0.0],
        yaw: 0.0,
    };
    for (t, s) in steps.iter().enumerate() {
        if t > 0 {
            let pos = pose.camera_to_world([s.translation[0], 0.0, s.translation[1]]);
            pose = CameraPose {
                position: pos,
                yaw: wrap_angle(pose.yaw + s.dyaw),
            };
        }
        poses.push(pose);
    }
    EgoMotion { poses, steps }
}

fn cost(step: &EgoStep, anchors: &[Anchor], prior: &EgoStep, has_prior: bool) -> f64 {
    let mut c = 0.0;
    let (s, co) = step.dyaw.sin_cos();
    for an in anchors {
        let p = [
            step.translation[0] + co * an.a[0] + s * an.a[1],
            step.translation[1] - s * an.a[0] + co * an.a[1],
        ];
        let r2 = (p[0] - an.b[0]).powi(2) + (p[1] - an.b[1]).powi(2);
        c += an.weight * (r2 / (an.radius * an.radius)).min(1.0);
    }
    if has_prior {
        // Ego motion is smooth: a small, bounded preference for the previous
        // step breaks ties between equally supported hypotheses.
        let d2 = (step.translation[0] - prior.translation[0]).powi(2)
            + (step.translation[1] - prior.translation[1]).powi(2);
        c += 0.5 * (d2 / 0.25).min(1.0);
    }
    c
}

fn plausible(step: &EgoStep, dt: f64, cfg: &EgoConfig) -> bool {
    let speed = (step.translation[0].powi(2) + step.translation[1].powi(2)).sqrt() / dt;
    speed <= cfg.max_speed_mps
        && step.dyaw.abs() / dt <= cfg.max_yaw_rate_rps
        && step.dyaw.is_finite()
        && speed.is_finite()
}

/// Weighted least-squares rigid fit `b ≈ R(θ)·a + T` (2D Kabsch).
fn kabsch(anchors: &[Anchor], mask: &[bool]) -> Option<EgoStep> {
    let mut w = 0.0;
    let (mut ma, mut mb) = ([0.0; 2], [0.0; 2]);
    for (an, &m) in anchors.iter().zip(mask) {
        if m {
            w += an.weight;
            for k in 0..2 {
                ma[k] += an.weight * an.a[k];
                mb[k] += an.weight * an.b[k];
            }
        }
    }
    if w <= 0.0 {
        return None;
    }
    for k in 0..2 {
        ma[k] /= w;
        mb[k] /= w;
    }
    let (mut sa, mut sb) = (0.0, 0.0);
    for (an, &m) in anchors.iter().zip(mask) {
        if m {
            let a = [an.a[0] - ma[0], an.a[1] - ma[1]];
            let b = [an.b[0] - mb[0], an.b[1] - mb[1]];
            sa += an.weight * (a[0] * b[0] + a[1] * b[1]);
            sb += an.weight * (b[0] * a[1] - b[1] * a[0]);
        }
    }
    let dyaw = if sa.abs() + sb.abs() > 1e-12 {
        sb.atan2(sa)
    } else {
        0.0
    };
    let (s, c) = dyaw.sin_cos();
    let t = [
        mb[0] - (c * ma[0] + s * ma[1]),
        mb[1] - (-s * ma[0] + c * ma[1]),
    ];
    Some(EgoStep {
        dyaw,
        translation: t,
        anchors: anchors.len(),
        inliers: 0,
        fallback: false,
    })
}

fn from_point_and_yaw(an: &Anchor, dyaw: f64) -> EgoStep {
    let (s, c) = dyaw.sin_cos();
    let t = [
        an.b[0] - (c * an.a[0] + s * an.a[1]),
        an.b[1] - (-s * an.a[0] + c * an.a[1]),
    ];
    EgoStep {
        dyaw,
        translation: t,
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
            let p = step.apply(an.a);
            let r = ((p[0] - an.b[0]).powi(2) + (p[1] - an.b[1]).powi(2)).sqrt();
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
    use crate::model::{BBox2D, CameraConfig, CameraIntrinsics, ObjectClass, Observation};

    fn obs(frame: u32, id: u32, p: [f64; 2], yaw: f64) -> Observation {
        Observation {
            frame,
            track_id: id,
            class: ObjectClass::Vehicle,
            type_name: Some("Car".into()),
            color: None,
            bbox: BBox2D {
                left: 0.0,
                top: 0.0,
                right: 10.0,
                bottom: 10.0,
            },
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
                let c = pose.world_to_camera([p[0], 0.0, p[1]]);
                observations.push(obs(f, k as u32, [c[0], c[2]], -1.5 - pose.yaw));
            }
            // Mover: 8 m ahead of the camera at all times.
            observations.push(obs(f, 9, [0.0, 8.0], -1.57));
            pose = CameraPose {
                position: pose.camera_to_world([0.0, 0.0, 1.0]),
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
}
