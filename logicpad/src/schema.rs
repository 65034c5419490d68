//! The vocabulary of a LogicPad: which predicates exist, their arity, kind,
//! producer group, declared function values, English phrases and the role
//! each plays in questions.

use crate::diag::{DiagKind, Diagnostic, Severity, SourceFile, Span, did_you_mean};
use crate::fol::{Arg, Atom};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Where a predicate's facts come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum PredKind {
    /// Produced by perception (`atomic_predicates`).
    Atomic,
    /// A function `F(x, v)` whose value `v` comes from a declared list.
    Function,
    /// Produced by rules only (`derived_predicates`).
    Derived,
}

/// How the question translator reads a predicate: the `role:` key of a
/// declaration. A LogicPad that declares roles says what its words are; one
/// that does not leaves the translator to infer them from names and groups.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Role {
    /// A unary noun that heads an object phrase: "pole", "pedestrian".
    Class,
    /// A unary state or action said of an object: "parked", "disappear".
    Property,
    /// A binary relation between two objects: "getting closer to", "on".
    Relation,
    /// A function whose values are nouns: `TypeOf(x, Car)` for "car".
    Type,
    /// A function whose values are adjectives: `ColorOf(x, White)` for "white".
    Attribute,
    /// A function whose values are places: `InitialLocation(x, Left)`.
    Location,
    /// Known to rules and queries but never the reading of a question's
    /// words: an alias (`IsCar`), a helper, a tracker predicate that a
    /// derived one speaks for (`Moving` behind `Move`).
    Silent,
}

impl Role {
    /// Every role, in the order the documentation lists them.
    pub const ALL: [Role; 7] = [
        Role::Class,
        Role::Property,
        Role::Relation,
        Role::Type,
        Role::Attribute,
        Role::Location,
        Role::Silent,
    ];

    /// The role as written in a LogicPad (`class`, `property`, …).
    pub fn name(self) -> &'static str {
        match self {
            Role::Class => "class",
            Role::Property => "property",
            Role::Relation => "relation",
            Role::Type => "type",
            Role::Attribute => "attribute",
            Role::Location => "location",
            Role::Silent => "silent",
        }
    }

    /// The role written `name`, if it is one.
    pub fn from_name(name: &str) -> Option<Role> {
        Role::ALL.into_iter().find(|r| r.name() == name)
    }

    /// Why a predicate of this kind and arity cannot play the role, or
    /// `None` when it can. Functions hold the value roles (type, attribute,
    /// location); other predicates the object roles, by arity.
    pub fn misfit(self, kind: PredKind, arity: usize) -> Option<String> {
        let function = kind == PredKind::Function;
        match self {
            Role::Silent => None,
            Role::Type | Role::Attribute | Role::Location if !function => Some(format!(
                "role `{}` is for a function with a value list (declared under `functions:`)",
                self.name()
            )),
            Role::Type | Role::Attribute | Role::Location => None,
            Role::Class | Role::Property | Role::Relation if function => Some(format!(
                "a function's role is `type`, `attribute`, `location` or `silent`, not `{}`",
                self.name()
            )),
            Role::Class | Role::Property if arity != 1 => Some(format!(
                "role `{}` needs one argument, but the predicate has {arity}",
                self.name()
            )),
            Role::Relation if arity != 2 => Some(format!(
                "role `relation` needs two arguments, but the predicate has {arity}"
            )),
            Role::Class | Role::Property | Role::Relation => None,
        }
    }

    /// Whether `frames:` means anything for this role: the frames of a
    /// location, or of the places said with a property ("disappears from
    /// the left" is where the object was last).
    pub fn takes_frames(self) -> bool {
        matches!(self, Role::Property | Role::Location)
    }
}

/// Which frames of an object a place refers to: the `frames:` key of a
/// location function or a property.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Frames {
    /// The object's first frames in the window.
    Initial,
    /// The object's last frames in the window.
    Last,
}

impl Frames {
    /// As written in a LogicPad: `initial` or `last`.
    pub fn name(self) -> &'static str {
        match self {
            Frames::Initial => "initial",
            Frames::Last => "last",
        }
    }

    /// The frames written `name`, if they are.
    pub fn from_name(name: &str) -> Option<Frames> {
        [Frames::Initial, Frames::Last]
            .into_iter()
            .find(|f| f.name() == name)
    }
}

