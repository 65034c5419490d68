//! Loading a LogicPad file: YAML walk, declarations, rule parsing and every
//! check, producing a [`Schema`], a [`Program`] and the diagnostics.

use crate::diag::{DiagKind, Diagnostic, Severity, SourceFile, Span};
use crate::fol::{self, Arg, Atom, Formula, Literal, Resolver};
use crate::program::{Program, RuleSource, SourceRule};
use crate::schema::{Frames, PredInfo, PredKind, Role, Schema};
use crate::yaml::{self, Node, Value};
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The project's default LogicPad, shipped in the repository.
pub const BUILTIN_SOURCE: &str = include_str!("../LogicPad.yaml");

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
/// Invariant: every rule in `program` passed every error-level check; rules
/// with errors are only present as diagnostics.
#[derive(Debug, Clone)]
pub struct LogicPad {
    schema: Arc<Schema>,
    program: Program,
    diagnostics: Vec<Diagnostic>,
    source: Arc<SourceFile>,
}

/// The `phrases:` and `description:` of a declaration.
fn words(node: &Node) -> (Vec<String>, Option<String>) {
    let phrases = node
        .get("phrases")
        .and_then(is_list_of_strings)
        .unwrap_or_default();
    let description = node
        .get("description")
        .and_then(Node::as_str)
        .map(str::to_string);
    (phrases, description)
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
            schema,
            program,
            diagnostics,
            source,
        })
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

/// A rule as parsed from one `logic` string, before the semantic checks.
struct Parsed {
    entry: String,
    text: String,
    node_span: Span,
    /// Offset of the formula text in the file (None: spans point at the node).
    base: Option<usize>,
    formula: Formula,
}

struct Loader {
    source: Arc<SourceFile>,
    schema: Schema,
    diags: Vec<Diagnostic>,
    rules: Vec<Parsed>,
    entry_meta: Vec<EntryMeta>,
}

/// What a derived entry says about its predicate besides the rules. Kept
/// until the rule heads are known (they give the arity a role must fit);
/// attached in `finish`.
struct EntryMeta {
    name: String,
    phrases: Vec<String>,
    description: Option<String>,
    role: RoleKeys,
}

/// The `role:` and `frames:` of a declaration, each with where it was
/// written, once their names are known to be valid.
#[derive(Default)]
struct RoleKeys {
    role: Option<(Role, Span)>,
    frames: Option<(Frames, Span)>,
    /// `sentence:`, the C3 template, with where it was written.
    sentence: Option<(String, Span)>,
}

impl RoleKeys {
    fn is_empty(&self) -> bool {
        self.role.is_none() && self.frames.is_none() && self.sentence.is_none()
    }
}

