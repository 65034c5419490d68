//! Facts and their provenance: where each fact came from and why it holds.

use serde::{Deserialize, Serialize};

/// Where a fact came from and why it holds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Provenance {
    /// Window index.
    pub window: u32,
    /// Inclusive frame range of the window.
    pub frames: (u32, u32),
    /// `"kitti:0000"`, `"sim:urban_crossing"`, … — shared by every fact of
    /// a source, since a window can hold millions of facts.
    pub source: std::sync::Arc<str>,
    /// The measured value compared with the threshold, when there is one.
    // In JSON, left out when absent (and read as absent when missing): a
    // fact that is read, not measured, is most facts, and a proof repeats
    // the provenance of every fact it rests on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measured: Option<f64>,
    /// `(FactConfig field name, value)` the measurement was compared with.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threshold: Option<(String, f64)>,
    /// Short human sentence, e.g. `"mean speed 3.2 m/s > moving_speed_vehicle 0.7 m/s"`.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
    /// How sure the measurement makes the fact, in (0, 1]
    /// ([`crate::belief`]); `None` is certain (read, not measured, or
    /// measured without noise). For a doubt ([`crate::WindowFacts::doubts`])
    /// it is the probability that the fact, though not asserted, holds.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub probability: Option<f64>,
}

impl Provenance {
    /// The fact's probability: 1 when certain.
    pub fn belief(&self) -> f64 {
        self.probability.unwrap_or(1.0)
    }
}

/// A positive ground fact `predicate(args…)` with its provenance.
///
/// Ordering and equality used for sorting and deduplication consider only
/// `(predicate, args)`; see [`Fact::key`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fact {
    /// Predicate name, e.g. `"Moving"`.
    pub predicate: String,
    /// Constant arguments, e.g. `["car_3"]`.
    pub args: Vec<String>,
    /// Why the fact holds. Shared: the facts of a text KB window all have
    /// one provenance, and a window can hold millions of facts.
    pub provenance: std::sync::Arc<Provenance>,
}

impl Fact {
    /// The sort and deduplication key.
    pub fn key(&self) -> (&str, &[String]) {
        (&self.predicate, &self.args)
    }

    /// The fact in the reference KB syntax, e.g. `TypeOf(car_3, Car)`.
    pub fn to_kb_line(&self) -> String {
        format!("{}({})", self.predicate, self.args.join(", "))
    }
}
