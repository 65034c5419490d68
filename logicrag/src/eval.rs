//! Batch evaluation: questions with expected answers → translation →
//! reasoning on the question's window → scores per category, confusion
//! matrix and the trivial baselines; and [`Skill`], the answers'
//! probabilities read as forecasts of "yes" and scored against the
//! base-rate predictor (Brier skill score, reliability table), per
//! category and without the presence questions (U1).

use crate::ask::{AskOptions, Outcome};
use crate::kb::KbError;
use crate::metrics::{Evaluation, Scores};
use crate::pipeline::Pipeline;
use crate::questions::Question;
use crate::source::SourceError;
use crate::translate::csv::{CsvError, parse_csv};
use serde::Serialize;
use std::collections::BTreeMap;

/// Errors of an evaluation.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    /// Occurs when the questions CSV cannot be parsed.
    #[error("{file}: {source}")]
    Csv {
        /// The file.
        file: String,
        /// The CSV error.
        #[source]
        source: CsvError,
    },
    /// Occurs when a row lacks a column or has an unreadable answer.
    #[error("{file}:{line}: {message}")]
    Row {
        /// The file.
        file: String,
        /// 1-based line of the row.
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Occurs when a question names a window the source does not have.
    #[error("{file}: question {number}: {window}")]
    UnknownWindow {
        /// The file (or question set).
        file: String,
        /// 1-based position of the question in the set.
        number: usize,
        /// The window asked for, and the source's.
        window: crate::kb::NoWindow,
    },
    /// Occurs when a window's KB cannot be built.
    #[error(transparent)]
    Kb(#[from] KbError),
    /// Occurs when the source cannot be loaded.
    #[error(transparent)]
    Source(#[from] SourceError),
    /// Occurs when a built-in question set is asked of a source that has
    /// none (only `sim:` sources do).
    #[error("{source_spec} has no built-in question set; give a questions CSV")]
    NoQuestionSet {
        /// The source as written.
        source_spec: String,
    },
}

/// The built-in question set of a simulator source (`sim:NAME[@SEED]` or
/// a scenario file), generated from the run's ground truth: the pipeline
/// must be opened with [`crate::pipeline::OpenOptions::keep_scene`]. The
/// questions are asked of the windows of exactly this run (its seed and
/// noise).
pub fn scenario_questions(pipeline: &Pipeline) -> Result<Vec<Question>, EvalError> {
    let extras = pipeline.extras();
    let Some(run) = extras.sim.as_ref() else {
        return Err(EvalError::NoQuestionSet {
            source_spec: pipeline.label().to_string(),
        });
    };
    // The windows just loaded, not a second run of perception over them.
    let windows: Vec<perception::WindowFacts> = pipeline
        .windows()
        .iter()
        .map(|w| perception::WindowFacts {
            index: w.index,
            first_frame: w.first_frame,
            last_frame: w.last_frame,
            facts: w.facts.to_vec(),
            doubts: w.doubts.clone(),
        })
        .collect();
    Ok(crate::questions::generate(run, &windows, &extras.config))
}

/// One scored question.
#[derive(Debug, Clone, Serialize)]
pub struct Record {
    /// Window id.
    pub window: String,
    /// The question.
    pub question: String,
    /// Its translation, or the translator's error.
    pub query: Result<String, String>,
    /// Expected answer.
    pub expected: bool,
    /// What the system said.
    pub said: Outcome,
    /// Category (may be empty).
    pub category: String,
    /// Whether `said` matches `expected`.
    pub correct: bool,
    /// The probability, as stated with the answer, that `said` is right
    /// (`None` for unknown and invalid).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub probability: Option<f64>,
}

/// The result of an evaluation.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Source label.
    pub source: String,
    /// Every question.
    pub records: Vec<Record>,
    /// Overall scores.
    pub overall: Scores,
    /// Scores per category.
    pub by_category: BTreeMap<String, Scores>,
    /// How well the answers' probabilities match their accuracy.
    #[serde(serialize_with = "calibration_json")]
    pub calibration: crate::metrics::Calibration,
    /// The answers as forecasts of "yes" against the base rate, overall,
    /// per category and without U1.
    #[serde(serialize_with = "skill_json")]
    pub skill: Skill,
    /// Counts.
    #[serde(skip)]
    pub evaluation: Evaluation,
}

/// Reads a questions CSV: `Question`, `Answer` (yes/no/1/0/true/false),
/// and optional `Window` and `Category` columns. Without a `Window`
/// column every question applies to `default_window`.
pub fn read_questions(
    text: &str,
    file: &str,
    default_window: Option<&str>,
) -> Result<Vec<Question>, EvalError> {
    let rows = parse_csv(text).map_err(|source| EvalError::Csv {
        file: file.into(),
        source,
    })?;
    let Some(header) = rows.first() else {
        return Err(EvalError::Row {
            file: file.into(),
            line: 1,
            message: "empty file; expected a header with Question and Answer".into(),
        });
    };
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h.trim().eq_ignore_ascii_case(name))
    };
    let q_col = col("Question").ok_or_else(|| EvalError::Row {
        file: file.into(),
        line: 1,
        message: "no `Question` column".into(),
    })?;
    let a_col = col("Answer")
        .or_else(|| col("Human"))
        .ok_or_else(|| EvalError::Row {
            file: file.into(),
            line: 1,
            message: "no `Answer` (or `Human`) column".into(),
        })?;
    let w_col = col("Window");
    let c_col = col("Category");
    let mut out = Vec::new();
    for (i, row) in rows.iter().enumerate().skip(1) {
        let line = i + 1;
        if row.iter().all(|f| f.trim().is_empty()) {
            continue;
        }
        let get = |c: usize| row.get(c).map(|s| s.trim().to_string()).unwrap_or_default();
        let answer = match get(a_col).to_ascii_lowercase().as_str() {
            "yes" | "1" | "true" | "y" => true,
            "no" | "0" | "false" | "n" => false,
            other => {
                return Err(EvalError::Row {
                    file: file.into(),
                    line,
                    message: format!("answer `{other}` is not yes/no/1/0"),
                });
            }
        };
        let window = match (w_col.map(get), default_window) {
            (Some(w), _) if !w.is_empty() => w,
            (_, Some(d)) => d.to_string(),
            _ => {
                return Err(EvalError::Row {
                    file: file.into(),
                    line,
                    message: "no window given: add a `Window` column or choose one with --frames"
                        .into(),
                });
            }
        };
        out.push(Question {
            window,
            question: get(q_col),
            answer,
            category: c_col.map(get).unwrap_or_default(),
        });
    }
    Ok(out)
}