fn is_list_of_strings(n: &Node) -> Option<Vec<String>> {
    match &n.value {
        Value::Seq(items) => items
            .iter()
            .map(|i| i.as_str().map(str::to_string))
            .collect(),
        Value::Scalar(s) => Some(vec![s.clone()]),
        _ => None,
    }
}

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

    /// Reads `role:` and `frames:` from a declaration; an unknown name is
    /// reported and left out, so the translator infers that part instead.
    fn role_keys(&mut self, item: &Node) -> RoleKeys {
        let mut keys = RoleKeys::default();
        if let Some(n) = item.get("role") {
            let names: Vec<&str> = Role::ALL.iter().map(|r| r.name()).collect();
            match n.as_str().map(str::trim) {
                Some(s) => match Role::from_name(s) {
                    Some(r) => keys.role = Some((r, n.span)),
                    None => {
                        let hint = crate::diag::did_you_mean(s, names.iter().copied());
                        let list = names.join(", ");
                        let d = self.diag(
                            DiagKind::BadRole,
                            Severity::Error,
                            n.span,
                            format!("unknown role `{s}`"),
                        );
                        d.label = "not a role".into();
                        d.help = Some(match hint {
                            Some(h) => format!("did you mean `{h}`? the roles are {list}"),
                            None => format!("the roles are {list}"),
                        });
                    }
                },
                None => self.not_text(
                    n,
                    DiagKind::BadRole,
                    "a role must be one word such as `class`",
                    "not a role",
                ),
            }
        }
        if let Some(n) = item.get("sentence") {
            match n.as_str() {
                Some(t) => keys.sentence = Some((t.to_string(), n.span)),
                None => self.not_text(
                    n,
                    DiagKind::Structure,
                    "a sentence must be text such as \"{x} moves\"",
                    "not a sentence",
                ),
            }
        }
        if let Some(n) = item.get("frames") {
            match n.as_str().map(str::trim).and_then(Frames::from_name) {
                Some(f) => keys.frames = Some((f, n.span)),
                None => {
                    let d = self.diag(
                        DiagKind::BadRole,
                        Severity::Error,
                        n.span,
                        "`frames` must be `initial` or `last`",
                    );
                    d.label = "not frames".into();
                    d.help = Some(
                        "the frames a place said with this predicate refers to: the object's first (`initial`) or last (`last`)".into(),
                    );
                }
            }
        }
        keys
    }

    /// Checks a sentence template against the predicate's arity: `{x}`
    /// stands for the first argument, `{y}` for the second; any other
    /// placeholder is an error and the template is left out.
    fn fit_sentence(&mut self, keys: &RoleKeys, name: &str, arity: usize) -> Option<String> {
        let (text, span) = keys.sentence.as_ref()?;
        let allowed: &[&str] = match arity {
            0 => &[],
            1 => &["x"],
            _ => &["x", "y"],
        };
        let mut rest = text.as_str();
        while let Some(open) = rest.find('{') {
            let after = &rest[open + 1..];
            let Some(close) = after.find('}') else {
                break;
            };
            let name_in = &after[..close];
            if !allowed.contains(&name_in) {
                let d = self.diag(
                    DiagKind::Structure,
                    Severity::Error,
                    *span,
                    format!("the sentence of `{name}` uses `{{{name_in}}}`, which its {arity} argument(s) do not fill"),
                );
                d.label = "unknown placeholder".into();
                d.help = Some("write `{x}` for the first argument and `{y}` for the second, e.g. \"{x} is to the left of {y}\"".into());
                return None;
            }
            rest = &after[close + 1..];
        }
        Some(text.clone())
    }

    /// Checks a role against the predicate's kind and arity, and frames
    /// against the role; what does not fit is reported and left out.
    /// Phrases of a silent predicate are kept but reported: no question
    /// reads them.
    fn fit_role(
        &mut self,
        keys: RoleKeys,
        name: &str,
        (kind, arity): (PredKind, usize),
        has_phrases: bool,
    ) -> (Option<Role>, Option<Frames>) {
        let mut role = None;
        if let Some((r, span)) = keys.role {
            match r.misfit(kind, arity) {
                None if r == Role::Silent && has_phrases => {
                    role = Some(r);
                    let d = self.diag(
                        DiagKind::BadRole,
                        Severity::Warning,
                        span,
                        format!("`{name}` is silent, so its phrases are never read in questions"),
                    );
                    d.label = "silent here".into();
                    d.help = Some(
                        "remove the phrases, or give it the role its words play (`class`, `property`, `relation`, …)".into(),
                    );
                }
                None => role = Some(r),
                Some(why) => {
                    let d = self.diag(
                        DiagKind::BadRole,
                        Severity::Error,
                        span,
                        format!("`{name}` cannot have the role `{}`", r.name()),
                    );
                    d.label = why;
                    d.help = Some(
                        "a unary predicate is a `class` or a `property`, a binary one a `relation`; a function is a `type`, an `attribute` or a `location`; any may be `silent`".into(),
                    );
                }
            }
        }
        let mut frames = None;
        if let Some((f, span)) = keys.frames {
            match role {
                Some(r) if !r.takes_frames() => {
                    let d = self.diag(
                        DiagKind::BadRole,
                        Severity::Warning,
                        span,
                        format!(
                            "`frames` means nothing for the role `{}` and is ignored",
                            r.name()
                        ),
                    );
                    d.label = "ignored".into();
                    d.help = Some("only a `location` or a `property` refers to frames".into());
                }
                _ => frames = Some(f),
            }
        }
        (role, frames)
    }

    fn document(&mut self, root: &Node) {
        let Value::Map(entries) = &root.value else {
            if matches!(root.value, Value::Null) {
                return;
            }
            let kind = root.kind();
            self.structure(
                root.span,
                format!("a LogicPad file must be a mapping, found {kind}"),
                "expected `atomic_predicates:`, `functions:` and `derived_predicates:`",
            );
            return;
        };
        let mut derived = None;
        for (k, v) in entries {
            match k.as_str() {
                Some("atomic_predicates") => self.atomic_group(v, None),
                Some("functions") => self.function_group(v, None),
                Some("derived_predicates") => derived = Some(v),
                Some(other) => {
                    let other = other.to_string();
                    let hint = crate::diag::did_you_mean(
                        &other,
                        ["atomic_predicates", "functions", "derived_predicates"],
                    );
                    let d = self.diag(
                        DiagKind::Structure,
                        Severity::Warning,
                        k.span,
                        format!("unknown top-level key `{other}` is ignored"),
                    );
                    d.label = "not a LogicPad section".into();
                    d.help = Some(match hint {
                        Some(h) => format!("did you mean `{h}`?"),
                        None => "the sections are `atomic_predicates`, `functions` and `derived_predicates`".into(),
                    });
                }
                None => self.structure(
                    k.span,
                    "a section name must be text",
                    "expected a section name",
                ),
            }
        }
        // Declarations first, so rules may use predicates declared below them.
        if let Some(v) = derived {
            self.derived(v);
        }
    }

    /// Parses a signature like `ColorOf(x, color)`.
    fn signature(&mut self, node: &Node, text: &str) -> Option<(String, Vec<String>, Span)> {
        let base = yaml::scalar_content_offset(&self.source.text, node, text);
        let shift = |s: Span| base.map_or(node.span, |b| s.shifted(b));
        match fol::parse_formula(text) {
            Ok(Formula::Atom(a)) => {
                let mut params = Vec::new();
                for t in &a.args {
                    match t {
                        fol::TermAst::Name(n, _) | fol::TermAst::QVar(n, _) => {
                            params.push(n.clone())
                        }
                        fol::TermAst::Quoted(_, s) => {
                            self.structure(
                                shift(*s),
                                "a declaration's parameters must be names",
                                "expected a name",
                            );
                            return None;
                        }
                    }
                }
                if params.is_empty() {
                    self.structure(
                        shift(a.span),
                        "a predicate needs at least one argument",
                        "declared with no arguments",
                    );
                    return None;
                }
                Some((a.pred, params, shift(a.pred_span)))
            }
            Ok(f) => {
                self.structure(
                    shift(f.span()),
                    format!("expected a predicate signature such as `Road(x)`, found `{text}`"),
                    "not a single predicate",
                );
                None
            }
            Err(e) => {
                let d = Diagnostic::new(
                    DiagKind::FolSyntax,
                    Severity::Error,
                    &self.source,
                    shift(e.span),
                    e.message,
                )
                .with_label(e.label)
                .with_help("a declaration looks like `Road(x)` or `DistanceIncrease(x, y)`");
                self.diags.push(d);
                None
            }
        }
    }

    fn declare(&mut self, info: PredInfo) {
        if let Some(prev) = self.schema.get(&info.name) {
            let prev_span = prev.span;
            let span = info.span.unwrap_or_default();
            let mut d = Diagnostic::new(
                DiagKind::DuplicateDeclaration,
                Severity::Warning,
                &self.source,
                span,
                format!(
                    "`{}` is declared twice; the first declaration is kept",
                    info.name
                ),
            )
            .with_label("declared again here");
            if let Some(ps) = prev_span {
                d = d.with_related(ps, "first declared here");
            }
            self.diags.push(d);
            return;
        }
        self.schema.insert(info);
    }

    fn atomic_group(&mut self, node: &Node, group: Option<&str>) {
        match &node.value {
            Value::Map(groups) => {
                for (k, v) in groups {
                    let Some(name) = k.as_str() else {
                        self.structure(
                            k.span,
                            "a group name must be text",
                            "expected a group name",
                        );
                        continue;
                    };
                    let g = match group {
                        Some(p) => format!("{p}/{name}"),
                        None => name.to_string(),
                    };
                    self.atomic_group(v, Some(&g));
                }
            }
            Value::Seq(items) => {
                for item in items {
                    self.atomic_item(item, group);
                }
            }
            Value::Null => {}
            Value::Scalar(_) => {
                let kind = node.kind();
                self.structure(
                    node.span,
                    format!("expected a list of predicates (grouped by producer), found {kind}"),
                    "expected `- Road(x)` items",
                )
            }
        }
    }

    fn atomic_item(&mut self, item: &Node, group: Option<&str>) {
        let (sig_node, phrases, description, keys) = match &item.value {
            Value::Scalar(_) => (item, Vec::new(), None, RoleKeys::default()),
            Value::Map(m) if item.get("predicate").is_some() => {
                let (phrases, description) = words(item);
                let _ = m;
                let keys = self.role_keys(item);
                (
                    item.get("predicate").unwrap_or(item),
                    phrases,
                    description,
                    keys,
                )
            }
            Value::Map(m) if m.len() == 1 => {
                let (k, v) = &m[0];
                let phrases = is_list_of_strings(v).unwrap_or_default();
                (k, phrases, None, RoleKeys::default())
            }
            _ => {
                let kind = item.kind();
                self.structure(
                    item.span,
                    format!("expected a predicate such as `Road(x)`, found {kind}"),
                    "not a predicate",
                );
                return;
            }
        };
        let Some(text) = sig_node.as_str().map(str::to_string) else {
            self.structure(
                sig_node.span,
                "expected a predicate signature such as `Road(x)`",
                "not text",
            );
            return;
        };
        if let Some((name, params, span)) = self.signature(sig_node, &text) {
            let sentence = self.fit_sentence(&keys, &name, params.len());
            let (role, frames) = self.fit_role(
                keys,
                &name,
                (PredKind::Atomic, params.len()),
                !phrases.is_empty(),
            );
            self.declare(PredInfo {
                name,
                arity: params.len(),
                kind: PredKind::Atomic,
                group: group.map(str::to_string),
                params,
                values: None,
                phrases,
                value_phrases: BTreeMap::new(),
                role,
                frames,
                sentence,
                description,
                span: Some(span),
            });
        }
    }

    fn function_group(&mut self, node: &Node, group: Option<&str>) {
        let Value::Map(entries) = &node.value else {
            if !matches!(node.value, Value::Null) {
                let kind = node.kind();
                self.structure(
                    node.span,
                    format!("`functions` must be a mapping, found {kind}"),
                    "expected `Name: {predicate: .., values: [..]}`",
                );
            }
            return;
        };
        for (k, v) in entries {
            let Some(name) = k.as_str().map(str::to_string) else {
                self.structure(k.span, "a function name must be text", "expected a name");
                continue;
            };
            if v.get("predicate").is_some() {
                self.function(&name, k, v, group);
            } else if matches!(v.value, Value::Map(_)) {
                let g = match group {
                    Some(p) => format!("{p}/{name}"),
                    None => name.clone(),
                };
                self.function_group(v, Some(&g));
            } else {
                let kind = v.kind();
                self.structure(
                    v.span,
                    format!("function `{name}` must be a mapping with `predicate` and `values`, found {kind}"),
                    "expected `predicate: {name}(x, value)` and `values: [..]`",
                );
            }
        }
    }

    fn function(&mut self, name: &str, key: &Node, v: &Node, group: Option<&str>) {
        let Some(pnode) = v.get("predicate") else {
            return;
        };
        let Some(text) = pnode.as_str().map(str::to_string) else {
            self.structure(
                pnode.span,
                "`predicate` must be a signature such as `ColorOf(x, color)`",
                "not text",
            );
            return;
        };
        let Some((pname, params, span)) = self.signature(pnode, &text) else {
            return;
        };
        if pname != name {
            let d = self.diag(
                DiagKind::Structure,
                Severity::Warning,
                span,
                format!("function entry `{name}` declares predicate `{pname}`; `{pname}` is used"),
            );
            d.label = "the predicate name".into();
            d.related.push(crate::diag::Label {
                span: key.span,
                text: "the entry name".into(),
            });
        }
        if params.len() < 2 {
            self.structure(
                span,
                format!("function `{pname}` needs an object and a value: `{pname}(x, value)`"),
                "too few parameters",
            );
            return;
        }
        let mut values = Vec::new();
        let mut value_phrases = BTreeMap::new();
        match v.get("values").map(|n| &n.value) {
            Some(Value::Seq(items)) => {
                // A value a query cannot spell is no value: `Truc$k` linted
                // clean and then failed in every query that named it.
                let writable = |s: &str| {
                    s.chars()
                        .next()
                        .is_some_and(|c| c.is_uppercase() || c.is_ascii_digit())
                        && s.chars().all(|c| c.is_alphanumeric() || c == '_')
                };
                for it in items {
                    let name = match &it.value {
                        Value::Scalar(s) => Some(s.as_str()),
                        Value::Map(m) if m.len() == 1 => m.first().and_then(|(k, _)| k.as_str()),
                        _ => None,
                    };
                    if let Some(n) = name.filter(|n| !writable(n)) {
                        self.structure(
                            it.span,
                            format!("function value `{n}` cannot be written in a query"),
                            "not a value name",
                        );
                        if let Some(d) = self.diags.last_mut() {
                            d.help = Some("a value is a capitalised name or a number of letters, digits and `_`, such as `White` or `NearLeft`".into());
                        }
                        continue;
                    }
                    match &it.value {
                        Value::Scalar(s) => values.push(s.clone()),
                        Value::Map(m) if m.len() == 1 => {
                            let (vk, vv) = &m[0];
                            if let Some(s) = vk.as_str() {
                                values.push(s.to_string());
                                value_phrases.insert(
                                    s.to_string(),
                                    is_list_of_strings(vv).unwrap_or_default(),
                                );
                            }
                        }
                        _ => self.structure(
                            it.span,
                            "a function value must be a name such as `White`",
                            "not a value",
                        ),
                    }
                }
            }
            _ => {
                self.structure(
                    v.span,
                    format!("function `{pname}` needs a `values:` list"),
                    "no `values` list here",
                );
                return;
            }
        }
        let (phrases, description) = words(v);
        let keys = self.role_keys(v);
        let worded = !phrases.is_empty() || value_phrases.values().any(|v| !v.is_empty());
        let (role, frames) =
            self.fit_role(keys, &pname, (PredKind::Function, params.len()), worded);
        self.declare(PredInfo {
            name: pname,
            arity: params.len(),
            kind: PredKind::Function,
            group: group.map(str::to_string),
            params,
            values: Some(values),
            phrases,
            value_phrases,
            role,
            frames,
            sentence: None,
            description,
            span: Some(span),
        });
    }

    fn derived(&mut self, node: &Node) {
        let Value::Seq(entries) = &node.value else {
            if !matches!(node.value, Value::Null) {
                let kind = node.kind();
                self.structure(
                    node.span,
                    format!("`derived_predicates` must be a list, found {kind}"),
                    "expected `- name: ..` entries",
                );
            }
            return;
        };
        for e in entries {
            let Some(name) = e.get("name").and_then(Node::as_str).map(str::to_string) else {
                self.structure(
                    e.span,
                    "a derived predicate entry needs a `name:`",
                    "no `name` here",
                );
                continue;
            };
            let Some(logic) = e.get("logic") else {
                self.structure(
                    e.span,
                    format!("derived predicate `{name}` has no `logic:`"),
                    "no `logic` here",
                );
                continue;
            };
            let items: Vec<&Node> = match &logic.value {
                Value::Scalar(_) => vec![logic],
                Value::Seq(items) => items.iter().collect(),
                _ => {
                    let kind = logic.kind();
                    self.structure(
                        logic.span,
                        format!("`logic` must be a rule or a list of rules, found {kind}"),
                        "not a rule",
                    );
                    continue;
                }
            };
            if items.is_empty() {
                // Without a rule the name is never declared, so a query on it
                // would fail as "not declared anywhere" while lint said
                // nothing.
                let d = Diagnostic::new(
                    DiagKind::Structure,
                    Severity::Warning,
                    &self.source,
                    logic.span,
                    format!("derived predicate `{name}` has an empty `logic:` list and is left out"),
                )
                .with_label("no rules here")
                .with_help(format!("give it at least one rule, such as \"∀x : Vehicles(x) ==> {name}(x)\", or remove the entry"));
                self.diags.push(d);
                continue;
            }
            let (phrases, description) = words(e);
            let role = self.role_keys(e);
            if !phrases.is_empty() || description.is_some() || !role.is_empty() {
                self.entry_meta.push(EntryMeta {
                    name: name.clone(),
                    phrases,
                    description,
                    role,
                });
            }
            for it in items {
                let Some(text) = it.as_str().map(str::to_string) else {
                    self.structure(
                        it.span,
                        "a rule must be text such as \"∀x : P(x) ==> Q(x)\"",
                        "not a rule",
                    );
                    continue;
                };
                let base = yaml::scalar_content_offset(&self.source.text, it, &text);
                match fol::parse_formula(&text) {
                    Ok(formula) => self.rules.push(Parsed {
                        entry: name.clone(),
                        text,
                        node_span: it.span,
                        base,
                        formula,
                    }),
                    Err(err) => {
                        let span = base.map_or(it.span, |b| err.span.shifted(b));
                        let d = Diagnostic::new(
                            DiagKind::FolSyntax,
                            Severity::Error,
                            &self.source,
                            span,
                            err.message,
                        )
                        .with_label(err.label)
                        .with_help(
                            "rules look like `∀x : Vehicles(x) ∧ ¬Moving(x) ==> Stopped(x)`",
                        );
                        self.diags.push(d);
                    }
                }
            }
        }
    }
}

