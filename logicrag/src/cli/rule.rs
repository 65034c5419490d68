//! `logicrag rule`: a rule in FOL, or an English definition, becomes a
//! LogicPad rule checked by the LogicPad checker, and with `--append FILE`
//! is added to a LogicPad file with its English sentence as a comment.

use super::LlmArgs;
use anyhow::{Result, bail};
use clap::Args;
use logicrag::compose;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct RuleArgs {
    /// The rule in FOL (`∀x : Pedestrian(x) ∧ On(x, y) ∧ Road(y) ==> Crossing(x)`)
    /// or an English definition ("A pedestrian is jaywalking when it is on a road and moving").
    pub text: String,
    /// The LogicPad to check against (default: the --append file, else the built-in LogicPad).
    #[arg(long)]
    pub logicpad: Option<PathBuf>,
    /// Add the rule to this LogicPad file, under `derived_predicates`.
    #[arg(long)]
    pub append: Option<PathBuf>,
    /// The new predicate's name (default: made from the defined words).
    #[arg(long)]
    pub name: Option<String>,
    /// English phrases the translator will know the predicate by, comma
    /// separated (default: the defined words).
    #[arg(long, value_delimiter = ',')]
    pub phrases: Vec<String>,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub llm: LlmArgs,
}

pub fn run(a: RuleArgs) -> Result<ExitCode> {
    let pad_path = a.logicpad.clone().or_else(|| a.append.clone());
    let pipeline = super::sourceless(&pad_path, None)?;
    let engine = pipeline.engine();
    let mut rule = if compose::looks_like_fol(&a.text) {
        let r = compose::from_fol(&a.text)?;
        if let Some(n) = &a.name
            && *n != r.name
        {
            bail!("--name {n} differs from the rule's head `{}`", r.name);
        }
        r
    } else {
        compose::from_definition(
            engine,
            &a.text,
            a.name.as_deref(),
            a.llm.translator,
            a.llm.llm_setup()?.as_ref(),
        )?
    };
    if !a.phrases.is_empty() {
        rule.phrases = a.phrases.iter().map(|p| p.trim().to_lowercase()).collect();
    }
    let ext = compose::extend(engine.pad(), &rule)?;
    let appended = match &a.append {
        Some(path) => {
            compose::write_pad(path, &ext)?;
            Some(path.display().to_string())
        }
        None => None,
    };
    if a.json {
        outln!(
            "{}",
            serde_json::json!({
                "rule": rule.logic,
                "name": rule.name,
                "arity": rule.arity,
                "phrases": rule.phrases,
                "sentence": rule.sentence,
                "via": rule.via,
                "notes": rule.notes,
                "warnings": ext.warnings,
                "appended": appended.as_ref().map(|f| serde_json::json!({"file": f, "line": ext.line})),
            })
        );
    } else {
        outln!("{}", rule.logic);
        for n in &rule.notes {
            outln!("note: {n}");
        }
        for w in &ext.warnings {
            outln!("warning: {w}");
        }
        match &appended {
            Some(f) => outln!(
                "appended to {f} at line {} (ask with \"{}\")",
                ext.line,
                rule.phrases.join("\", \"")
            ),
            None => outln!("checked against the LogicPad; --append FILE adds it"),
        }
    }
    Ok(ExitCode::SUCCESS)
}