/// Evaluates questions on a pipeline's windows; each window is reasoned once.
pub fn evaluate(
    pipeline: Pipeline,
    questions: &[Question],
    file: &str,
) -> Result<Report, EvalError> {
    evaluate_with_progress(pipeline, questions, file, &|_| {})
}

/// [`evaluate`], calling `progress(n)` each time a window's `n` questions
/// are answered.
///
/// Windows are reasoned in parallel, so `progress` is called from worker
/// threads, in no particular order; the sum of its arguments reaches
/// `questions.len()` when evaluation succeeds.
pub fn evaluate_with_progress(
    pipeline: Pipeline,
    questions: &[Question],
    file: &str,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<Report, EvalError> {
    // Each distinct question is translated and checked once, whatever the
    // number of windows.
    let mut prepared: std::collections::HashMap<&str, _> = std::collections::HashMap::new();
    for q in questions {
        prepared
            .entry(q.question.as_str())
            .or_insert_with(|| pipeline.prepare(&q.question));
    }
    let label = pipeline.label().to_string();
    let opts = AskOptions::BINDINGS;
    let mut records = Vec::with_capacity(questions.len());
    pipeline.answer_each_in_order(
        questions.len(),
        |i| questions[i].window.clone(),
        |i, window| EvalError::UnknownWindow {
            file: file.into(),
            number: i + 1,
            window,
        },
        |engine, kb, i| {
            let q = &questions[i];
            let (query, said, probability) = match prepared.get(q.question.as_str()) {
                Some(Ok(p)) => {
                    let r = engine.ask(kb, p, opts);
                    (Ok(p.query.clone()), r.answer, r.probability)
                }
                Some(Err(e)) => (Err(e.reason()), Outcome::Invalid, None),
                None => (Err("not prepared".to_string()), Outcome::Invalid, None),
            };
            let correct = matches!(
                (said, q.answer),
                (Outcome::Yes, true) | (Outcome::No, false)
            );
            Record {
                window: q.window.clone(),
                question: q.question.clone(),
                query,
                expected: q.answer,
                said,
                category: q.category.clone(),
                correct,
                probability,
            }
        },
        progress,
        &mut |_, r| records.push(r),
    )?;
    let mut evaluation = Evaluation::default();
    let mut calibration = crate::metrics::Calibration::default();
    let mut skill = Skill::default();
    for r in &records {
        evaluation.add(&r.category, r.expected, r.said);
        if let Some(p) = r.probability {
            calibration.add(p, r.correct);
        }
        skill.add(r);
    }
    let by_category = evaluation
        .by_category
        .iter()
        .map(|(k, c)| (k.clone(), c.scores()))
        .collect();
    Ok(Report {
        source: label,
        overall: evaluation.overall.scores(),
        by_category,
        records,
        calibration,
        skill,
        evaluation,
    })
}

fn calibration_json<S: serde::Serializer>(
    c: &crate::metrics::Calibration,
    s: S,
) -> Result<S::Ok, S::Error> {
    serde::Serialize::serialize(&c.to_json(), s)
}

fn skill_json<S: serde::Serializer>(k: &Skill, s: S) -> Result<S::Ok, S::Error> {
    serde::Serialize::serialize(&k.to_json(), s)
}

/// A wrong answer stated with at least this probability of being right is
/// counted as confidently wrong ([`Forecasts::confident_wrong`]).
pub const CONFIDENT_P: f64 = 0.99;

/// The category of the presence questions ("Is there a red car?"), nearly
/// always right at every noise level; [`Skill::without_presence`] leaves
/// it out so that it cannot hide the harder questions.
pub const PRESENCE_CATEGORY: &str = "U1";

/// One bin of a reliability table: the answers whose forecast P(yes) falls
/// in `[from, to)` (the last bin includes 1).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct ReliabilityBin {
    /// Lower edge of the bin.
    pub from: f64,
    /// Upper edge of the bin.
    pub to: f64,
    /// Answers in the bin.
    pub n: usize,
    /// Their mean forecast P(yes).
    pub mean_p_yes: f64,
    /// The share of them whose expected answer is yes.
    pub frequency_yes: f64,
}