/// A rule after name resolution, before the semantic checks.
struct Draft {
    entry: String,
    text: String,
    node_span: Span,
    base: Option<usize>,
    heads: Vec<(Atom, bool)>,
    bodies: Vec<Vec<Literal>>,
    vars: Vec<String>,
}

/// Moves every span of a literal from formula coordinates to file coordinates.
fn shift_atom(a: &mut Atom, f: &dyn Fn(Span) -> Span) {
    a.span = f(a.span);
    a.pred_span = f(a.pred_span);
    for s in &mut a.arg_spans {
        *s = f(*s);
    }
}
fn shift_lit(l: &mut Literal, f: &dyn Fn(Span) -> Span) {
    match l {
        Literal::Pos(a) | Literal::Neg(a) => shift_atom(a, f),
        Literal::Cmp { span, .. } => *span = f(*span),
    }
}

impl Loader {
    fn shifter(&self, base: Option<usize>, node_span: Span) -> impl Fn(Span) -> Span + use<> {
        move |s: Span| base.map_or(node_span, |b| s.shifted(b))
    }

    fn draft(&mut self, p: Parsed) -> Option<Draft> {
        let shift = self.shifter(p.base, p.node_span);
        let mut bound = Vec::new();
        fol::bound_names(&p.formula, &mut bound);
        let mut f = &p.formula;
        while let Formula::Quantified {
            quant: fol::Quant::Forall,
            body,
            ..
        } = f
        {
            f = body;
        }
        let Formula::Implies(body, head, _) = f else {
            let d = Diagnostic::new(
                DiagKind::FolSyntax,
                Severity::Error,
                &self.source,
                shift(f.span()),
                "a rule needs `==>` between its body and its head",
            )
            .with_label("no `==>` in this rule")
            .with_help("write rules as `∀x : Body(x) ==> Head(x)`");
            self.diags.push(d);
            return None;
        };
        let never = |_: &str| false;
        let mut r = Resolver {
            bound,
            is_constant: &never,
            vars: Vec::new(),
            var_spans: Vec::new(),
        };
        // Head: one atom, a negated atom (integrity constraint) or a conjunction of atoms.
        let mut head_f: &Formula = head;
        while let Formula::Quantified {
            quant: fol::Quant::Forall,
            body,
            ..
        } = head_f
        {
            head_f = body;
        }
        let head_parts: Vec<&Formula> = match head_f {
            Formula::And(fs) => fs.iter().collect(),
            other => vec![other],
        };
        let mut heads = Vec::new();
        for h in head_parts {
            match h {
                Formula::Atom(a) => heads.push((r.atom(a), false)),
                Formula::Not(inner, _) if matches!(**inner, Formula::Atom(_)) => {
                    if let Formula::Atom(a) = &**inner {
                        heads.push((r.atom(a), true));
                    }
                }
                other => {
                    let d = Diagnostic::new(
                        DiagKind::Unsupported,
                        Severity::Error,
                        &self.source,
                        shift(other.span()),
                        "a rule head must be an atom, a negated atom, or a conjunction of atoms",
                    )
                    .with_label("unsupported head")
                    .with_help("split a disjunctive head into several rules with the same body");
                    self.diags.push(d);
                    return None;
                }
            }
        }
        let bodies = match fol::to_dnf(body, &mut r) {
            Ok(b) => b,
            Err(e) => {
                let d = Diagnostic::new(
                    DiagKind::Unsupported,
                    Severity::Error,
                    &self.source,
                    shift(e.span),
                    e.message,
                )
                .with_label(e.label);
                self.diags.push(d);
                return None;
            }
        };
        for (a, _) in &mut heads {
            shift_atom(a, &shift);
        }
        let mut bodies = bodies;
        for b in &mut bodies {
            for l in b {
                shift_lit(l, &shift);
            }
        }
        Some(Draft {
            entry: p.entry,
            text: p.text,
            node_span: p.node_span,
            base: p.base,
            heads,
            bodies,
            vars: r.vars,
        })
    }

