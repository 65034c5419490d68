//! Loading a LogicPad file: YAML walk, declarations, rule parsing and every
//! check, producing a [`Schema`], a [`Program`] and the diagnostics.
//!
//! This module holds the public types ([`LogicPad`], [`LoadError`],
//! [`BUILTIN_SOURCE`]), the top-level API and the `Loader` state shared by
//! the stages, each in its own submodule:
//! - `load`: the YAML walk and the declarations (text → parsed rules);
//! - `roles`: the `role:`, `frames:` and `sentence:` keys of a declaration;
//! - `rules`: a parsed formula → resolved rule drafts, and the safety check;
//! - `check`: the per-rule checks that turn drafts into a [`Program`];
//! - `graph`: checks over the predicate dependency graph (negation cycles,
//!   dead rules).

mod check;
mod graph;
mod load;
mod roles;
mod rules;

use crate::diag::{DiagKind, Diagnostic, Severity, SourceFile, Span};
use crate::program::Program;
use crate::schema::Schema;
use crate::yaml::{self, Node};
use load::{EntryMeta, Parsed};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The project's default LogicPad, shipped in the repository.
pub const BUILTIN_SOURCE: &str = include_str!("../../LogicPad.yaml");

/// Errors that stop a LogicPad from loading at all.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// Occurs when the file cannot be read.
    #[error("cannot read LogicPad file `{}`: {source}", path.display())]
    Io {
        /// The path given.
        path: PathBuf,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// Occurs when the text is not valid YAML (nothing in it can be used).
    #[error("{}", .0.summary())]
    Yaml(Box<Diagnostic>),
    /// Occurs in strict mode when any check reports an error.
    #[error(
        "{file}: {} error(s) in strict mode; first: {}",
        count_errors(diagnostics),
        first_error(diagnostics)
    )]
    Strict {
        /// File name.
        file: String,
        /// Every diagnostic (errors and warnings).
        diagnostics: Vec<Diagnostic>,
    },
}

fn count_errors(d: &[Diagnostic]) -> usize {
    d.iter().filter(|d| d.is_error()).count()
}
fn first_error(d: &[Diagnostic]) -> String {
    d.iter()
        .find(|d| d.is_error())
        .map(Diagnostic::summary)
        .unwrap_or_default()
}

impl LoadError {
    /// The diagnostics carried by this error (empty for I/O errors).
    pub fn diagnostics(&self) -> Vec<Diagnostic> {
        match self {
            LoadError::Io { .. } => Vec::new(),
            LoadError::Yaml(d) => vec![(**d).clone()],
            LoadError::Strict { diagnostics, .. } => diagnostics.clone(),
        }
    }
}

/// A loaded LogicPad: its vocabulary, its compiled rules and what the checker found.
///
/// Invariants: every rule in `program` passed every error-level check; rules
/// with errors are only present as diagnostics. `constants` holds every
/// constant a rule's head or positive body names and every declared value,
/// and nothing else.
#[derive(Debug, Clone)]
pub struct LogicPad {
    schema: Arc<Schema>,
    program: Program,
    diagnostics: Vec<Diagnostic>,
    source: Arc<SourceFile>,
    constants: Arc<rustc_hash::FxHashSet<String>>,
}

/// The constants `program`'s rules name (heads and positive bodies) and the
/// values `schema` declares.
fn named_constants(schema: &Schema, program: &Program) -> rustc_hash::FxHashSet<String> {
    let in_rules = program.rules().iter().flat_map(|r| {
        r.head
            .args
            .iter()
            .chain(r.body.iter().flat_map(|a| a.args.iter()))
            .filter_map(|a| match a {
                crate::CArg::Const(kanren::Term::Sym(s)) => Some(s.as_str().to_string()),
                _ => None,
            })
    });
    let declared = schema
        .predicates()
        .flat_map(|p| p.values.iter().flatten().cloned());
    in_rules.chain(declared).collect()
}

/// Reads a LogicPad file: a regular file only (a FIFO would block forever
/// and a device never end).
pub(crate) fn read_source(path: &Path) -> std::io::Result<String> {
    if !std::fs::metadata(path)?.is_file() {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            "not a regular file (a directory, FIFO or device is not read)",
        ));
    }
    std::fs::read_to_string(path)
}

impl LogicPad {
    /// Reads and checks a LogicPad file (not strict: rules with errors are left out).
    pub fn load(path: impl AsRef<Path>) -> Result<LogicPad, LoadError> {
        LogicPad::load_with(path, false)
    }