/// One predicate of a [`Schema`].
///
/// Invariant: for a [`PredKind::Function`], `values` is `Some` and the value
/// is the last argument; a `role`, when present, fits the kind and arity
/// ([`Role::misfit`] is `None`: the loader drops a role that does not).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PredInfo {
    /// Name, e.g. `ColorOf`.
    pub name: String,
    /// Number of arguments.
    pub arity: usize,
    /// Atomic, function or derived.
    pub kind: PredKind,
    /// Producer group (`semantic_segmentation`, `tracker`, `location`, …); for
    /// derived predicates the `name` of the entry that defines them.
    pub group: Option<String>,
    /// Parameter names as declared (`ColorOf(x, color)` → `["x", "color"]`).
    pub params: Vec<String>,
    /// Declared values of a function's last argument.
    pub values: Option<Vec<String>>,
    /// English phrases for the question translator.
    pub phrases: Vec<String>,
    /// English phrases per declared value (functions only).
    pub value_phrases: BTreeMap<String, Vec<String>>,
    /// The declared role in questions (`role:`); `None` when not declared.
    pub role: Option<Role>,
    /// The declared frames of a location or property (`frames:`).
    pub frames: Option<Frames>,
    /// How a fact of this predicate reads in a sentence (`sentence:`):
    /// `{x}` is the first argument, `{y}` the second ("{x} is on {y}"); an
    /// empty sentence says the fact is left unsaid (its converse says it).
    pub sentence: Option<String>,
    /// Free-text description, if given.
    pub description: Option<String>,
    /// Where it was declared (None for predicates that only appear as a rule head).
    pub span: Option<Span>,
}

/// All predicates a LogicPad knows, by name (sorted, so iteration is deterministic).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Schema {
    preds: BTreeMap<String, PredInfo>,
}