    /// Safety: every head variable, every variable under `¬` and every
    /// variable of a comparison must occur in a positive body atom.
    fn check_safety(
        &mut self,
        d: &Draft,
        head: &Atom,
        negated_head: bool,
        body: &[Literal],
    ) -> bool {
        let mut positives: Vec<&Atom> = body.iter().filter_map(Literal::positive).collect();
        if negated_head {
            positives.push(head);
        }
        let bound: BTreeSet<usize> = positives
            .iter()
            .flat_map(|a| a.args.iter())
            .filter_map(|x| if let Arg::Var(v) = x { Some(*v) } else { None })
            .collect();
        let mut offenders: Vec<(usize, Span, String)> = Vec::new();
        let check =
            |v: usize, span: Span, place: String, offenders: &mut Vec<(usize, Span, String)>| {
                if !bound.contains(&v) && !offenders.iter().any(|(o, _, _)| *o == v) {
                    offenders.push((v, span, place));
                }
            };
        if !negated_head {
            for (i, a) in head.args.iter().enumerate() {
                if let Arg::Var(v) = a {
                    check(
                        *v,
                        head.arg_spans.get(i).copied().unwrap_or(head.span),
                        "the head".into(),
                        &mut offenders,
                    );
                }
            }
        }
        let mut negs = Vec::new();
        for l in body {
            match l {
                Literal::Neg(a) => {
                    negs.push(a);
                    for (i, x) in a.args.iter().enumerate() {
                        if let Arg::Var(v) = x {
                            let sp = a.arg_spans.get(i).copied().unwrap_or(a.span);
                            check(*v, sp, format!("`¬{}`", a.pred), &mut offenders);
                        }
                    }
                }
                Literal::Cmp {
                    left, right, span, ..
                } => {
                    for x in [left, right] {
                        if let Arg::Var(v) = x {
                            check(*v, *span, "a comparison".into(), &mut offenders);
                        }
                    }
                }
                Literal::Pos(_) => {}
            }
        }
        let Some((v, span, place)) = offenders.first().cloned() else {
            return true;
        };
        let name = d.vars.get(v).cloned().unwrap_or_default();
        let mut diag = Diagnostic::new(
            DiagKind::UnsafeRule,
            Severity::Error,
            &self.source,
            span,
            format!("unsafe rule: variable `{name}` in {place} is bound by no positive atom"),
        )
        .with_label(format!("`{name}` ranges over everything here"));
        for (v2, sp2, place2) in offenders.iter().skip(1) {
            let n2 = d.vars.get(*v2).cloned().unwrap_or_default();
            diag = diag.with_related(*sp2, format!("`{n2}` in {place2} is unbound too"));
        }
        // How the reference's `¬P` → `NotP` rewriting treated this rule.
        let help = match negs.first() {
            Some(a) if positives.is_empty() => {
                let not_name = format!("Not{}", a.pred);
                let how = if self.schema.get(&not_name).is_some() {
                    format!(
                        "the reference rewrote `¬{}` into the base predicate `{not_name}`, which hid this; ",
                        a.pred
                    )
                } else {
                    format!(
                        "under the reference's `¬{0}` → `{not_name}` rewriting this rule is dead: nothing produces `{not_name}`; ",
                        a.pred
                    )
                };
                let written = self
                    .source
                    .text
                    .get(a.span.start..a.span.end)
                    .unwrap_or(&a.pred)
                    .to_string();
                format!(
                    "{how}add a positive atom that binds `{name}`, e.g. `Vehicles({name}) ∧ ¬{written}`"
                )
            }
            _ => format!("add a positive atom that binds `{name}` to the body"),
        };
        diag = diag.with_help(help);
        self.diags.push(diag);
        false
    }

