//! The simulator's seeded noise model: jittered boxes and positions,
//! missed detections (more of them behind nearer objects) and identity
//! switches, applied to a run's clean observations.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::run::ID_SWITCH_BASE;
use super::scenario::NoiseSpec;

use crate::model::{BBox2D, CameraConfig, Observation};

struct Noise {
    spec: NoiseSpec,
    rng: ChaCha8Rng,
}

impl Noise {
    fn gauss(&mut self) -> f64 {
        // Box–Muller; u1 in (0, 1] keeps the log finite.
        let u1: f64 = 1.0 - self.rng.random::<f64>();
        let u2: f64 = self.rng.random::<f64>();
        (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
    }
}

pub(super) fn apply_noise(
    obs: Vec<Observation>,
    spec: NoiseSpec,
    seed: u64,
    cam: &CameraConfig,
) -> Vec<Observation> {
    let mut n = Noise {
        spec,
        rng: ChaCha8Rng::seed_from_u64(seed),
    };
    let mut ids: std::collections::BTreeMap<u32, u32> = std::collections::BTreeMap::new();
    let mut next = ID_SWITCH_BASE;
    let occluded = if spec.miss_per_occlusion > 0.0 {
        occluded_fractions(&obs)
    } else {
        vec![0.0; obs.len()]
    };
    // Per-object depth scale bias, from its own stream so that it does not
    // depend on the order objects are met in.
    let bias = |id: u32| {
        if spec.depth_bias_fraction > 0.0 {
            let mut b = Noise {
                spec,
                rng: ChaCha8Rng::seed_from_u64(seed ^ (u64::from(id) << 32) ^ 0x5eed_b1a5),
            };
            spec.depth_bias_fraction * b.gauss()
        } else {
            0.0
        }
    };
    let mut out = Vec::with_capacity(obs.len());
    for (mut o, occ) in obs.into_iter().zip(occluded) {
        if o.footprint.is_some() {
            out.push(o);
            continue;
        }
        let depth = o.position.map_or(0.0, |p| p[2].max(0.0));
        let miss =
            n.spec.miss_probability + n.spec.miss_per_m * depth + n.spec.miss_per_occlusion * occ;
        if n.rng.random::<f64>() < miss {
            continue;
        }
        if !o.class.is_static() && n.rng.random::<f64>() < n.spec.id_switch_probability {
            ids.insert(o.track_id, next);
            next += 1;
        }
        if let Some(id) = ids.get(&o.track_id) {
            o.track_id = *id;
        }
        if let Some(p) = o.position.as_mut() {
            let (gx, gz) = (n.gauss(), n.gauss());
            p[0] += n.spec.position_sigma_m * gx;
            let sigma = n.spec.depth_sigma_fraction + n.spec.depth_sigma_per_m * p[2].max(0.0);
            p[2] = (p[2] * (1.0 + bias(o.track_id) + sigma * gz)).max(0.1);
        }
        let j = n.spec.box_jitter_px;
        let (a, b, c, d) = (n.gauss() * j, n.gauss() * j, n.gauss() * j, n.gauss() * j);
        let k = &cam.intrinsics;
        // The simulator's observations all have boxes (they are projected).
        let Some(ob) = o.bbox else {
            out.push(o);
            continue;
        };
        let bb = BBox2D {
            left: ob.left + a,
            top: ob.top + b,
            right: ob.right + c,
            bottom: ob.bottom + d,
        };
        let fixed = BBox2D {
            left: bb.left.min(bb.right),
            right: bb.left.max(bb.right),
            top: bb.top.min(bb.bottom),
            bottom: bb.top.max(bb.bottom),
        };
        if let Some(cl) = fixed.clip(k.image_width, k.image_height) {
            o.bbox = Some(cl);
        }
        out.push(o);
    }
    out
}

/// Per observation, the share of its box covered by the boxes of nearer
/// solid objects in the same frame (the largest single cover, so that two
/// overlapping occluders are not counted twice); 0 for surfaces.
fn occluded_fractions(obs: &[Observation]) -> Vec<f64> {
    let mut out = vec![0.0; obs.len()];
    let mut start = 0;
    while start < obs.len() {
        let frame = obs[start].frame;
        let end = start + obs[start..].iter().take_while(|o| o.frame == frame).count();
        for i in start..end {
            let (Some(a), Some(da)) = (&obs[i].bbox, obs[i].position.map(|p| p[2])) else {
                continue;
            };
            let area = a.area();
            if area <= 0.0 {
                continue;
            }
            let cover = (start..end)
                .filter(|&j| j != i && obs[j].position.is_some_and(|p| p[2] < da))
                .map(|j| {
                    let Some(b) = &obs[j].bbox else { return 0.0 };
                    let w = (a.right.min(b.right) - a.left.max(b.left)).max(0.0);
                    let h = (a.bottom.min(b.bottom) - a.top.max(b.top)).max(0.0);
                    w * h / area
                })
                .fold(0.0, f64::max);
            out[i] = cover.min(1.0);
        }
        start = end;
    }
    out
}