impl Schema {
    /// An empty schema.
    pub fn new() -> Schema {
        Schema::default()
    }
    /// Adds or replaces a predicate.
    pub fn insert(&mut self, info: PredInfo) {
        self.preds.insert(info.name.clone(), info);
    }
    /// Looks a predicate up.
    pub fn get(&self, name: &str) -> Option<&PredInfo> {
        self.preds.get(name)
    }
    /// Mutable access (loader only).
    pub(crate) fn get_mut(&mut self, name: &str) -> Option<&mut PredInfo> {
        self.preds.get_mut(name)
    }
    /// Arity of a predicate.
    pub fn arity(&self, name: &str) -> Option<usize> {
        self.preds.get(name).map(|p| p.arity)
    }
    /// Kind of a predicate.
    pub fn kind(&self, name: &str) -> Option<PredKind> {
        self.preds.get(name).map(|p| p.kind)
    }
    /// Declared values of a function.
    pub fn values(&self, name: &str) -> Option<&[String]> {
        self.preds.get(name).and_then(|p| p.values.as_deref())
    }
    /// English phrases of a predicate (empty when none were given).
    pub fn phrases(&self, name: &str) -> &[String] {
        self.preds.get(name).map_or(&[], |p| p.phrases.as_slice())
    }
    /// English phrases of one value of a function (empty when none were given).
    pub fn value_phrases(&self, function: &str, value: &str) -> &[String] {
        self.preds
            .get(function)
            .and_then(|p| p.value_phrases.get(value))
            .map_or(&[], |v| v.as_slice())
    }
    /// The declared role of a predicate (`None` when undeclared or unknown).
    pub fn role(&self, name: &str) -> Option<Role> {
        self.preds.get(name).and_then(|p| p.role)
    }
    /// Every predicate, sorted by name.
    pub fn predicates(&self) -> impl Iterator<Item = &PredInfo> + '_ {
        self.preds.values()
    }
    /// Number of predicates.
    pub fn len(&self) -> usize {
        self.preds.len()
    }
    /// True when no predicate is declared.
    pub fn is_empty(&self) -> bool {
        self.preds.is_empty()
    }
    /// The closest known predicate name, for "did you mean".
    pub fn suggest(&self, name: &str) -> Option<&str> {
        did_you_mean(name, self.preds.keys().map(String::as_str))
    }

    /// Checks one atom against the schema: unknown predicate (with a
    /// suggestion), arity, and constants outside a function's values.
    pub(crate) fn check_atom(
        &self,
        atom: &Atom,
        source: &Arc<SourceFile>,
        out: &mut Vec<Diagnostic>,
    ) -> bool {
        let Some(info) = self.get(&atom.pred) else {
            let mut d = Diagnostic::new(
                DiagKind::UnknownPredicate,
                Severity::Error,
                source,
                atom.pred_span,
                format!("unknown predicate `{}`", atom.pred),
            )
            .with_label("not declared anywhere in this LogicPad");
            d = match self.suggest(&atom.pred) {
                Some(s) => d.with_help(format!("did you mean `{s}`?")),
                None => d.with_help(
                    "declare it under `atomic_predicates`, `functions` or `derived_predicates`"
                        .to_string(),
                ),
            };
            out.push(d);
            return false;
        };
        if info.arity != atom.args.len() {
            let sig = if info.params.is_empty() {
                format!("{}/{}", info.name, info.arity)
            } else {
                format!("{}({})", info.name, info.params.join(", "))
            };
            out.push(
                Diagnostic::new(
                    DiagKind::ArityMismatch,
                    Severity::Error,
                    source,
                    atom.span,
                    format!(
                        "`{}` takes {} argument{}, but {} {} given",
                        atom.pred,
                        info.arity,
                        if info.arity == 1 { "" } else { "s" },
                        atom.args.len(),
                        if atom.args.len() == 1 { "is" } else { "are" }
                    ),
                )
                .with_label(format!(
                    "{} argument{} here",
                    atom.args.len(),
                    if atom.args.len() == 1 { "" } else { "s" }
                ))
                .with_help(format!("declared as `{sig}`")),
            );
            return false;
        }
        if let (Some(values), Some(Arg::Const(c))) = (&info.values, atom.args.last())
            && !values.iter().any(|v| v == c)
        {
            let span = atom.arg_spans.last().copied().unwrap_or(atom.span);
            let mut d = Diagnostic::new(
                DiagKind::UndeclaredValue,
                Severity::Error,
                source,
                span,
                format!("`{c}` is not a declared value of `{}`", atom.pred),
            )
            .with_label(format!("not among the values of `{}`", atom.pred));
            d = match did_you_mean(c, values.iter().map(String::as_str)) {
                Some(s) => d.with_help(format!(
                    "did you mean `{s}`? declared values: {}",
                    values.join(", ")
                )),
                None => d.with_help(format!(
                    "add `{c}` to the `values` of `{}`; declared values: {}",
                    atom.pred,
                    values.join(", ")
                )),
            };
            out.push(d);
            return false;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn role_names_round_trip_and_roles_fit_by_kind_and_arity() {
        for r in Role::ALL {
            assert_eq!(Role::from_name(r.name()), Some(r));
        }
        assert_eq!(Role::from_name("noun"), None);
        assert_eq!(Frames::from_name("last"), Some(Frames::Last));
        assert_eq!(Frames::from_name("end"), None);
        assert_eq!(Role::Class.misfit(PredKind::Derived, 1), None);
        assert!(Role::Class.misfit(PredKind::Atomic, 2).is_some());
        assert_eq!(Role::Relation.misfit(PredKind::Atomic, 2), None);
        assert!(Role::Relation.misfit(PredKind::Derived, 1).is_some());
        assert_eq!(Role::Type.misfit(PredKind::Function, 2), None);
        assert!(Role::Type.misfit(PredKind::Atomic, 2).is_some());
        assert!(Role::Property.misfit(PredKind::Function, 2).is_some());
        assert_eq!(Role::Silent.misfit(PredKind::Function, 2), None);
        assert_eq!(Role::Silent.misfit(PredKind::Atomic, 3), None);
        assert!(Role::Location.takes_frames() && Role::Property.takes_frames());
        assert!(!Role::Class.takes_frames());
    }
}
