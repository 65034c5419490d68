//! The paper's Table II: each question answered by the logic alone (LR)
//! and by an LMM under C1, C2 and C3, scored per category.

use super::client::LlmError;
use super::{Condition, Lmm, Verdict};
use crate::ask::{AskOptions, Outcome};
use crate::eval::EvalError;
use crate::images::FrameImages;
use crate::metrics::Evaluation;
use crate::pipeline::Pipeline;
use crate::questions::Question;
use serde::Serialize;
use std::collections::BTreeMap;

/// One question under one condition, as asked and answered: what a person
/// checks by hand.
#[derive(Debug, Clone, Serialize)]
pub struct LmmRecord {
    /// Window id.
    pub window: String,
    /// The question.
    pub question: String,
    /// Its category.
    pub category: String,
    /// The expected answer.
    pub expected: bool,
    /// The logic's own answer (LR).
    pub logic: Outcome,
    /// The model's answer: condition, prompt, frames, reply, verdict.
    #[serde(flatten)]
    pub answer: super::LmmAnswer,
}

impl LmmRecord {
    /// Whether the model's verdict is the expected answer.
    pub fn correct(&self) -> bool {
        matches!(
            (self.answer.verdict, self.expected),
            (Verdict::Yes, true) | (Verdict::No, false)
        )
    }
}

fn said(v: Verdict) -> Outcome {
    match v {
        Verdict::Yes => Outcome::Yes,
        Verdict::No => Outcome::No,
        Verdict::Unclear => Outcome::Unknown,
    }
}

/// Asks every question of every window of `pipeline` under every
/// condition. Windows run in parallel (each model request is one blocking
/// call); `progress` hears how many questions each window finished.
pub fn evaluate_lmm(
    pipeline: Pipeline,
    images: Option<&FrameImages>,
    questions: &[Question],
    conditions: &[Condition],
    lmm: &BTreeMap<Condition, Lmm>,
    frames: usize,
    progress: &(dyn Fn(usize) + Sync),
) -> Result<Vec<LmmRecord>, LmmEvalError> {
    let prepared: Vec<_> = questions
        .iter()
        .map(|q| pipeline.prepare(&q.question))
        .collect();
    let mut answered = Vec::with_capacity(questions.len());
    pipeline.answer_each_in_order(
        questions.len(),
        |i| questions[i].window.clone(),
        |i, window| {
            LmmEvalError::Eval(EvalError::UnknownWindow {
                file: "questions".into(),
                number: i + 1,
                window,
            })
        },
        |engine, kb, i| -> Result<Vec<LmmRecord>, LmmEvalError> {
            let q = &questions[i];
            let (logic, ctx) = match &prepared[i] {
                Ok(p) => {
                    let r = engine.ask(kb, p, AskOptions::default());
                    (
                        r.answer,
                        crate::context::RagContext::new(kb, Some(&q.question), &r, engine.words()),
                    )
                }
                Err(e) => {
                    // The reason goes into C2 as it does for `ask`: an
                    // Invalid answer never comes without one.
                    let r = crate::ask::invalid(kb, &q.question, &[])
                        .with_reason(format!("cannot translate: {}", e.reason()));
                    (
                        Outcome::Invalid,
                        crate::context::RagContext::new(kb, Some(&q.question), &r, engine.words()),
                    )
                }
            };
            let pngs: Vec<Vec<u8>> = match images {
                Some(imgs) => imgs.pngs(
                    kb.first_frame,
                    kb.last_frame,
                    frames,
                    crate::images::DEFAULT_MAX_SIDE,
                )?,
                None => Vec::new(),
            };
            let mut out = Vec::new();
            for c in conditions {
                let Some(model) = lmm.get(c) else { continue };
                let a = model.ask(*c, &q.question, &ctx, &pngs)?;
                out.push(LmmRecord {
                    window: q.window.clone(),
                    question: q.question.clone(),
                    category: q.category.clone(),
                    expected: q.answer,
                    logic,
                    answer: a,
                });
            }
            Ok(out)
        },
        progress,
        &mut |_, r| answered.push(r),
    )?;
    let mut records = Vec::new();
    for r in answered {
        records.extend(r?);
    }
    Ok(records)
}