/// A set of answers read as forecasts "yes with P(yes)" — a yes said with
/// probability `p` forecasts `p`, a no said with `p` forecasts `1 − p` —
/// and scored against the base-rate predictor, which forecasts every
/// question of the set with the set's frequency of yes.
///
/// Invariants: `scored ≤ questions`, `correct ≤ questions`,
/// `scored_yes ≤ scored`, and the bins' counts sum to `scored`. Unknown
/// and invalid answers state no probability: they count in `questions`
/// (and against accuracy) but not in the Brier scores, whose base rate is
/// taken over the same `scored` answers so that both are compared on the
/// same questions.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Forecasts {
    /// Questions asked.
    pub questions: usize,
    /// Questions answered right.
    pub correct: usize,
    /// Answers that state a probability (yes and no).
    pub scored: usize,
    /// Of those, the questions whose expected answer is yes.
    pub scored_yes: usize,
    /// Of those, the answers that are right.
    pub scored_correct: usize,
    /// Wrong answers stated with probability at least [`CONFIDENT_P`].
    pub confident_wrong: usize,
    /// Sum of `(P(yes) − truth)²` over the scored answers.
    squared_error: f64,
    /// Per tenth of P(yes): answers, sum of P(yes), expected yes.
    bins: [(usize, f64, usize); Forecasts::BINS],
}

impl Forecasts {
    /// Equal-width bins of the reliability table.
    pub const BINS: usize = 10;

    /// Records one answer: what was expected, what was said and the stated
    /// probability that it is right.
    pub fn add(&mut self, expected: bool, said: Outcome, probability: Option<f64>) {
        self.questions += 1;
        let correct = matches!(
            (said, expected),
            (Outcome::Yes, true) | (Outcome::No, false)
        );
        self.correct += usize::from(correct);
        let p_yes = match (said, probability) {
            (Outcome::Yes, Some(p)) => p,
            (Outcome::No, Some(p)) => 1.0 - p,
            _ => return,
        };
        let p_yes = p_yes.clamp(0.0, 1.0);
        if !correct && probability.is_some_and(|p| p >= CONFIDENT_P) {
            self.confident_wrong += 1;
        }
        let y = if expected { 1.0 } else { 0.0 };
        self.scored += 1;
        self.scored_yes += usize::from(expected);
        self.scored_correct += usize::from(correct);
        self.squared_error += (p_yes - y) * (p_yes - y);
        let i = ((p_yes * Self::BINS as f64) as usize).min(Self::BINS - 1);
        let b = &mut self.bins[i];
        b.0 += 1;
        b.1 += p_yes;
        b.2 += usize::from(expected);
    }

