//! `logicrag lint`: every diagnostic of a LogicPad file, exit code by the
//! worst (0 clean, 1 warnings, 2 errors).

use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct LintArgs {
    /// The LogicPad YAML file.
    pub file: PathBuf,
    /// Treat every error as fatal (nothing loads).
    #[arg(long)]
    pub strict: bool,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: LintArgs) -> Result<ExitCode> {
    let report = logicpad::lint_with(&a.file, a.strict);
    if a.json {
        let diags: Vec<_> = report
            .diagnostics
            .iter()
            .map(|d| {
                serde_json::json!({
                    "severity": if d.is_error() { "error" } else { "warning" },
                    "code": d.kind.code(), "line": d.line(), "column": d.column(), "message": d.message,
                })
            })
            .collect();
        outln!(
            "{}",
            serde_json::json!({"file": a.file.display().to_string(), "diagnostics": diags})
        );
    } else {
        outp!("{}", report.render());
    }
    Ok(ExitCode::from(report.exit_code() as u8))
}
