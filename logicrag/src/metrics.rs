//! Binary question-answering metrics as the paper reports them (accuracy,
//! F1), plus balanced accuracy, per-category breakdowns, a confusion matrix
//! and the always-yes / always-no baselines that show whether a score means
//! anything on a skewed question set.

use crate::ask::Outcome;
use serde::Serialize;
use std::collections::BTreeMap;

/// Counts of (truth, said) pairs. Invariant: every field is a count of
/// scored questions; `total()` is their sum.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Confusion {
    /// Truth yes: how often each outcome was said (yes, no, unknown, invalid).
    pub truth_yes: [usize; 4],
    /// Truth no: how often each outcome was said.
    pub truth_no: [usize; 4],
}

fn idx(s: Outcome) -> usize {
    match s {
        Outcome::Yes => 0,
        Outcome::No => 1,
        Outcome::Unknown => 2,
        Outcome::Invalid => 3,
    }
}

impl Confusion {
    /// Records one scored question.
    pub fn add(&mut self, truth: bool, said: Outcome) {
        if truth {
            self.truth_yes[idx(said)] += 1;
        } else {
            self.truth_no[idx(said)] += 1;
        }
    }
    /// Number of scored questions.
    pub fn total(&self) -> usize {
        self.truth_yes.iter().sum::<usize>() + self.truth_no.iter().sum::<usize>()
    }
    /// The scores of these counts.
    pub fn scores(&self) -> Scores {
        let tp = self.truth_yes[0] as f64;
        let fneg = (self.truth_yes[1] + self.truth_yes[2] + self.truth_yes[3]) as f64;
        let tn = self.truth_no[1] as f64;
        let fp = self.truth_no[0] as f64;
        let pos = self.truth_yes.iter().sum::<usize>() as f64;
        let neg = self.truth_no.iter().sum::<usize>() as f64;
        let n = pos + neg;
        let ratio = |a: f64, b: f64| if b > 0.0 { a / b } else { 0.0 };
        let precision = ratio(tp, tp + fp);
        let recall = ratio(tp, tp + fneg);
        let f1 = ratio(2.0 * precision * recall, precision + recall);
        // Balanced accuracy averages the recall of each class that occurs;
        // with one class only it is that class's recall.
        let tpr = ratio(tp, pos);
        let tnr = ratio(tn, neg);
        let balanced_accuracy = match (pos > 0.0, neg > 0.0) {
            (true, true) => (tpr + tnr) / 2.0,
            (true, false) => tpr,
            (false, true) => tnr,
            (false, false) => 0.0,
        };
        Scores {
            n: self.total(),
            accuracy: ratio(tp + tn, n),
            balanced_accuracy,
            precision,
            recall,
            f1,
            always_yes_accuracy: ratio(pos, n),
            always_no_accuracy: ratio(neg, n),
            always_yes_f1: ratio(2.0 * pos, 2.0 * pos + neg),
        }
    }
}

/// Scores of a set of answers; yes is the positive class.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct Scores {
    /// Scored questions.
    pub n: usize,
    /// Fraction answered correctly (unknown/invalid count as wrong).
    pub accuracy: f64,
    /// Mean of the yes-recall and the no-recall.
    pub balanced_accuracy: f64,
    /// Of the yes answers, the fraction whose truth is yes.
    pub precision: f64,
    /// Of the truth-yes questions, the fraction answered yes.
    pub recall: f64,
    /// Harmonic mean of precision and recall.
    pub f1: f64,
    /// Accuracy of answering yes to everything.
    pub always_yes_accuracy: f64,
    /// Accuracy of answering no to everything.
    pub always_no_accuracy: f64,
    /// F1 of answering yes to everything.
    pub always_yes_f1: f64,
}

/// One column of the paper's table — the logic alone (`LR`) or the model
/// under a condition (`C1`–`C3`) — with its scores overall and per
/// category, as `eval --report` writes it and `plot eval` reads it.
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct ScoreColumn {
    /// `LR`, `C1`, `C2`, `C3`.
    pub name: String,
    /// Scores over every question.
    pub overall: Scores,
    /// Scores per category.
    pub by_category: BTreeMap<String, Scores>,
}

impl ScoreColumn {
    /// A column from an evaluation's confusion counts.
    pub fn from_evaluation(name: &str, e: &Evaluation) -> ScoreColumn {
        ScoreColumn {
            name: name.to_string(),
            overall: e.overall.scores(),
            by_category: e
                .by_category
                .iter()
                .map(|(k, c)| (k.clone(), c.scores()))
                .collect(),
        }
    }
}

