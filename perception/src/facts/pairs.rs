//! Pair facts: the loop over a window's pairs, their common frames, facts
//! emitted with their converse, and `On` (road users on surfaces, people on
//! vehicles).

use crate::geometry::{covered_fraction, observation_footprint, point_in_polygon};
use crate::model::ObjectClass;

use super::relative::RelativeScratch;
use super::{DEFAULT_FOOTPRINT_M, TrackState, WindowCtx};

impl WindowCtx<'_, '_> {
    pub(super) fn pair_facts(&mut self, present: &[(usize, std::ops::Range<usize>)]) {
        let tracks = &self.a.tracks;
        // One set of buffers for every pair of the window: the pair loop is
        // O(n²), so it must not allocate per pair, let alone per frame.
        let mut scratch = RelativeScratch::default();
        for (i, (ti, ri)) in present.iter().enumerate() {
            let x = &tracks[*ti];
            if x.surface {
                continue;
            }
            for (tj, rj) in present.iter().skip(i + 1) {
                let y = &tracks[*tj];
                if y.surface {
                    continue;
                }
                if x.class.is_static() && y.class.is_static() {
                    continue;
                }
                self.distance_facts(&mut scratch, x, ri.clone(), y, rj.clone());
                if !x.class.is_ground_surface() && !y.class.is_ground_surface() {
                    self.relative_facts(&mut scratch, x, ri.clone(), y, rj.clone());
                    self.closer_facts(x, ri.clone(), y, rj.clone());
                }
            }
        }
        // On(x, y): road users on surfaces, people on vehicles.
        for (ti, ri) in present {
            let x = &tracks[*ti];
            if x.surface || x.class.is_static() {
                continue;
            }
            for (tj, rj) in present {
                if ti == tj {
                    continue;
                }
                let y = &tracks[*tj];
                if y.surface {
                    self.on_surface(x, ri.clone(), y, rj.clone());
                } else if x.class.is_person_like() && y.class == ObjectClass::Vehicle {
                    self.on_vehicle(x, ri.clone(), y, rj.clone());
                }
            }
        }
    }

    /// Frames where both are observed, as pairs of observation indices, in
    /// frame order: a merge of the two sorted frame lists, O(|rx| + |ry|)
    /// and lazy, so the pair loop allocates nothing for it.
    pub(super) fn common<'t>(
        x: &'t TrackState,
        rx: std::ops::Range<usize>,
        y: &'t TrackState,
        ry: std::ops::Range<usize>,
    ) -> impl Iterator<Item = (usize, usize)> + 't {
        let (mut a, mut b) = (rx.start, ry.start);
        std::iter::from_fn(move || {
            while a < rx.end && b < ry.end {
                match x.frames[a].cmp(&y.frames[b]) {
                    std::cmp::Ordering::Less => a += 1,
                    std::cmp::Ordering::Greater => b += 1,
                    std::cmp::Ordering::Equal => {
                        let both = (a, b);
                        a += 1;
                        b += 1;
                        return Some(both);
                    }
                }
            }
            None
        })
    }

    /// Emits `pred(first, second)` and its converse `conv(second, first)`
    /// from one measurement, so that the converse property holds by
    /// construction (`RightOf(y, x)` iff `LeftOf(x, y)`), both with the
    /// measurement's probability.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn push_with_converse(
        &mut self,
        (pred, conv): (&str, &str),
        (first, second): (&str, &str),
        measured: f64,
        threshold: (&str, f64),
        note: String,
        converse_note: String,
        probability: f64,
    ) {
        self.push_p(
            pred,
            &[first, second],
            Some(measured),
            Some(threshold),
            note,
            probability,
        );
        self.push_p(
            conv,
            &[second, first],
            Some(measured),
            Some(threshold),
            converse_note,
            probability,
        );
    }

    fn on_surface(
        &mut self,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let frames = rx.len();
        let on = Self::common(x, rx, y, ry)
            .filter(|&(a, b)| match (x.cam[a], y.footprints[b].as_deref()) {
                (Some(p), Some(poly)) => point_in_polygon(p, poly),
                _ => false,
            })
            .count();
        self.on_fact(x, y, on, frames, "ground point inside the surface");
    }

    fn on_vehicle(
        &mut self,
        x: &TrackState,
        rx: std::ops::Range<usize>,
        y: &TrackState,
        ry: std::ops::Range<usize>,
    ) {
        let frames = rx.len();
        let on = Self::common(x, rx, y, ry)
            .filter(|&(a, b)| match (x.cam[a], y.cam[b]) {
                (Some(pa), Some(pb)) => {
                    let fa = observation_footprint(pa, self.obs(x, a), DEFAULT_FOOTPRINT_M);
                    let fb = observation_footprint(pb, self.obs(y, b), DEFAULT_FOOTPRINT_M);
                    covered_fraction(&fa, &fb) >= 0.5
                }
                _ => false,
            })
            .count();
        self.on_fact(x, y, on, frames, "footprint mostly over the vehicle's");
    }

    fn on_fact(&mut self, x: &TrackState, y: &TrackState, on: usize, frames: usize, what: &str) {
        if on == 0 || frames == 0 {
            return;
        }
        let cfg = self.a.config;
        let frac = on as f64 / frames as f64;
        // `On` holds when the fraction reaches on_min_fraction; its belief
        // is the posterior that the true fraction of frames does.
        self.decide(
            frac >= cfg.on_min_fraction,
            "On",
            &[&x.name, &y.name],
            Some(frac),
            Some(("on_min_fraction", cfg.on_min_fraction)),
            |_| format!("{what} in {on} of {frames} frames"),
            crate::belief::majority(on, frames, cfg.on_min_fraction),
        );
    }
}
