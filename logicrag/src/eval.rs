//! Batch evaluation: questions with expected answers → translation →
//! reasoning on the question's window → scores per category, confusion
//! matrix and the trivial baselines.

use crate::ask::{AskOptions, Outcome};
use crate::kb::KbError;
use crate::metrics::{Evaluation, Scores};
use crate::pipeline::Pipeline;
use crate::questions::Question;
use crate::source::{LoadOptions, Loaded, SourceError, SourceSpec, load};
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

/// Loads a simulator source (`sim:NAME[@SEED]` or a scenario file) and
/// generates its built-in question set from the run's ground truth. The
/// seed of `spec` and `opts.noise` are honoured: the questions are asked of
/// the windows of exactly this run.
pub fn scenario_questions(
    spec: &SourceSpec,
    opts: &LoadOptions,
) -> Result<(Loaded, Vec<Question>), EvalError> {
    if !matches!(spec, SourceSpec::Sim { .. }) {
        return Err(EvalError::NoQuestionSet {
            source_spec: spec.to_string(),
        });
    }
    let loaded = load(spec, opts, &mut |_| {})?;
    let Some(run) = loaded.sim.as_ref() else {
        return Err(EvalError::NoQuestionSet {
            source_spec: spec.to_string(),
        });
    };
    // The windows just loaded, not a second run of perception over them.
    let windows: Vec<perception::WindowFacts> = loaded
        .windows
        .iter()
        .map(|w| perception::WindowFacts {
            index: w.index,
            first_frame: w.first_frame,
            last_frame: w.last_frame,
            facts: w.facts.to_vec(),
            doubts: w.doubts.clone(),
        })
        .collect();
    let questions = crate::questions::generate(run, &windows, &opts.config);
    Ok((loaded, questions))
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
    let records = pipeline.answer_each(
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
    )?;
    let mut evaluation = Evaluation::default();
    let mut calibration = crate::metrics::Calibration::default();
    for r in &records {
        evaluation.add(&r.category, r.expected, r.said);
        if let Some(p) = r.probability {
            calibration.add(p, r.correct);
        }
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
        evaluation,
    })
}

fn calibration_json<S: serde::Serializer>(
    c: &crate::metrics::Calibration,
    s: S,
) -> Result<S::Ok, S::Error> {
    serde::Serialize::serialize(&c.to_json(), s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn facts_of(seed: u64) -> Vec<String> {
        let spec = SourceSpec::Sim {
            scenario: "braking".into(),
            seed,
        };
        let opts = LoadOptions {
            noise: Some(perception::sim::NoisePreset::High),
            ..LoadOptions::default()
        };
        let (loaded, questions) = scenario_questions(&spec, &opts).unwrap();
        assert!(!questions.is_empty());
        loaded
            .windows
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
        let spec: SourceSpec = "kitti:/nowhere".parse().unwrap();
        let e = scenario_questions(&spec, &LoadOptions::default()).unwrap_err();
        assert!(matches!(e, EvalError::NoQuestionSet { .. }), "{e}");
    }
}