    /// Adds another set of answers.
    pub fn merge(&mut self, other: &Forecasts) {
        self.questions += other.questions;
        self.correct += other.correct;
        self.scored += other.scored;
        self.scored_yes += other.scored_yes;
        self.scored_correct += other.scored_correct;
        self.confident_wrong += other.confident_wrong;
        self.squared_error += other.squared_error;
        for (a, b) in self.bins.iter_mut().zip(&other.bins) {
            a.0 += b.0;
            a.1 += b.1;
            a.2 += b.2;
        }
    }

    /// Share of the questions answered right. `None` with no questions.
    pub fn accuracy(&self) -> Option<f64> {
        (self.questions > 0).then(|| self.correct as f64 / self.questions as f64)
    }

    /// Brier score of the forecasts, the mean of `(P(yes) − truth)²`.
    /// `None` with no scored answer.
    pub fn brier(&self) -> Option<f64> {
        (self.scored > 0).then(|| self.squared_error / self.scored as f64)
    }

    /// The set's frequency of yes, the base-rate predictor's forecast.
    pub fn base_rate(&self) -> Option<f64> {
        (self.scored > 0).then(|| self.scored_yes as f64 / self.scored as f64)
    }

    /// Brier score of the base-rate predictor: with frequency `f` of yes,
    /// `f·(1 − f)² + (1 − f)·f² = f·(1 − f)`.
    pub fn base_brier(&self) -> Option<f64> {
        self.base_rate().map(|f| f * (1.0 - f))
    }

    /// Brier skill score, `1 − Brier / Brier_base`: 1 is perfect, 0 no
    /// better than the base rate, negative worse. `None` with no scored
    /// answer or when every question has the same answer (the base rate
    /// is then perfect and there is no skill to measure).
    pub fn skill(&self) -> Option<f64> {
        match (self.brier(), self.base_brier()) {
            (Some(b), Some(base)) if base > 0.0 => Some(1.0 - b / base),
            _ => None,
        }
    }

    /// Brier score of a second reference, the constant-confidence
    /// predictor: the same answers, each stated with the set's accuracy
    /// `a` as its probability of being right, scores `a·(1 − a)`. Beating
    /// it takes probabilities that tell right answers from wrong ones,
    /// which the base rate of yes (far easier to beat when the answers
    /// are mostly right) does not measure.
    pub fn constant_confidence_brier(&self) -> Option<f64> {
        (self.scored > 0).then(|| {
            let a = self.scored_correct as f64 / self.scored as f64;
            a * (1.0 - a)
        })
    }

    /// `1 − Brier / Brier_const` against
    /// [`Forecasts::constant_confidence_brier`]; `None` as for
    /// [`Forecasts::skill`] (every answer right, or every one wrong).
    pub fn confidence_skill(&self) -> Option<f64> {
        match (self.brier(), self.constant_confidence_brier()) {
            (Some(b), Some(base)) if base > 0.0 => Some(1.0 - b / base),
            _ => None,
        }
    }

    /// The reliability table: the non-empty bins, in order of P(yes).
    pub fn reliability(&self) -> Vec<ReliabilityBin> {
        self.bins
            .iter()
            .enumerate()
            .filter(|(_, b)| b.0 > 0)
            .map(|(i, &(n, sum, yes))| ReliabilityBin {
                from: i as f64 / Self::BINS as f64,
                to: (i + 1) as f64 / Self::BINS as f64,
                n,
                mean_p_yes: sum / n as f64,
                frequency_yes: yes as f64 / n as f64,
            })
            .collect()
    }

    /// The figures as JSON: `questions`, `correct`, `accuracy`, `scored`,
    /// `brier`, `base_rate`, `base_brier`, `skill`,
    /// `constant_confidence_brier`, `confidence_skill`, `confident_wrong`
    /// and `reliability` (the non-empty bins).
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "questions": self.questions,
            "correct": self.correct,
            "accuracy": self.accuracy(),
            "scored": self.scored,
            "brier": self.brier(),
            "base_rate": self.base_rate(),
            "base_brier": self.base_brier(),
            "skill": self.skill(),
            "constant_confidence_brier": self.constant_confidence_brier(),
            "confidence_skill": self.confidence_skill(),
            "confident_wrong": self.confident_wrong,
            "reliability": self.reliability(),
        })
    }
}

/// [`Forecasts`] of a question set, overall, per category (each against
/// its own base rate) and without the presence questions.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Skill {
    /// Every question.
    pub overall: Forecasts,
    /// Every question but those of [`PRESENCE_CATEGORY`].
    pub without_presence: Forecasts,
    /// Per category (the empty string for questions without one).
    pub by_category: BTreeMap<String, Forecasts>,
}