    /// Reads and checks a file; with `strict`, any error-level diagnostic fails the load.
    pub fn load_with(path: impl AsRef<Path>, strict: bool) -> Result<LogicPad, LoadError> {
        let path = path.as_ref();
        let text = read_source(path).map_err(|source| LoadError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        LogicPad::parse(&text, &path.display().to_string(), strict)
    }

    /// Checks LogicPad text. `file_name` is used in diagnostics.
    pub fn parse(src: &str, file_name: &str, strict: bool) -> Result<LogicPad, LoadError> {
        let source = SourceFile::new(file_name, src);
        let root = yaml::parse(src).map_err(|e| {
            LoadError::Yaml(Box::new(
                Diagnostic::new(
                    DiagKind::YamlSyntax,
                    Severity::Error,
                    &source,
                    e.span,
                    "invalid YAML",
                )
                .with_label(e.message)
                .with_help("fix the YAML syntax; nothing in this file could be loaded"),
            ))
        })?;
        let mut loader = Loader {
            source: Arc::clone(&source),
            schema: Schema::new(),
            diags: Vec::new(),
            rules: Vec::new(),
            entry_meta: Vec::new(),
        };
        loader.document(&root);
        let (schema, program, mut diagnostics) = loader.finish();
        // An empty file (or `~`) linted clean and, loaded, replaced the
        // whole vocabulary with nothing.
        if schema.is_empty() {
            diagnostics.push(
                Diagnostic::new(
                    DiagKind::Structure,
                    Severity::Warning,
                    &source,
                    Span::new(0, src.len().min(1)),
                    "this LogicPad declares no predicates",
                )
                .with_label("nothing declared")
                .with_help("declare predicates under `atomic_predicates`, `functions` or `derived_predicates`"),
            );
        }
        diagnostics.sort_by(|a, b| {
            (a.span.start, a.kind, &a.message).cmp(&(b.span.start, b.kind, &b.message))
        });
        diagnostics.dedup();
        if strict && diagnostics.iter().any(Diagnostic::is_error) {
            return Err(LoadError::Strict {
                file: file_name.to_string(),
                diagnostics,
            });
        }
        Ok(LogicPad {
            constants: Arc::new(named_constants(&schema, &program)),
            schema,
            program,
            diagnostics,
            source,
        })
    }

    /// Whether a rule (its head or positive body) or a declared value names
    /// the constant `c`: then the LogicPad itself gives `c` a meaning,
    /// whether or not a window mentions it.
    pub fn names_constant(&self, c: &str) -> bool {
        self.constants.contains(c)
    }

    /// The project's default LogicPad (`logicpad/LogicPad.yaml`, embedded).
    pub fn builtin() -> LogicPad {
        match LogicPad::parse(BUILTIN_SOURCE, "LogicPad.yaml", false) {
            Ok(p) => p,
            // The builtin file is checked by a unit test to load cleanly; an
            // empty pad keeps this infallible should that ever regress.
            Err(_) => LogicPad::empty(),
        }
    }

    /// A LogicPad with no predicates and no rules.
    pub fn empty() -> LogicPad {
        let schema = Arc::new(Schema::new());
        let source = SourceFile::new("<empty>", "");
        let program = Program::build(Arc::clone(&schema), Vec::new());
        LogicPad {
            constants: Arc::new(named_constants(&schema, &program)),
            schema,
            program,
            diagnostics: Vec::new(),
            source,
        }
    }

    /// The vocabulary (declared predicates plus rule heads).
    pub fn schema(&self) -> &Schema {
        &self.schema
    }
    /// The vocabulary, shareable.
    pub fn schema_arc(&self) -> Arc<Schema> {
        Arc::clone(&self.schema)
    }
    /// Everything the checker found, sorted by position.
    pub fn diagnostics(&self) -> &[Diagnostic] {
        &self.diagnostics
    }
    /// The compiled, stratified rules that passed the checks.
    pub fn program(&self) -> &Program {
        &self.program
    }
    /// The checked text.
    pub fn source(&self) -> &Arc<SourceFile> {
        &self.source
    }
    /// True when any diagnostic is an error.
    pub fn has_errors(&self) -> bool {
        self.diagnostics.iter().any(Diagnostic::is_error)
    }
}

/// The state of one load, shared by the stages in the submodules: each adds
/// its own `impl Loader` block.
struct Loader {
    source: Arc<SourceFile>,
    schema: Schema,
    diags: Vec<Diagnostic>,
    rules: Vec<Parsed>,
    entry_meta: Vec<EntryMeta>,
}

/// Diagnostic helpers used by every stage.
impl Loader {
    fn diag(
        &mut self,
        kind: DiagKind,
        sev: Severity,
        span: Span,
        msg: impl Into<String>,
    ) -> &mut Diagnostic {
        self.diags
            .push(Diagnostic::new(kind, sev, &self.source, span, msg));
        let last = self.diags.len() - 1;
        &mut self.diags[last]
    }

    /// A key whose value is not text: `expected` and what was found.
    fn not_text(&mut self, n: &Node, kind: DiagKind, expected: &str, label: &str) {
        let found = n.kind();
        let d = self.diag(
            kind,
            Severity::Error,
            n.span,
            format!("{expected}, found {found}"),
        );
        d.label = label.into();
    }

    fn structure(&mut self, span: Span, msg: impl Into<String>, label: impl Into<String>) {
        let d = Diagnostic::new(
            DiagKind::Structure,
            Severity::Error,
            &self.source,
            span,
            msg,
        )
        .with_label(label);
        self.diags.push(d);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The constants a LogicPad names: those of rule heads and positive
    /// bodies, and declared values; not those only under `¬`.
    #[test]
    fn named_constants_are_rule_constants_and_declared_values() {
        let src = "atomic_predicates:
  g:
    - Near(x, y)
    - Seen(x)
functions:
  ColorOf:
    predicate: ColorOf(x, value)
    values: [White, Red]
derived_predicates:
  - name: NearHome
    logic: \"∀x : Near(x, HomeBase) ∧ ¬Near(x, FarAway) ==> NearHome(x)\"
";
        let pad = LogicPad::parse(src, "consts.yaml", false).expect("loads");
        assert!(pad.diagnostics().is_empty(), "{:?}", pad.diagnostics());
        assert!(pad.names_constant("HomeBase"));
        assert!(pad.names_constant("White"));
        assert!(pad.names_constant("Red"));
        assert!(!pad.names_constant("FarAway"));
        assert!(!pad.names_constant("car_1"));
        assert!(!LogicPad::empty().names_constant("White"));
    }
}
