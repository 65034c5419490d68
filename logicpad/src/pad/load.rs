//! The YAML walk: top-level sections, atomic predicates, functions and
//! derived entries, declared into the [`Schema`]; each rule's FOL text is
//! parsed into a `Parsed` for the later stages (`rules`, `check`).

use super::Loader;
use super::roles::RoleKeys;
use crate::diag::{DiagKind, Diagnostic, Severity, Span};
use crate::fol::{self, Formula};
use crate::schema::{PredInfo, PredKind};
use crate::yaml::{self, Node, Value};
use std::collections::BTreeMap;

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

/// A rule as parsed from one `logic` string, before the semantic checks.
pub(super) struct Parsed {
    pub(super) entry: String,
    pub(super) text: String,
    pub(super) node_span: Span,
    /// Offset of the formula text in the file (None: spans point at the node).
    pub(super) base: Option<usize>,
    pub(super) formula: Formula,
}

/// What a derived entry says about its predicate besides the rules. Kept
/// until the rule heads are known (they give the arity a role must fit);
/// attached in `finish`.
pub(super) struct EntryMeta {
    pub(super) name: String,
    pub(super) phrases: Vec<String>,
    pub(super) description: Option<String>,
    pub(super) role: RoleKeys,
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
    pub(super) fn document(&mut self, root: &Node) {
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