    fn finish(mut self) -> (Arc<Schema>, Program, Vec<Diagnostic>) {
        let parsed = std::mem::take(&mut self.rules);
        let drafts: Vec<Draft> = parsed.into_iter().filter_map(|p| self.draft(p)).collect();
        let declared: BTreeSet<String> = self.schema.predicates().map(|p| p.name.clone()).collect();
        let entry_names: BTreeSet<String> = drafts.iter().map(|d| d.entry.clone()).collect();
        // Rule heads define derived predicates (first head fixes the arity).
        for d in &drafts {
            for (h, neg) in &d.heads {
                if !*neg && self.schema.get(&h.pred).is_none() {
                    self.schema.insert(PredInfo {
                        name: h.pred.clone(),
                        arity: h.args.len(),
                        kind: PredKind::Derived,
                        group: Some(d.entry.clone()),
                        params: Vec::new(),
                        values: None,
                        phrases: Vec::new(),
                        value_phrases: BTreeMap::new(),
                        role: None,
                        frames: None,
                        sentence: None,
                        description: None,
                        span: Some(h.pred_span),
                    });
                }
            }
        }
        for meta in std::mem::take(&mut self.entry_meta) {
            let Some((kind, arity)) = self.schema.get(&meta.name).map(|p| (p.kind, p.arity)) else {
                continue;
            };
            let worded = !meta.phrases.is_empty();
            let sentence = self.fit_sentence(&meta.role, &meta.name, arity);
            let (role, frames) = self.fit_role(meta.role, &meta.name, (kind, arity), worded);
            if let Some(p) = self.schema.get_mut(&meta.name) {
                p.phrases.extend(meta.phrases);
                if p.description.is_none() {
                    p.description = meta.description;
                }
                // A declaration's own role comes first; the entry that
                // derives the predicate only fills in what it left open.
                p.role = p.role.or(role);
                p.frames = p.frames.or(frames);
                if p.sentence.is_none() {
                    p.sentence = sentence;
                }
            }
        }
        // Head names that match neither their entry nor a declaration: likely typos.
        for d in &drafts {
            for (h, neg) in &d.heads {
                if *neg
                    || h.pred == d.entry
                    || declared.contains(&h.pred)
                    || entry_names.contains(&h.pred)
                {
                    continue;
                }
                let close = crate::diag::did_you_mean(&h.pred, declared.iter().map(String::as_str));
                let mut diag = Diagnostic::new(
                    DiagKind::HeadMismatch,
                    Severity::Warning,
                    &self.source,
                    h.pred_span,
                    format!(
                        "rule head `{}` is neither its entry's name `{}` nor a declared predicate",
                        h.pred, d.entry
                    ),
                )
                .with_label("defines a new predicate");
                diag = match close {
                    Some(c) => diag.with_help(format!(
                        "`{}` and the declared `{c}` are different predicates; did you mean `{c}`?",
                        h.pred
                    )),
                    None => diag.with_help(format!(
                        "rename the head to `{}` or add an entry for `{}`",
                        d.entry, h.pred
                    )),
                };
                self.diags.push(diag);
            }
        }
        // Per-rule checks: schema, safety; each (head, disjunct) becomes one rule.
        let mut rules: Vec<SourceRule> = Vec::new();
        let mut seen: BTreeMap<String, Span> = BTreeMap::new();
        let schema_snapshot = self.schema.clone();
        for d in &drafts {
            let line = self.source.line_col(d.base.unwrap_or(d.node_span.start)).0;
            for (head, negated_head) in &d.heads {
                if *negated_head {
                    let diag = Diagnostic::new(
                        DiagKind::NegatedHead,
                        Severity::Warning,
                        &self.source,
                        head.span,
                        format!("`¬{}` in a rule head is not a Horn rule", head.pred),
                    )
                    .with_label("negated head")
                    .with_help(format!(
                        "kept as an integrity constraint: after reasoning, every `{}` fact that satisfies the body is reported as a violation; nothing is derived",
                        head.pred
                    ));
                    self.diags.push(diag);
                }
                for body in &d.bodies {
                    let mut ok = true;
                    let mut local = Vec::new();
                    ok &= schema_snapshot.check_atom(head, &self.source, &mut local);
                    for l in body {
                        if let Literal::Pos(a) | Literal::Neg(a) = l {
                            ok &= schema_snapshot.check_atom(a, &self.source, &mut local);
                        }
                    }
                    self.diags.append(&mut local);
                    if !ok || !self.check_safety(d, head, *negated_head, body) {
                        continue;
                    }
                    let key = canonical(head, *negated_head, body, &d.vars);
                    if let Some(first) = seen.get(&key) {
                        let diag = Diagnostic::new(
                            DiagKind::DuplicateRule,
                            Severity::Warning,
                            &self.source,
                            d.base
                                .map_or(d.node_span, |b| Span::new(b, b + d.text.len())),
                            format!("duplicate rule for `{}`; the copy is ignored", head.pred),
                        )
                        .with_label("same rule again")
                        .with_related(*first, "first written here");
                        self.diags.push(diag);
                        continue;
                    }
                    seen.insert(
                        key,
                        d.base
                            .map_or(d.node_span, |b| Span::new(b, b + d.text.len())),
                    );
                    rules.push(SourceRule {
                        source: RuleSource {
                            entry: d.entry.clone(),
                            text: d.text.clone(),
                            line,
                            span: d
                                .base
                                .map_or(d.node_span, |b| Span::new(b, b + d.text.len())),
                        },
                        head: head.clone(),
                        body: body.clone(),
                        vars: d.vars.clone(),
                        constraint: *negated_head,
                    });
                }
            }
        }
        self.negation_cycles(&mut rules);
        self.dead_rules(&rules);
        // Base predicates named `NotP` encode negation as facts (the reference's quirk).
        let names: Vec<(String, Option<Span>)> = self
            .schema
            .predicates()
            .filter(|p| p.kind == PredKind::Atomic)
            .map(|p| (p.name.clone(), p.span))
            .collect();
        for (n, span) in names {
            if let Some(rest) = n.strip_prefix("Not")
                && rest.chars().next().is_some_and(char::is_uppercase)
                && self.schema.get(rest).is_some()
            {
                let diag = Diagnostic::new(
                        DiagKind::NegationAsPredicate,
                        Severity::Warning,
                        &self.source,
                        span.unwrap_or_default(),
                        format!("`{n}` encodes negation as a base predicate"),
                    )
                    .with_label(format!("a separate fact, unrelated to `{rest}` for the reasoner"))
                    .with_help(format!(
                        "the world is closed: write `¬{rest}(..)` in rules and queries; `{n}` facts can contradict `{rest}` facts"
                    ));
                self.diags.push(diag);
            }
        }
        let schema = Arc::new(self.schema);
        let program = Program::build(Arc::clone(&schema), rules);
        (schema, program, self.diags)
    }