/// Overall and per-category confusion counts.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Evaluation {
    /// Every scored question.
    pub overall: Confusion,
    /// Per category (e.g. U1..U4, B1, B2); questions without one are under "".
    pub by_category: BTreeMap<String, Confusion>,
}

impl Evaluation {
    /// Records one question.
    pub fn add(&mut self, category: &str, truth: bool, said: Outcome) {
        self.overall.add(truth, said);
        self.by_category
            .entry(category.to_string())
            .or_default()
            .add(truth, said);
    }

    /// A fixed-width score table: one row per category, then the total.
    pub fn table(&self) -> String {
        let mut s = String::new();
        s.push_str(&format!(
            "{:<10} {:>5} {:>6} {:>7} {:>6} {:>6} {:>6} {:>8} {:>8}\n",
            "category", "n", "acc", "bal.acc", "prec", "recall", "F1", "all-yes", "all-no"
        ));
        let mut row = |name: &str, c: &Confusion| {
            let sc = c.scores();
            s.push_str(&format!(
                "{:<10} {:>5} {:>6.2} {:>7.2} {:>6.2} {:>6.2} {:>6.2} {:>8.2} {:>8.2}\n",
                name,
                sc.n,
                sc.accuracy,
                sc.balanced_accuracy,
                sc.precision,
                sc.recall,
                sc.f1,
                sc.always_yes_accuracy,
                sc.always_no_accuracy
            ));
        };
        for (cat, c) in &self.by_category {
            if !cat.is_empty() {
                row(cat, c);
            }
        }
        if let Some(c) = self.by_category.get("") {
            row("(none)", c);
        }
        row("all", &self.overall);
        s
    }

    /// The overall confusion matrix as text.
    pub fn confusion_table(&self) -> String {
        let c = &self.overall;
        let mut s = format!(
            "{:<10} {:>6} {:>6} {:>8} {:>8}\n",
            "truth\\said", "yes", "no", "unknown", "invalid"
        );
        for (name, row) in [("yes", &c.truth_yes), ("no", &c.truth_no)] {
            s.push_str(&format!(
                "{:<10} {:>6} {:>6} {:>8} {:>8}\n",
                name, row[0], row[1], row[2], row[3]
            ));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scores_of_a_known_confusion() {
        let mut c = Confusion::default();
        // 3 truth-yes: 2 yes, 1 unknown; 2 truth-no: 1 no, 1 yes.
        for (t, s) in [
            (true, Outcome::Yes),
            (true, Outcome::Yes),
            (true, Outcome::Unknown),
            (false, Outcome::No),
            (false, Outcome::Yes),
        ] {
            c.add(t, s);
        }
        let sc = c.scores();
        assert_eq!(sc.n, 5);
        assert!((sc.accuracy - 3.0 / 5.0).abs() < 1e-12);
        assert!((sc.precision - 2.0 / 3.0).abs() < 1e-12);
        assert!((sc.recall - 2.0 / 3.0).abs() < 1e-12);
        assert!((sc.balanced_accuracy - (2.0 / 3.0 + 0.5) / 2.0).abs() < 1e-12);
        assert!((sc.always_yes_accuracy - 0.6).abs() < 1e-12);
        assert!((sc.always_no_accuracy - 0.4).abs() < 1e-12);
    }

    #[test]
    fn perfect_answers_score_one_everywhere() {
        let mut e = Evaluation::default();
        e.add("U1", true, Outcome::Yes);
        e.add("U1", false, Outcome::No);
        e.add("B2", false, Outcome::No);
        let sc = e.overall.scores();
        assert_eq!((sc.accuracy, sc.balanced_accuracy, sc.f1), (1.0, 1.0, 1.0));
        assert_eq!(e.by_category["B2"].scores().accuracy, 1.0);
        let t = e.table();
        assert!(
            t.contains("U1") && t.contains("B2") && t.lines().last().unwrap().starts_with("all")
        );
        assert!(e.confusion_table().contains("truth\\said"));
    }

    #[test]
    fn empty_is_zero_not_nan() {
        let sc = Confusion::default().scores();
        assert_eq!(sc.accuracy, 0.0);
        assert!(!sc.f1.is_nan());
    }
}

/// How well the answers' probabilities match how often they are right:
/// the Brier score and the expected calibration error over equal-width
/// bins of the stated probability.
///
/// Invariant: `n` is the number of answers added; `bins[i]` holds the
/// answers whose probability lies in `[i, i + 1) / BINS` (1 in the last),
/// as (count, sum of probabilities, number right).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Calibration {
    /// Answers with a probability (yes and no; unknown and invalid state
    /// none and are not counted).
    pub n: usize,
    /// Sum of the squared errors `(p − right)²`.
    squared_error: f64,
    /// Per bin: answers, sum of their probabilities, answers right.
    bins: Vec<(usize, f64, usize)>,
}

impl Calibration {
    /// Bins of the expected calibration error (the usual ten).
    pub const BINS: usize = 10;

