//! Windows: how a sequence is cut into windows, and the facts of one window.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

use super::Fact;
use crate::error::PerceptionError;

/// How a sequence is cut into windows: windows start at `0, stride,
/// 2·stride, …` and span `size` frames. `size = stride = 10` reproduces the
/// paper; `stride < size` gives overlapping windows.
///
/// Invariant: `size > 0`, `stride > 0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct WindowSpec {
    /// Frames per window.
    pub size: u32,
    /// Frames between window starts.
    pub stride: u32,
}

impl Default for WindowSpec {
    fn default() -> Self {
        WindowSpec {
            size: 10,
            stride: 10,
        }
    }
}

impl WindowSpec {
    /// The paper's setting: 10-frame non-overlapping windows.
    pub const PAPER: WindowSpec = WindowSpec {
        size: 10,
        stride: 10,
    };

    /// The windows `(index, first_frame, last_frame)` (inclusive) over
    /// `frame_count` frames. The last window is clipped to the sequence; a
    /// window that would only repeat the tail already covered by the previous
    /// one is not produced.
    pub fn windows(&self, frame_count: u32) -> Result<Vec<(u32, u32, u32)>, PerceptionError> {
        if self.size == 0 || self.stride == 0 {
            return Err(PerceptionError::InvalidWindow(format!(
                "size and stride must be positive, got size {} stride {}",
                self.size, self.stride
            )));
        }
        let mut out = Vec::new();
        let mut start = 0u32;
        let mut index = 0u32;
        while start < frame_count {
            let last = start.saturating_add(self.size - 1).min(frame_count - 1);
            out.push((index, start, last));
            if last == frame_count - 1 {
                break;
            }
            index += 1;
            start = start.saturating_add(self.stride);
        }
        Ok(out)
    }
}

/// The facts of one window.
///
/// Invariant: `facts` sorted by [`Fact::key`] with no duplicate key;
/// `doubts` likewise, and no doubt has the key of a fact.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WindowFacts {
    /// Window index.
    pub index: u32,
    /// First frame (inclusive).
    pub first_frame: u32,
    /// Last frame (inclusive).
    pub last_frame: u32,
    /// Sorted, deduplicated facts.
    pub facts: Vec<Fact>,
    /// Facts that were measured and not asserted, each with the probability
    /// that it holds all the same (`provenance.probability`), kept when
    /// that is at least `FactConfig::doubt_min_probability`. They are not
    /// facts of the KB: reasoning is closed-world. They say how sure an
    /// answer that rests on their absence is.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub doubts: Vec<Fact>,
}

impl WindowFacts {
    /// Sorts by key and keeps the first fact of each key.
    pub fn normalize(&mut self) {
        self.facts.sort_by(|a, b| a.key().cmp(&b.key()));
        self.facts.dedup_by(|a, b| a.key() == b.key());
        self.doubts.sort_by(|a, b| a.key().cmp(&b.key()));
        self.doubts.dedup_by(|a, b| a.key() == b.key());
        let facts = &self.facts;
        self.doubts
            .retain(|d| facts.binary_search_by(|f| f.key().cmp(&d.key())).is_err());
    }

    /// The text KB, one `Pred(a, b)` per line, sorted.
    pub fn to_kb(&self) -> String {
        let mut s = String::new();
        for f in &self.facts {
            s.push_str(&f.to_kb_line());
            s.push('\n');
        }
        s
    }

    /// The facts as relation tables: predicate → sorted argument tuples.
    pub fn relation_tables(&self) -> BTreeMap<String, Vec<Vec<String>>> {
        let mut out: BTreeMap<String, Vec<Vec<String>>> = BTreeMap::new();
        for f in &self.facts {
            out.entry(f.predicate.clone())
                .or_default()
                .push(f.args.clone());
        }
        out
    }

    /// Whether the window holds `predicate(args…)`.
    pub fn contains(&self, predicate: &str, args: &[&str]) -> bool {
        self.facts.iter().any(|f| {
            f.predicate == predicate
                && f.args.len() == args.len()
                && f.args.iter().zip(args).all(|(a, b)| a == b)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_cover_and_clip() {
        let w = WindowSpec {
            size: 10,
            stride: 10,
        };
        let ws = w.windows(25).unwrap();
        assert_eq!(ws, vec![(0, 0, 9), (1, 10, 19), (2, 20, 24)]);
        let o = WindowSpec {
            size: 10,
            stride: 5,
        };
        assert_eq!(
            o.windows(20).unwrap(),
            vec![(0, 0, 9), (1, 5, 14), (2, 10, 19)]
        );
        assert!(WindowSpec { size: 0, stride: 1 }.windows(5).is_err());
        assert!(w.windows(0).unwrap().is_empty());
    }
}