    /// Drops (and reports) every rule that negates a predicate of its own
    /// recursive component: such programs have no stratification.
    fn negation_cycles(&mut self, rules: &mut Vec<SourceRule>) {
        let names: Vec<String> = self.schema.predicates().map(|p| p.name.clone()).collect();
        let index: BTreeMap<&str, usize> = names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.as_str(), i))
            .collect();
        let mut edges: Vec<Vec<(usize, usize)>> = vec![Vec::new(); names.len()]; // head -> (body pred, rule)
        for (ri, r) in rules.iter().enumerate() {
            if r.constraint {
                continue;
            }
            let Some(&h) = index.get(r.head.pred.as_str()) else {
                continue;
            };
            for l in &r.body {
                if let Literal::Pos(a) | Literal::Neg(a) = l
                    && let Some(&b) = index.get(a.pred.as_str())
                {
                    edges[h].push((b, ri));
                }
            }
        }
        let plain: Vec<Vec<usize>> = edges
            .iter()
            .map(|e| e.iter().map(|(b, _)| *b).collect())
            .collect();
        let comp = crate::program::scc_ids(&plain);
        let mut drop = BTreeSet::new();
        for (ri, r) in rules.iter().enumerate() {
            if r.constraint {
                continue;
            }
            let Some(&h) = index.get(r.head.pred.as_str()) else {
                continue;
            };
            for l in &r.body {
                let Literal::Neg(a) = l else { continue };
                let Some(&b) = index.get(a.pred.as_str()) else {
                    continue;
                };
                if comp.get(b) != comp.get(h) {
                    continue;
                }
                // Show the cycle: head ⇒ ¬b ⇒ … ⇒ head (shortest path b ⇝ head).
                let path = shortest_path(&edges, b, h).unwrap_or_default();
                let mut cycle = format!("{} ⇐ ¬{}", names[h], names[b]);
                let mut related = Vec::new();
                let mut cur = b;
                for (next, rule) in &path {
                    cycle.push_str(&format!(" ⇐ {}", names[*next]));
                    if let Some(rr) = rules.get(*rule) {
                        related.push((
                            rr.source.span,
                            format!("`{}` depends on `{}` here", names[cur], names[*next]),
                        ));
                    }
                    cur = *next;
                }
                let mut diag = Diagnostic::new(
                    DiagKind::NegationCycle,
                    Severity::Error,
                    &self.source,
                    a.span,
                    format!("negation through recursion: `{}` depends on its own negation", names[h]),
                )
                .with_label(format!("cycle: {cycle}"))
                .with_help("no stratification exists; break the cycle or replace the negation by a positive predicate");
                for (sp, t) in related {
                    diag = diag.with_related(sp, t);
                }
                self.diags.push(diag);
                drop.insert(ri);
            }
        }
        let mut i = 0;
        rules.retain(|_| {
            let keep = !drop.contains(&i);
            i += 1;
            keep
        });
    }

    /// Warns about rules whose body needs a predicate nothing can produce
    /// (a derived predicate all of whose rules were left out or are dead).
    fn dead_rules(&mut self, rules: &[SourceRule]) {
        let mut producible: BTreeSet<String> = self
            .schema
            .predicates()
            .filter(|p| p.kind != PredKind::Derived)
            .map(|p| p.name.clone())
            .collect();
        loop {
            let mut changed = false;
            for r in rules.iter().filter(|r| !r.constraint) {
                if producible.contains(&r.head.pred) {
                    continue;
                }
                let ok = r.body.iter().all(|l| match l {
                    Literal::Pos(a) => producible.contains(&a.pred),
                    _ => true,
                });
                if ok {
                    producible.insert(r.head.pred.clone());
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        for r in rules {
            for l in &r.body {
                let Literal::Pos(a) = l else { continue };
                if producible.contains(&a.pred) {
                    continue;
                }
                let diag = Diagnostic::new(
                    DiagKind::DeadRule,
                    Severity::Warning,
                    &self.source,
                    a.pred_span,
                    format!("dead rule: nothing can produce `{}`, so this rule never fires", a.pred),
                )
                .with_label(format!("no fact source and no working rule for `{}`", a.pred))
                .with_help(format!("fix the rules for `{}` (see the errors above) or declare it as an atomic predicate", a.pred));
                self.diags.push(diag);
                break;
            }
        }
    }
}

/// Breadth-first path from `from` to `to` along head→body edges, as
/// (next predicate, rule index) steps.
fn shortest_path(
    edges: &[Vec<(usize, usize)>],
    from: usize,
    to: usize,
) -> Option<Vec<(usize, usize)>> {
    let mut prev: Vec<Option<(usize, usize)>> = vec![None; edges.len()];
    let mut seen = vec![false; edges.len()];
    let mut queue = std::collections::VecDeque::from([from]);
    *seen.get_mut(from)? = true;
    while let Some(n) = queue.pop_front() {
        if n == to {
            let mut path = Vec::new();
            let mut cur = to;
            while cur != from {
                let (p, rule) = prev[cur]?;
                path.push((cur, rule));
                cur = p;
            }
            path.reverse();
            return Some(path);
        }
        for &(m, rule) in edges.get(n)? {
            if !seen[m] {
                seen[m] = true;
                prev[m] = Some((n, rule));
                queue.push_back(m);
            }
        }
    }
    None
}

/// A text key equal for rules that differ only in body order.
fn canonical(head: &Atom, negated: bool, body: &[Literal], vars: &[String]) -> String {
    let arg = |a: &Arg| match a {
        Arg::Var(v) => format!("?{}", vars.get(*v).map_or("", String::as_str)),
        Arg::Const(c) => c.clone(),
    };
    let atom = |a: &Atom| {
        format!(
            "{}({})",
            a.pred,
            a.args.iter().map(arg).collect::<Vec<_>>().join(",")
        )
    };
    let mut lits: Vec<String> = body
        .iter()
        .map(|l| match l {
            Literal::Pos(a) => atom(a),
            Literal::Neg(a) => format!("¬{}", atom(a)),
            Literal::Cmp {
                left,
                right,
                negated,
                ..
            } => {
                format!(
                    "{}{}{}",
                    arg(left),
                    if *negated { "≠" } else { "=" },
                    arg(right)
                )
            }
        })
        .collect();
    lits.sort();
    lits.dedup();
    format!(
        "{}{} :- {}",
        if negated { "¬" } else { "" },
        atom(head),
        lits.join(", ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(src: &str) -> LogicPad {
        match LogicPad::parse(src, "roles.yaml", false) {
            Ok(p) => p,
            Err(e) => panic!("{e}"),
        }
    }

    fn bad_roles(pad: &LogicPad) -> Vec<String> {
        pad.diagnostics()
            .iter()
            .filter(|d| d.kind == DiagKind::BadRole)
            .map(Diagnostic::summary)
            .collect()
    }

    const ROLES: &str = "atomic_predicates:
  objects:
    - predicate: Cone(x)
      role: class
    - predicate: Parked(x)
      role: property
      phrases: [parked]
    - predicate: Appear(x)
      role: property
      frames: initial
    - Moving(x)
functions:
  Place:
    predicate: Place(x, p)
    role: location
    frames: last
    values: [Left]
derived_predicates:
  - name: Near
    role: relation
    logic: \"∀x,y : Cone(x) ∧ Cone(y) ==> Near(x, y)\"
";

    #[test]
    fn roles_and_frames_are_read_from_every_kind_of_declaration() {
        let pad = load(ROLES);
        assert!(pad.diagnostics().is_empty(), "{:?}", bad_roles(&pad));
        let s = pad.schema();
        assert_eq!(s.role("Cone"), Some(Role::Class));
        assert_eq!(s.role("Parked"), Some(Role::Property));
        assert_eq!(s.role("Moving"), None);
        assert_eq!(s.role("Place"), Some(Role::Location));
        assert_eq!(s.role("Near"), Some(Role::Relation));
        assert_eq!(
            s.get("Appear").and_then(|p| p.frames),
            Some(Frames::Initial)
        );
        assert_eq!(s.get("Place").and_then(|p| p.frames), Some(Frames::Last));
    }

    #[test]
    fn an_unknown_role_is_an_error_at_its_line_and_column() {
        let src = ROLES.replace("role: class", "role: noun");
        let pad = load(&src);
        let found = bad_roles(&pad);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(
            found[0].starts_with("roles.yaml:4:13: error[logicpad::bad_role]: unknown role `noun`"),
            "{found:?}"
        );
        // The declaration stays; only the role is left out.
        assert_eq!(pad.schema().arity("Cone"), Some(1));
        assert_eq!(pad.schema().role("Cone"), None);
        // Strict loading fails on it.
        assert!(LogicPad::parse(&src, "roles.yaml", true).is_err());
        let typo = load(&ROLES.replace("role: relation", "role: relatoin"));
        let d = typo
            .diagnostics()
            .iter()
            .find(|d| d.kind == DiagKind::BadRole)
            .map(|d| d.help.clone().unwrap_or_default());
        assert!(
            d.as_deref()
                .is_some_and(|h| h.starts_with("did you mean `relation`?")),
            "{d:?}"
        );
    }

    #[test]
    fn a_role_that_does_not_fit_is_left_out() {
        // A binary derived predicate cannot be a class, a predicate cannot
        // hold a function's role, a function cannot be a relation.
        let src = ROLES
            .replace("role: class\n", "role: class\n      frames: last\n")
            .replace("role: relation", "role: class")
            .replace("role: property\n      phrases", "role: type\n      phrases")
            .replace("role: location", "role: relation");
        let pad = load(&src);
        let found = bad_roles(&pad);
        assert_eq!(found.len(), 4, "{found:?}");
        assert!(
            found
                .iter()
                .any(|f| f.contains("`Near` cannot have the role `class`"))
        );
        assert!(
            found
                .iter()
                .any(|f| f.contains("`Parked` cannot have the role `type`"))
        );
        assert!(
            found
                .iter()
                .any(|f| f.contains("`Place` cannot have the role `relation`"))
        );
        // Frames with a role that takes none: a warning.
        assert!(
            found
                .iter()
                .any(|f| f.contains("warning") && f.contains("`frames` means nothing")),
            "{found:?}"
        );
        assert_eq!(pad.schema().get("Cone").and_then(|p| p.frames), None);
        // A dropped role leaves its frames to the translator's inference.
        assert_eq!(
            pad.schema().get("Place").and_then(|p| p.frames),
            Some(Frames::Last)
        );
        assert_eq!(pad.schema().role("Near"), None);
        assert_eq!(pad.schema().role("Parked"), None);
        // Bad frames are an error; phrases of a silent predicate a warning.
        let src = ROLES.replace("frames: initial", "frames: first").replace(
            "role: property\n      phrases",
            "role: silent\n      phrases",
        );
        let found = bad_roles(&load(&src));
        assert_eq!(found.len(), 2, "{found:?}");
        assert!(
            found
                .iter()
                .any(|f| f.contains("error") && f.contains("`frames` must be"))
        );
        assert!(
            found
                .iter()
                .any(|f| f.contains("warning") && f.contains("`Parked` is silent")),
            "{found:?}"
        );
    }

    #[test]
    fn the_builtin_logicpad_declares_a_role_for_every_entry() {
        let pad = LogicPad::builtin();
        assert!(pad.diagnostics().is_empty(), "{:?}", pad.diagnostics());
        let missing: Vec<&str> = pad
            .schema()
            .predicates()
            .filter(|p| p.role.is_none())
            .map(|p| p.name.as_str())
            .collect();
        assert!(missing.is_empty(), "no role: {missing:?}");
        // "on" is a word, not YAML 1.1's `true`.
        assert!(pad.schema().phrases("On").iter().any(|p| p == "on"));
    }
}