    /// Records an answer said with probability `p` of being right, and
    /// whether it was. For a yes/no question this is the Brier score of
    /// the forecast "yes with P(yes)": `(P(yes) − truth)² = (p − right)²`.
    pub fn add(&mut self, p: f64, right: bool) {
        let p = p.clamp(0.0, 1.0);
        if self.bins.is_empty() {
            self.bins = vec![(0, 0.0, 0); Self::BINS];
        }
        let y = if right { 1.0 } else { 0.0 };
        self.n += 1;
        self.squared_error += (p - y) * (p - y);
        let i = ((p * Self::BINS as f64) as usize).min(Self::BINS - 1);
        let b = &mut self.bins[i];
        b.0 += 1;
        b.1 += p;
        b.2 += usize::from(right);
    }

    /// Adds another set of answers.
    pub fn merge(&mut self, other: &Calibration) {
        if other.n == 0 {
            return;
        }
        if self.bins.is_empty() {
            self.bins = vec![(0, 0.0, 0); Self::BINS];
        }
        self.n += other.n;
        self.squared_error += other.squared_error;
        for (a, b) in self.bins.iter_mut().zip(&other.bins) {
            a.0 += b.0;
            a.1 += b.1;
            a.2 += b.2;
        }
    }

    /// Mean squared error of the probabilities (0 is perfect; always
    /// saying 0.5 scores 0.25). `None` with no answers.
    pub fn brier(&self) -> Option<f64> {
        (self.n > 0).then(|| self.squared_error / self.n as f64)
    }

    /// Expected calibration error: over the bins, the answers' share times
    /// the gap between the bin's mean probability and its accuracy.
    pub fn ece(&self) -> Option<f64> {
        (self.n > 0).then(|| {
            self.bins
                .iter()
                .filter(|b| b.0 > 0)
                .map(|&(k, sum, right)| {
                    let k = k as f64;
                    (k / self.n as f64) * (sum / k - right as f64 / k).abs()
                })
                .sum()
        })
    }

    /// Mean stated probability. `None` with no answers.
    pub fn mean_probability(&self) -> Option<f64> {
        (self.n > 0).then(|| self.bins.iter().map(|b| b.1).sum::<f64>() / self.n as f64)
    }

    /// The figures as JSON: `n`, `brier`, `ece`, `mean_probability`, and
    /// per non-empty bin its range, answers, mean probability and accuracy.
    pub fn to_json(&self) -> serde_json::Value {
        let bins: Vec<serde_json::Value> = self
            .bins
            .iter()
            .enumerate()
            .filter(|(_, b)| b.0 > 0)
            .map(|(i, &(k, sum, right))| {
                serde_json::json!({
                    "from": i as f64 / Self::BINS as f64,
                    "to": (i + 1) as f64 / Self::BINS as f64,
                    "n": k,
                    "mean_probability": sum / k as f64,
                    "accuracy": right as f64 / k as f64,
                })
            })
            .collect();
        serde_json::json!({
            "n": self.n,
            "brier": self.brier(),
            "ece": self.ece(),
            "mean_probability": self.mean_probability(),
            "bins": bins,
        })
    }
}

#[cfg(test)]
mod calibration_tests {
    use super::Calibration;

    #[test]
    fn a_certain_right_answer_is_perfect_and_a_certain_wrong_one_the_worst() {
        let mut c = Calibration::default();
        c.add(1.0, true);
        assert_eq!(c.brier(), Some(0.0));
        assert_eq!(c.ece(), Some(0.0));
        c.add(1.0, false);
        assert_eq!(c.brier(), Some(0.5));
        assert_eq!(c.ece(), Some(0.5));
    }

    #[test]
    fn seventy_percent_right_at_point_seven_is_calibrated() {
        let mut c = Calibration::default();
        for i in 0..10 {
            c.add(0.7, i < 7);
        }
        assert!(c.ece().unwrap() < 1e-12);
        // Brier = 0.7·0.09 + 0.3·0.49 = 0.21.
        assert!((c.brier().unwrap() - 0.21).abs() < 1e-12);
        let mut d = Calibration::default();
        d.merge(&c);
        d.merge(&c);
        assert_eq!(d.n, 20);
        assert!((d.brier().unwrap() - 0.21).abs() < 1e-12);
        assert_eq!(Calibration::default().brier(), None);
    }
}
