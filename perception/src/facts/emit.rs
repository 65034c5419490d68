//! Asserting a window's facts and doubts with their provenance: the
//! [`WindowCtx`] calls every fact family goes through.

use crate::model::{Fact, Observation, Provenance};

use super::{TrackState, WindowCtx};

impl WindowCtx<'_, '_> {
    /// Asserts a fact that is certain (read, or not measured with noise).
    pub(super) fn push(
        &mut self,
        predicate: &str,
        args: &[&str],
        measured: Option<f64>,
        threshold: Option<(&str, f64)>,
        note: String,
    ) {
        self.push_p(predicate, args, measured, threshold, note, 1.0);
    }

    /// Whether the sequence's positions were measured without noise (the
    /// labels of a dataset, a noise-free simulation): then every test is
    /// decided exactly, its facts are certain and nothing is in doubt. A
    /// window's residuals or a frame vote short of unanimous describe the
    /// scene then (a car that accelerates, a pair that crosses), not the
    /// measurement.
    fn exact(&self) -> bool {
        let n = &self.a.ego.noise;
        let cfg = self.a.config;
        n.samples > 0
            && n.lateral_m <= cfg.exact_noise_m
            && n.depth_sd(cfg.near_far_m) <= cfg.exact_noise_m
    }

    /// Asserts a measured fact with the probability its evidence gives.
    pub(super) fn push_p(
        &mut self,
        predicate: &str,
        args: &[&str],
        measured: Option<f64>,
        threshold: Option<(&str, f64)>,
        note: String,
        probability: f64,
    ) {
        let p = (probability < 1.0 && !self.exact()).then_some(probability);
        let fact = self.fact(predicate, args, measured, threshold, note, p);
        self.facts.push(fact);
    }

    /// Asserts the fact when `asserted`; else keeps it as a doubt when
    /// the probability that it holds all the same reaches
    /// `doubt_min_probability` (an exact sequence has no doubts).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn decide(
        &mut self,
        asserted: bool,
        predicate: &str,
        args: &[&str],
        measured: Option<f64>,
        threshold: Option<(&str, f64)>,
        note: impl FnOnce(bool) -> String,
        probability: f64,
    ) {
        let min = self.a.config.doubt_min_probability;
        if asserted {
            self.push_p(
                predicate,
                args,
                measured,
                threshold,
                note(true),
                probability,
            );
        } else if !self.exact() && probability > 0.0 && probability >= min {
            let p = Some(probability.min(1.0));
            let fact = self.fact(predicate, args, measured, threshold, note(false), p);
            self.doubts.push(fact);
        }
    }

    pub(super) fn fact(
        &self,
        predicate: &str,
        args: &[&str],
        measured: Option<f64>,
        threshold: Option<(&str, f64)>,
        note: String,
        probability: Option<f64>,
    ) -> Fact {
        Fact {
            predicate: predicate.to_string(),
            args: args.iter().map(|s| (*s).to_string()).collect(),
            provenance: std::sync::Arc::new(Provenance {
                window: self.index,
                frames: (self.first, self.last),
                source: self.a.source.clone(),
                measured,
                threshold: threshold.map(|(n, v)| (n.to_string(), v)),
                note,
                probability,
            }),
        }
    }

    pub(super) fn obs(&self, t: &TrackState, k: usize) -> &Observation {
        &self.a.seq.observations[t.obs[k]]
    }
}