impl Skill {
    /// Records one scored question.
    pub fn add(&mut self, r: &Record) {
        self.add_answer(&r.category, r.expected, r.said, r.probability);
    }

    /// Records one answer of `category`.
    pub fn add_answer(
        &mut self,
        category: &str,
        expected: bool,
        said: Outcome,
        probability: Option<f64>,
    ) {
        self.overall.add(expected, said, probability);
        if category != PRESENCE_CATEGORY {
            self.without_presence.add(expected, said, probability);
        }
        self.by_category
            .entry(category.to_string())
            .or_default()
            .add(expected, said, probability);
    }

    /// Adds another question set.
    pub fn merge(&mut self, other: &Skill) {
        self.overall.merge(&other.overall);
        self.without_presence.merge(&other.without_presence);
        for (k, f) in &other.by_category {
            self.by_category.entry(k.clone()).or_default().merge(f);
        }
    }

    /// As JSON: `overall`, `without_u1` and `by_category`, each as
    /// [`Forecasts::to_json`] writes it.
    pub fn to_json(&self) -> serde_json::Value {
        serde_json::json!({
            "overall": self.overall.to_json(),
            "without_u1": self.without_presence.to_json(),
            "by_category": self
                .by_category
                .iter()
                .map(|(k, f)| (k.clone(), f.to_json()))
                .collect::<serde_json::Map<_, _>>(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn facts_of(seed: u64) -> Vec<String> {
        let spec = crate::source::SourceSpec::Sim {
            scenario: "braking".into(),
            seed,
        };
        let options = crate::pipeline::OpenOptions {
            source: crate::session::SourceOptions {
                noise: Some(perception::sim::NoisePreset::High.into()),
                ..Default::default()
            },
            keep_scene: true,
            ..Default::default()
        };
        let pipeline = Pipeline::open(spec, &options, &mut |_| {}).unwrap();
        let questions = scenario_questions(&pipeline).unwrap();
        assert!(!questions.is_empty());
        pipeline
            .windows()
            .iter()
            .flat_map(|w| w.facts.iter().map(|f| f.to_string()))
            .collect()
    }

    /// Regression (issue 22): `eval --source sim:FILE@SEED` evaluated seed 0
    /// whatever the seed; the built-in question set now comes from the run
    /// of the seed asked for.
    #[test]
    fn the_built_in_question_set_is_asked_of_the_seed_given() {
        assert_eq!(facts_of(3), facts_of(3));
        assert_ne!(facts_of(3), facts_of(4));
    }

    #[test]
    fn only_simulator_sources_have_a_built_in_question_set() {
        let options = crate::pipeline::OpenOptions {
            keep_scene: true,
            ..Default::default()
        };
        let dir = std::env::temp_dir().join(format!("logicrag-eval-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("w0.facts");
        std::fs::write(&file, "Vehicles(car_1).\n").unwrap();
        let spec = format!("facts:{}", file.display()).parse().unwrap();
        let pipeline = Pipeline::open(spec, &options, &mut |_| {}).unwrap();
        let e = scenario_questions(&pipeline).unwrap_err();
        let _ = std::fs::remove_dir_all(&dir);
        assert!(matches!(e, EvalError::NoQuestionSet { .. }), "{e}");
    }

    /// Hand-computed: four answers, three expected yes (base rate 0.75,
    /// base Brier 0.75 · 0.25 = 0.1875).
    /// - yes said with 0.9, expected yes: P(yes) 0.9, error 0.01
    /// - no said with 0.75, expected no:  P(yes) 0.25, error 0.0625
    /// - no said with 0.7, expected yes:  P(yes) 0.3, error 0.49
    /// - yes said with 1.0, expected yes: P(yes) 1.0, error 0
    ///
    /// Brier 0.5625 / 4 = 0.140625, skill 1 − 0.140625 / 0.1875 = 0.25.
    #[test]
    fn the_brier_skill_score_and_reliability_bins_of_a_hand_computed_set() {
        let mut f = Forecasts::default();
        f.add(true, Outcome::Yes, Some(0.9));
        f.add(false, Outcome::No, Some(0.75));
        f.add(true, Outcome::No, Some(0.7));
        f.add(true, Outcome::Yes, Some(1.0));
        let close = |a: Option<f64>, b: f64| a.is_some_and(|a| (a - b).abs() < 1e-12);
        assert!(close(f.brier(), 0.140625), "{:?}", f.brier());
        assert!(close(f.base_rate(), 0.75));
        assert!(close(f.base_brier(), 0.1875));
        assert!(close(f.skill(), 0.25), "{:?}", f.skill());
        assert!(close(f.accuracy(), 0.75));
        assert_eq!(f.confident_wrong, 0);
        // Three of four right: the constant-confidence predictor states
        // 0.75 on each, Brier 0.75 · 0.25 = 0.1875, the same as the base
        // rate here (three yes of four) by coincidence of the counts.
        assert!(close(f.constant_confidence_brier(), 0.1875));
        assert!(close(f.confidence_skill(), 0.25));
        let bins = f.reliability();
        let rows: Vec<(f64, usize, f64)> = bins
            .iter()
            .map(|b| (b.from, b.n, b.frequency_yes))
            .collect();
        assert_eq!(rows, [(0.2, 1, 0.0), (0.3, 1, 1.0), (0.9, 2, 1.0)]);
        assert!((bins[2].mean_p_yes - 0.95).abs() < 1e-12);
        assert!((bins[2].to - 1.0).abs() < 1e-12);
        // A confident wrong answer, and answers without a probability:
        // they count against accuracy, not in the Brier score.
        f.add(false, Outcome::Yes, Some(0.995));
        f.add(true, Outcome::Unknown, None);
        assert_eq!((f.questions, f.scored, f.confident_wrong), (6, 5, 1));
        assert!(close(f.accuracy(), 3.0 / 6.0));
        // The scores follow the scored answers: 3 yes of 5 and 3 right of
        // 5; the wrong yes at 0.995 adds (0.995 − 0)² = 0.990025.
        assert!(close(f.base_rate(), 0.6));
        assert!(close(f.brier(), (0.5625 + 0.990025) / 5.0));
        assert!(close(f.constant_confidence_brier(), 0.24));
        let mut g = Forecasts::default();
        g.merge(&f);
        g.merge(&f);
        assert_eq!(g.scored, 10);
        assert!(close(g.brier(), f.brier().unwrap()));
        assert!(close(g.skill(), f.skill().unwrap()));
        // The two references part when accuracy and the rate of yes do:
        // two yes of four (base 0.25), three right of four (0.1875).
        let mut h = Forecasts::default();
        h.add(true, Outcome::Yes, Some(0.9));
        h.add(true, Outcome::Yes, Some(0.9));
        h.add(false, Outcome::Yes, Some(0.9));
        h.add(false, Outcome::No, Some(0.9));
        // Errors 0.01, 0.01, 0.81, 0.01: Brier 0.21.
        assert!(close(h.brier(), 0.21));
        assert!(close(h.base_brier(), 0.25));
        assert!(close(h.skill(), 1.0 - 0.21 / 0.25));
        assert!(close(h.constant_confidence_brier(), 0.1875));
        assert!(close(h.confidence_skill(), 1.0 - 0.21 / 0.1875));
        // One answer for every question: no skill to measure.
        let mut same = Forecasts::default();
        same.add(true, Outcome::Yes, Some(0.6));
        assert_eq!(same.skill(), None);
        assert_eq!(Forecasts::default().brier(), None);
    }

    #[test]
    fn skill_is_kept_per_category_and_without_presence_questions() {
        let mut k = Skill::default();
        k.add_answer("U1", true, Outcome::Yes, Some(1.0));
        k.add_answer("U1", false, Outcome::No, Some(1.0));
        k.add_answer("U2", true, Outcome::Yes, Some(0.6));
        k.add_answer("U2", false, Outcome::Yes, Some(0.6));
        assert_eq!(k.overall.questions, 4);
        assert_eq!(k.without_presence.questions, 2);
        assert_eq!(k.by_category["U1"].skill(), Some(1.0));
        // U2: P(yes) 0.6 for both; Brier (0.16 + 0.36) / 2 = 0.26 against
        // a base rate of 0.5 (0.25): worse than the base rate.
        let u2 = k.by_category["U2"].skill().unwrap();
        assert!((u2 - (1.0 - 0.26 / 0.25)).abs() < 1e-12, "{u2}");
        assert_eq!(k.without_presence, k.by_category["U2"]);
        let v = k.to_json();
        assert_eq!(v["without_u1"]["questions"], 2);
        assert_eq!(v["by_category"]["U1"]["confident_wrong"], 0);
        assert!(v["overall"]["reliability"].is_array());
    }
}