/// Errors of an LMM evaluation.
#[derive(Debug, thiserror::Error)]
pub enum LmmEvalError {
    /// Occurs when the question set or a window is wrong.
    #[error(transparent)]
    Eval(#[from] EvalError),
    /// Occurs when a window's KB cannot be built.
    #[error(transparent)]
    Kb(#[from] crate::kb::KbError),
    /// Occurs when the model cannot be asked.
    #[error(transparent)]
    Llm(#[from] LlmError),
    /// Occurs when a frame cannot be read.
    #[error(transparent)]
    Image(#[from] crate::images::ImageError),
}

/// Scores of the logic alone and of each condition.
#[derive(Debug, Clone, Default)]
pub struct Table {
    /// Column name (`LR`, `C1`, …) → scores.
    pub columns: BTreeMap<String, Evaluation>,
}

impl Table {
    /// The logic's answers from `logic` (question, expected, category,
    /// said) and the model's from `records`.
    pub fn new(records: &[LmmRecord]) -> Table {
        let mut columns: BTreeMap<String, Evaluation> = BTreeMap::new();
        let mut seen_logic = std::collections::BTreeSet::new();
        for r in records {
            if seen_logic.insert((r.window.clone(), r.question.clone())) {
                columns
                    .entry("LR".into())
                    .or_default()
                    .add(&r.category, r.expected, r.logic);
            }
            columns
                .entry(r.answer.condition.as_str().to_uppercase())
                .or_default()
                .add(&r.category, r.expected, said(r.answer.verdict));
        }
        Table { columns }
    }

    /// The columns of an evaluation: `LR` from `logic` (the logic's
    /// answers to every question) and, for each condition the model
    /// answered under, `C1`–`C3` (this table's own `LR` is the logic on the
    /// model's questions, the same or fewer, so it is not repeated).
    pub fn score_columns(&self, logic: &Evaluation) -> Vec<crate::metrics::ScoreColumn> {
        use crate::metrics::ScoreColumn;
        std::iter::once(ScoreColumn::from_evaluation("LR", logic))
            .chain(
                self.columns
                    .iter()
                    .filter(|(name, _)| name.as_str() != "LR")
                    .map(|(name, e)| ScoreColumn::from_evaluation(name, e)),
            )
            .collect()
    }

    /// Rows per category and overall, accuracy and F1 per column.
    pub fn render(&self) -> String {
        // The logic alone first, as in the paper's table.
        let mut names: Vec<&String> = self.columns.keys().collect();
        names.sort_by_key(|n| (n.as_str() != "LR", n.as_str()));
        let mut cats: Vec<String> = self
            .columns
            .values()
            .flat_map(|e| e.by_category.keys().cloned())
            .collect();
        cats.sort();
        cats.dedup();
        let mut s = format!("{:<10}", "category");
        for n in &names {
            s.push_str(&format!(" {:>6} {:>5}", format!("{n} acc"), "F1"));
        }
        s.push('\n');
        let row = |label: &str, get: &dyn Fn(&Evaluation) -> Option<crate::metrics::Scores>| {
            let mut line = format!("{label:<10}");
            for n in &names {
                match self.columns.get(*n).and_then(get) {
                    Some(sc) => line.push_str(&format!(" {:>6.2} {:>5.2}", sc.accuracy, sc.f1)),
                    None => line.push_str(&format!(" {:>6} {:>5}", "-", "-")),
                }
            }
            line.push('\n');
            line
        };
        for c in &cats {
            s.push_str(&row(c, &|e| e.by_category.get(c).map(|x| x.scores())));
        }
        s.push_str(&row("all", &|e| Some(e.overall.scores())));
        s
    }
}
