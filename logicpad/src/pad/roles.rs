//! The `role:`, `frames:` and `sentence:` keys of a declaration: read while
//! walking the YAML, then fitted to the predicate's kind and arity once known.
//! Separate because the same checks serve declarations and derived entries.

use super::Loader;
use crate::diag::{DiagKind, Severity, Span};
use crate::schema::{Frames, PredKind, Role};
use crate::yaml::Node;

/// The `role:` and `frames:` of a declaration, each with where it was
/// written, once their names are known to be valid.
#[derive(Default)]
pub(super) struct RoleKeys {
    role: Option<(Role, Span)>,
    frames: Option<(Frames, Span)>,
    /// `sentence:`, the C3 template, with where it was written.
    sentence: Option<(String, Span)>,
}

impl RoleKeys {
    pub(super) fn is_empty(&self) -> bool {
        self.role.is_none() && self.frames.is_none() && self.sentence.is_none()
    }
}

impl Loader {
    /// Reads `role:` and `frames:` from a declaration; an unknown name is
    /// reported and left out, so the translator infers that part instead.
    pub(super) fn role_keys(&mut self, item: &Node) -> RoleKeys {
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
    pub(super) fn fit_sentence(
        &mut self,
        keys: &RoleKeys,
        name: &str,
        arity: usize,
    ) -> Option<String> {
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
    pub(super) fn fit_role(
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diag::Diagnostic;
    use crate::pad::LogicPad;

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
