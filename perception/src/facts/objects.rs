//! Per-object facts: class, type, colour, appearance and disappearance,
//! locations, and the motion facts of the objects that can move.

use super::{TrackState, WindowCtx};

impl WindowCtx<'_, '_> {
    pub(super) fn object_facts(&mut self, t: &TrackState, r: std::ops::Range<usize>) {
        let cfg = self.a.config;
        let name = t.name.as_str();
        let class = t.class.predicate();
        // A detector's track is as sure as its detections: their mean
        // score over the window (the detector's own figure, not
        // calibrated); labels and the simulator score 1 and are certain.
        // Not subject to `exact`: it is about what, not where.
        let n = r.len().max(1) as f64;
        let score = r
            .clone()
            .map(|k| f64::from(self.obs(t, k).confidence))
            .sum::<f64>()
            / n;
        let detected = (score < 1.0).then(|| score.clamp(0.0, 1.0));
        let scored = |what: &str| match detected {
            Some(s) => format!(
                "{what} (mean detector score {s:.2} over {} sightings)",
                r.len()
            ),
            None => what.to_string(),
        };
        let fact = self.fact(
            class,
            &[name],
            None,
            None,
            scored(&match self.a.seq.track_keys.get(&t.track_id) {
                // The full source id (an AV2 track_uuid), which the name
                // shortens to 8 characters.
                Some(key) => format!("class of track {} (source track id {key})", t.name),
                None => format!("class of track {}", t.name),
            }),
            detected,
        );
        self.facts.push(fact);
        if let Some(v) = &t.type_value {
            let fact = self.fact(
                "TypeOf",
                &[name, v],
                None,
                None,
                scored("type from the source"),
                detected,
            );
            self.facts.push(fact);
        }
        if let Some(v) = &t.color_value {
            self.push(
                "ColorOf",
                &[name, v],
                None,
                None,
                "colour from the source".into(),
            );
        }
        // Appear / Disappear with look-back / look-ahead beyond the window.
        let k0 = r.start;
        let k1 = r.end - 1;
        let f_in = t.frames[k0];
        let seen_before = k0 > 0 && f_in - t.frames[k0 - 1] <= cfg.appear_lookback_frames;
        if f_in > 0 && !seen_before {
            self.push(
                "Appear",
                &[name],
                Some(f64::from(f_in)),
                Some((
                    "appear_lookback_frames",
                    f64::from(cfg.appear_lookback_frames),
                )),
                format!(
                    "first seen in frame {f_in}, not in the {} frames before",
                    cfg.appear_lookback_frames
                ),
            );
        }
        let f_out = t.frames[k1];
        let seen_after =
            k1 + 1 < t.frames.len() && t.frames[k1 + 1] - f_out <= cfg.disappear_lookahead_frames;
        if f_out + 1 < self.a.seq.frame_count && !seen_after {
            self.push(
                "Disappear",
                &[name],
                Some(f64::from(f_out)),
                Some((
                    "disappear_lookahead_frames",
                    f64::from(cfg.disappear_lookahead_frames),
                )),
                format!(
                    "last seen in frame {f_out}, not in the {} frames after",
                    cfg.disappear_lookahead_frames
                ),
            );
        }
        let z0 = self.location("InitialLocation", t, k0, r.clone());
        let z1 = self.location("LastLocation", t, k1, r.clone());
        if !t.surface && !t.class.is_ground_surface() {
            self.near_fact(t, r.clone(), z0, z1);
        }
        // AtLeft / AtRight / AtCenter from the median box centre.
        let fracs: Vec<f64> = (k0..=k1)
            .filter_map(|k| self.x_fraction(self.obs(t, k)))
            .collect();
        if let Some(m) = crate::signal::median(&fracs) {
            let (side, field, thr) = self.side(m);
            let pred = match side {
                "Left" => "AtLeft",
                "Right" => "AtRight",
                _ => "AtCenter",
            };
            self.push(
                pred,
                &[name],
                Some(m),
                Some((field, thr)),
                format!("median box centre at {m:.2} of the image width"),
            );
        }
        // CloseToCamera from the nearest ground distance.
        let nearest = (k0..=k1)
            .filter_map(|k| t.cam[k])
            .map(|g| g.0.coords.norm())
            .fold(f64::INFINITY, f64::min);
        // A surface reaches under the car whenever it is in view; nearness
        // says nothing about it.
        if nearest < cfg.close_to_camera_m && !t.surface {
            self.push(
                "CloseToCamera",
                &[name],
                Some(nearest),
                Some(("close_to_camera_m", cfg.close_to_camera_m)),
                format!(
                    "nearest ground distance {nearest:.1} m < close_to_camera_m {:.1} m",
                    cfg.close_to_camera_m
                ),
            );
        }
        if !t.class.is_static() && !t.surface {
            self.motion_facts(t);
        }
    }
}
