//! `lint`: every diagnostic of a LogicPad file, rendered for a person.

use crate::diag::{DiagKind, Diagnostic, Severity, SourceFile, Span};
use crate::pad::LogicPad;
use std::io::IsTerminal;
use std::path::Path;

/// What `lint` found in one file.
#[derive(Debug, Clone)]
pub struct LintReport {
    /// The file checked.
    pub file: String,
    /// Every diagnostic, sorted by position.
    pub diagnostics: Vec<Diagnostic>,
    /// Rules that passed the checks.
    pub rules: usize,
    /// Integrity constraints kept.
    pub constraints: usize,
}

impl LintReport {
    /// Number of error-level diagnostics.
    pub fn errors(&self) -> usize {
        self.diagnostics
            .iter()
            .filter(|d| d.severity == Severity::Error)
            .count()
    }
    /// Number of warnings.
    pub fn warnings(&self) -> usize {
        self.diagnostics
            .iter()
            .filter(|d| d.severity == Severity::Warning)
            .count()
    }
    /// 0 clean, 1 warnings only, 2 errors.
    pub fn exit_code(&self) -> i32 {
        if self.errors() > 0 {
            2
        } else if self.warnings() > 0 {
            1
        } else {
            0
        }
    }
    /// miette's graphical rendering of every diagnostic (colour only when
    /// stdout is a terminal) and a summary line.
    pub fn render(&self) -> String {
        self.render_with(std::io::stdout().is_terminal(), 100)
    }
    /// Renders with or without colour at a given width (for tests: no colour).
    pub fn render_with(&self, colour: bool, width: usize) -> String {
        let theme = if colour {
            miette::GraphicalTheme::unicode()
        } else {
            miette::GraphicalTheme::unicode_nocolor()
        };
        let handler = miette::GraphicalReportHandler::new_themed(theme)
            .with_width(width)
            .with_links(false);
        let mut out = String::new();
        for d in &self.diagnostics {
            if d.has_long_line() {
                out.push_str(&d.render_plain(width));
            } else if handler.render_report(&mut out, d).is_err() {
                out.push_str(&format!("{}\n", d.summary()));
            }
            out.push('\n');
        }
        out.push_str(&format!(
            "{}: {} error(s), {} warning(s); {} rule(s) and {} constraint(s) loaded\n",
            self.file,
            self.errors(),
            self.warnings(),
            self.rules,
            self.constraints
        ));
        out
    }
}

/// Lints a LogicPad file.
pub fn lint(path: impl AsRef<Path>) -> LintReport {
    lint_with(path, false)
}

/// Lints a file; with `strict`, the summary still lists every diagnostic.
pub fn lint_with(path: impl AsRef<Path>, strict: bool) -> LintReport {
    let path = path.as_ref();
    let file = path.display().to_string();
    match crate::pad::read_source(path) {
        Ok(text) => lint_source(&text, &file, strict),
        Err(e) => {
            let src = SourceFile::new(file.as_str(), "");
            let d = Diagnostic::new(
                DiagKind::Io,
                Severity::Error,
                &src,
                Span::default(),
                format!("cannot read `{file}`: {e}"),
            )
            .with_help("check the path");
            LintReport {
                file,
                diagnostics: vec![d],
                rules: 0,
                constraints: 0,
            }
        }
    }
}

/// Lints LogicPad text.
pub fn lint_source(text: &str, file: &str, strict: bool) -> LintReport {
    match LogicPad::parse(text, file, strict) {
        Ok(pad) => LintReport {
            file: file.to_string(),
            diagnostics: pad.diagnostics().to_vec(),
            rules: pad.program().rules().len(),
            constraints: pad.program().constraints().len(),
        },
        Err(e) => LintReport {
            file: file.to_string(),
            diagnostics: e.diagnostics(),
            rules: 0,
            constraints: 0,
        },
    }
}
