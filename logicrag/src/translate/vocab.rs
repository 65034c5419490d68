//! The words a question may use: predicates and functions with their English
//! phrases, and the grammatical role each one plays.
//!
//! A [`Vocabulary`] is data, not grammar: the translator's closed-class
//! grammar (determiners, auxiliaries, prepositions, negation) is fixed, while
//! every content word comes from here. An expert who adds a predicate with a
//! phrase makes it askable without touching the parser.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::OnceLock;

use thiserror::Error;

/// When in a window a location holds: at the object's first or last frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Anchor {
    /// The object's first frames in the window (`InitialLocation`).
    Initial,
    /// The object's last frames in the window (`LastLocation`).
    Last,
}

/// How the grammar uses a predicate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PredicateRole {
    /// A unary noun that heads an object phrase: "pole", "pedestrian".
    Class,
    /// A unary state or action said of an object: "moving", "parked", "disappear".
    Property,
    /// A binary relation between two objects: "getting closer to", "on".
    Relation,
    /// A predicate that has no words of its own (an `Is*` alias, a helper);
    /// it is known so that queries naming it are valid, but never produced.
    Silent,
}

impl PredicateRole {
    /// The role as LogicPad.yaml spells it.
    pub fn name(self) -> &'static str {
        match self {
            PredicateRole::Class => "class",
            PredicateRole::Property => "property",
            PredicateRole::Relation => "relation",
            PredicateRole::Silent => "silent",
        }
    }
}

/// How the grammar uses a function (a binary predicate whose second argument
/// is one of a declared list of values).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FunctionRole {
    /// Values are nouns that head an object phrase: `TypeOf(x, Car)` for "car".
    Type,
    /// Values are adjectives before the noun: `ColorOf(x, White)` for "white".
    Attribute,
    /// Values are places; the anchor says which frames the place refers to.
    Location(Anchor),
}

/// One predicate of a vocabulary.
///
/// Invariant (checked by [`VocabularyBuilder::build`]): `name` is an
/// identifier starting with an ASCII letter; a `Class` or `Property` has
/// arity 1 and a `Relation` arity 2 (a `Silent` predicate any arity).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PredicateSpec {
    /// The predicate's name as written in queries, e.g. `ConstantSpeed`.
    pub name: String,
    /// Number of arguments.
    pub arity: usize,
    /// Grammatical role.
    pub role: PredicateRole,
    /// English phrases; when none are given the default phrase is the name
    /// split at case boundaries ("constant speed"), except for `Silent`.
    pub phrases: Vec<String>,
    /// For properties whose location complement has a fixed time: the place
    /// an object disappears from is its last location, whatever the
    /// preposition says.
    pub anchor: Option<Anchor>,
}

/// One value of a function, with its phrases.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ValueSpec {
    /// The value constant, CamelCase, e.g. `NearLeft`.
    pub name: String,
    /// English phrases; the default is the name split at case boundaries.
    pub phrases: Vec<String>,
}

/// One function (`TypeOf`, `ColorOf`, `InitialLocation`, ...).
///
/// Invariant: `values` is non-empty and its names are distinct.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FunctionSpec {
    /// The function's name, e.g. `ColorOf`.
    pub name: String,
    /// Grammatical role of its values.
    pub role: FunctionRole,
    /// The declared values.
    pub values: Vec<ValueSpec>,
    /// Nouns that ask for the value rather than state it ("colour" in
    /// "What colour is the van?"); only a `Type` or `Attribute` function
    /// uses them.
    pub nouns: Vec<String>,
}

/// Errors found while building a vocabulary.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum VocabularyError {
    /// Occurs when a predicate, function or value name is not an identifier
    /// (letters, digits and `_`, starting with a letter).
    #[error("'{0}' is not a valid name (letters, digits and _, starting with a letter)")]
    BadName(String),
    /// Occurs when the same predicate or function name is declared twice.
    #[error("'{0}' is declared twice")]
    Duplicate(String),
    /// Occurs when a predicate's arity does not fit its role (a class or
    /// property must be unary, a relation binary).
    #[error("predicate '{name}' has arity {arity}, which does not fit its role `{}`", .role.name())]
    BadArity {
        /// The predicate.
        name: String,
        /// The declared arity.
        arity: usize,
        /// The declared role.
        role: PredicateRole,
    },
    /// Occurs when nouns are given for a function that was not declared.
    #[error("'{0}' is given value nouns but is not a declared function")]
    UnknownFunction(String),
    /// Occurs when a function declares no values or the same value twice.
    #[error("function '{function}' has a bad value list: {why}")]
    BadValues {
        /// The function.
        function: String,
        /// What is wrong.
        why: String,
    },
}

/// A checked set of predicates and functions with their phrases.
///
/// Invariant: names are distinct across predicates and functions, and every
/// spec satisfies its own invariant. Predicates and functions keep the order
/// in which they were declared; that order breaks ties between equal phrases
/// (the first declaration wins), so classes are declared before types.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Vocabulary {
    predicates: Vec<PredicateSpec>,
    functions: Vec<FunctionSpec>,
    /// Property → the classes every rule for it requires of its object
    /// (see [`Vocabulary::with_rules`]); empty until rules are given.
    guards: BTreeMap<String, Vec<String>>,
}

/// Collects predicates and functions, then checks them in [`build`](Self::build).
#[derive(Debug, Clone, Default)]
pub struct VocabularyBuilder {
    predicates: Vec<PredicateSpec>,
    functions: Vec<FunctionSpec>,
    /// Names given nouns without being declared as functions.
    unknown: Vec<String>,
}

fn owned(phrases: &[&str]) -> Vec<String> {
    phrases.iter().map(|p| (*p).to_string()).collect()
}

impl VocabularyBuilder {
    /// Adds a predicate with an explicit role.
    pub(crate) fn predicate_with_role(
        mut self,
        name: &str,
        arity: usize,
        role: PredicateRole,
        phrases: &[&str],
    ) -> Self {
        self.predicates.push(PredicateSpec {
            name: name.to_string(),
            arity,
            role,
            phrases: owned(phrases),
            anchor: None,
        });
        self
    }

    /// Adds a predicate; a binary one is a relation, a unary one a property.
    pub fn predicate(self, name: &str, arity: usize, phrases: &[&str]) -> Self {
        let role = if arity == 2 {
            PredicateRole::Relation
        } else {
            PredicateRole::Property
        };
        self.predicate_with_role(name, arity, role, phrases)
    }

    /// Adds a unary class noun ("pole", "pedestrian").
    pub fn class(self, name: &str, phrases: &[&str]) -> Self {
        self.predicate_with_role(name, 1, PredicateRole::Class, phrases)
    }

    /// Adds a unary property ("moving", "parked").
    pub fn property(self, name: &str, phrases: &[&str]) -> Self {
        self.predicate_with_role(name, 1, PredicateRole::Property, phrases)
    }

    /// Adds a unary property whose location complement always refers to the
    /// given frames ("disappears from the left" is where it was last).
    pub fn anchored_property(mut self, name: &str, anchor: Anchor, phrases: &[&str]) -> Self {
        self.predicates.push(PredicateSpec {
            name: name.to_string(),
            arity: 1,
            role: PredicateRole::Property,
            phrases: owned(phrases),
            anchor: Some(anchor),
        });
        self
    }

    /// Adds a binary relation ("getting closer to").
    pub fn relation(self, name: &str, phrases: &[&str]) -> Self {
        self.predicate_with_role(name, 2, PredicateRole::Relation, phrases)
    }

    /// Adds a predicate given in full.
    pub(crate) fn predicate_spec(mut self, spec: PredicateSpec) -> Self {
        self.predicates.push(spec);
        self
    }

    /// Adds a predicate that the translator knows but never produces.
    pub fn silent(self, name: &str, arity: usize) -> Self {
        self.predicate_with_role(name, arity, PredicateRole::Silent, &[])
    }

    /// Adds a function with an explicit role; `values` pairs a value name with
    /// its phrases (empty: the default phrase).
    pub fn function_with_role(
        mut self,
        name: &str,
        role: FunctionRole,
        values: &[(&str, &[&str])],
    ) -> Self {
        self.functions.push(FunctionSpec {
            name: name.to_string(),
            role,
            values: values
                .iter()
                .map(|(v, ps)| ValueSpec {
                    name: (*v).to_string(),
                    phrases: owned(ps),
                })
                .collect(),
            nouns: Vec::new(),
        });
        self
    }

    /// Gives the function `name`, declared before, the nouns that ask for
    /// its value ("colour", "type"). [`build`](Self::build) reports a name
    /// that was never declared as a function.
    pub(crate) fn function_nouns(mut self, name: &str, nouns: &[&str]) -> Self {
        match self.functions.iter_mut().find(|f| f.name == name) {
            Some(f) => f.nouns.extend(owned(nouns)),
            None => self.unknown.push(name.to_string()),
        }
        self
    }

    /// Adds a function, guessing its role from its name (see
    /// `function_role_for`).
    pub fn function(self, name: &str, values: &[(&str, &[&str])]) -> Self {
        let role = function_role_for(name);
        self.function_with_role(name, role, values)
    }

    /// Checks names, arities and values.
    ///
    /// # Errors
    /// [`VocabularyError`] for the first problem found.
    pub fn build(self) -> Result<Vocabulary, VocabularyError> {
        if let Some(name) = self.unknown.first() {
            return Err(VocabularyError::UnknownFunction(name.clone()));
        }
        let mut seen = BTreeSet::new();
        for p in &self.predicates {
            check_name(&p.name)?;
            if !seen.insert(p.name.clone()) {
                return Err(VocabularyError::Duplicate(p.name.clone()));
            }
            let fits = match p.role {
                PredicateRole::Class | PredicateRole::Property => p.arity == 1,
                PredicateRole::Relation => p.arity == 2,
                PredicateRole::Silent => true,
            };
            if !fits {
                return Err(VocabularyError::BadArity {
                    name: p.name.clone(),
                    arity: p.arity,
                    role: p.role,
                });
            }
        }
        for f in &self.functions {
            check_name(&f.name)?;
            if !seen.insert(f.name.clone()) {
                return Err(VocabularyError::Duplicate(f.name.clone()));
            }
            if f.values.is_empty() {
                return Err(VocabularyError::BadValues {
                    function: f.name.clone(),
                    why: "no values".into(),
                });
            }
            let mut vs = BTreeSet::new();
            for v in &f.values {
                check_name(&v.name)?;
                if !vs.insert(v.name.as_str()) {
                    return Err(VocabularyError::BadValues {
                        function: f.name.clone(),
                        why: format!("'{}' listed twice", v.name),
                    });
                }
            }
        }
        Ok(Vocabulary {
            predicates: self.predicates,
            functions: self.functions,
            guards: BTreeMap::new(),
        })
    }
}

/// The role a function gets when none is given: `TypeOf` (and any name
/// starting with `Type`) holds nouns, a name containing `Location` or
/// `Position` holds places (last frames when it starts with `Last`, `Final`
/// or `End`, first frames otherwise), anything else holds adjectives.
pub(crate) fn function_role_for(name: &str) -> FunctionRole {
    if name.starts_with("Type") {
        FunctionRole::Type
    } else if name.contains("Location") || name.contains("Position") {
        if name.starts_with("Last") || name.starts_with("Final") || name.starts_with("End") {
            FunctionRole::Location(Anchor::Last)
        } else {
            FunctionRole::Location(Anchor::Initial)
        }
    } else {
        FunctionRole::Attribute
    }
}

fn check_name(name: &str) -> Result<(), VocabularyError> {
    let mut chars = name.chars();
    let ok = chars.next().is_some_and(|c| c.is_ascii_alphabetic())
        && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
    if ok {
        Ok(())
    } else {
        Err(VocabularyError::BadName(name.to_string()))
    }
}

/// Splits a CamelCase name into lower-case words: `ConstantSpeed` →
/// "constant speed", `SUV` → "suv", `PoliceCar` → "police car",
/// `DistanceDecreasesToZero` → "distance decreases to zero".
pub(crate) fn default_phrase(name: &str) -> String {
    camel_words(name)
        .iter()
        .map(|w| w.to_lowercase())
        .collect::<Vec<_>>()
        .join(" ")
}

/// The words of a CamelCase name, case kept: `PoliceCar` → `Police`,
/// `Car`; a run of capitals is one word (`SUVLarge` → `SUV`, `Large`;
/// plural `SUVs` stays whole); spaces and underscores separate too. The
/// translator's default phrases and the RAG context's nouns both read
/// names through it.
pub(crate) fn camel_words(name: &str) -> Vec<String> {
    let chars: Vec<char> = name.chars().collect();
    let mut words = Vec::new();
    let mut word = String::new();
    for (i, &c) in chars.iter().enumerate() {
        if c.is_whitespace() || c == '_' {
            if !word.is_empty() {
                words.push(std::mem::take(&mut word));
            }
            continue;
        }
        let prev = i.checked_sub(1).and_then(|p| chars.get(p));
        let next = chars.get(i + 1);
        // A capital run ends before a capital followed by lower case
        // (`SUVLarge` → `SUV` `Large`), but not before a plural `s`
        // (`SUVs`).
        let plural_s = |n: &char| *n == 's' && chars.get(i + 2).is_none_or(|m| m.is_uppercase());
        let starts_word = c.is_uppercase()
            && prev.is_some_and(|p| {
                p.is_lowercase()
                    || p.is_ascii_digit()
                    || (p.is_uppercase() && next.is_some_and(|n| n.is_lowercase() && !plural_s(n)))
            });
        if starts_word && !word.is_empty() {
            words.push(std::mem::take(&mut word));
        }
        word.push(c);
    }
    if !word.is_empty() {
        words.push(word);
    }
    words
}

impl Vocabulary {
    /// Starts an empty vocabulary.
    pub fn builder() -> VocabularyBuilder {
        VocabularyBuilder::default()
    }

    /// The predicates, in declaration order.
    pub fn predicates(&self) -> &[PredicateSpec] {
        &self.predicates
    }

    /// The functions, in declaration order.
    pub fn functions(&self) -> &[FunctionSpec] {
        &self.functions
    }

    /// The predicate with this name.
    pub fn predicate(&self, name: &str) -> Option<&PredicateSpec> {
        self.predicates.iter().find(|p| p.name == name)
    }

    /// The function with this name.
    pub fn function(&self, name: &str) -> Option<&FunctionSpec> {
        self.functions.iter().find(|f| f.name == name)
    }

    /// The classes a property is defined for: every rule of the LogicPad
    /// given to [`Vocabulary::with_rules`] requires one of them of its
    /// object (`Cross`: `["Pedestrian"]`). Empty when the property holds
    /// of any object, or when no rules were given.
    pub fn guards(&self, name: &str) -> &[String] {
        self.guards.get(name).map_or(&[], Vec::as_slice)
    }

    /// This vocabulary with the guard classes of its properties taken from
    /// a LogicPad's rules, so that a property said of an object of another
    /// class is refused rather than answered "no" ("is the car crossing?":
    /// `Cross` is derived for pedestrians only).
    ///
    /// A unary derived predicate with the role `property` is guarded when
    /// every rule for it (disjunctions are split into several rules) has a
    /// positive body atom `C(x)` on its head variable with `C` a class of
    /// this vocabulary or `Ego`; its guards are the union of those classes,
    /// a derived class (`IsPerson`) standing for its own guards (`Person`,
    /// `Pedestrian`). One rule without such an atom leaves it unguarded.
    #[must_use]
    pub fn with_rules(mut self, program: &logicpad::Program) -> Vocabulary {
        let mut guards = BTreeMap::new();
        for p in &self.predicates {
            if p.role == PredicateRole::Property
                && p.arity == 1
                && let Some(g) = self.rule_guards(program, &p.name, 0)
            {
                guards.insert(p.name.clone(), g);
            }
        }
        self.guards = guards;
        self
    }

    /// The guard classes of the unary predicate `name` in `program`, if
    /// every rule for it has some (`depth` bounds the expansion of derived
    /// classes).
    fn rule_guards(
        &self,
        program: &logicpad::Program,
        name: &str,
        depth: usize,
    ) -> Option<Vec<String>> {
        use logicpad::CArg;
        let id = program.pred_id(name)?;
        let mut out: Vec<String> = Vec::new();
        let mut rules = 0;
        for r in program.rules().iter().filter(|r| r.head.pred == id) {
            rules += 1;
            let [CArg::Var(v)] = r.head.args.as_slice() else {
                return None;
            };
            let mut found = false;
            for a in r.body.iter() {
                if !matches!(a.args.as_slice(), [CArg::Var(w)] if w == v) {
                    continue;
                }
                let Some(class) = program.pred_name(a.pred) else {
                    continue;
                };
                let is_class = class == "Ego"
                    || self
                        .predicate(class)
                        .is_some_and(|p| p.role == PredicateRole::Class);
                if !is_class {
                    continue;
                }
                found = true;
                let expanded = (depth < 4)
                    .then(|| self.rule_guards(program, class, depth + 1))
                    .flatten()
                    .unwrap_or_else(|| vec![class.to_string()]);
                for c in expanded {
                    if !out.contains(&c) {
                        out.push(c);
                    }
                }
            }
            if !found {
                return None;
            }
        }
        (rules > 0).then_some(out)
    }

    /// The project's canonical vocabulary: the built-in LogicPad's
    /// (`logicpad/LogicPad.yaml`), whose entries declare their roles and
    /// carry the English phrases of everyday driving questions. The YAML is
    /// the one list: classes, functions and their values, tracker and
    /// derived predicates, with their words.
    pub fn builtin() -> Vocabulary {
        // Read once: the file is embedded and never changes.
        static BUILTIN: OnceLock<Vocabulary> = OnceLock::new();
        BUILTIN
            .get_or_init(|| {
                let pad = logicpad::LogicPad::builtin();
                match super::schema::vocabulary_of(pad.schema(), None) {
                    Ok(v) => v.with_rules(pad.program()),
                    // The built-in LogicPad is checked by a unit test to give
                    // a vocabulary; an empty one is the only non-panicking
                    // fallback.
                    Err(_) => Vocabulary {
                        predicates: Vec::new(),
                        functions: Vec::new(),
                        guards: BTreeMap::new(),
                    },
                }
            })
            .clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_phrases_split_case() {
        assert_eq!(default_phrase("ConstantSpeed"), "constant speed");
        assert_eq!(default_phrase("SUV"), "suv");
        assert_eq!(default_phrase("PoliceCar"), "police car");
        assert_eq!(default_phrase("NearLeft"), "near left");
        assert_eq!(
            default_phrase("DistanceDecreasesToZero"),
            "distance decreases to zero"
        );
        assert_eq!(default_phrase("TrafficSign"), "traffic sign");
        assert_eq!(default_phrase("ABCWord"), "abc word");
    }

    #[test]
    fn builtin_builds_and_covers_the_canonical_vocabulary() {
        let v = Vocabulary::builtin();
        for name in [
            "Vehicles",
            "Pedestrian",
            "Person",
            "Cyclist",
            "Pole",
            "TrafficLight",
            "Appear",
            "Disappear",
            "Moving",
            "SpeedUp",
            "DistanceIncrease",
            "On",
            "Stopped",
            "ConstantSpeed",
            "Collide",
            "Ride",
            "IsCar",
            "Appeared",
        ] {
            assert!(v.predicate(name).is_some(), "{name} missing");
        }
        for name in ["TypeOf", "ColorOf", "InitialLocation", "LastLocation"] {
            assert!(v.function(name).is_some(), "{name} missing");
        }
        assert_eq!(
            v.function("LastLocation").map(|f| f.role),
            Some(FunctionRole::Location(Anchor::Last))
        );
        // 19 values and Argoverse 2's 25 categories not among them.
        assert_eq!(v.function("TypeOf").map(|f| f.values.len()), Some(44));
        assert_eq!(
            v.function("ColorOf").map(|f| f.nouns.clone()),
            Some(vec!["colour".to_string(), "color".to_string()])
        );
        // An everyday person is anyone; `Person` is a sitting person.
        assert_eq!(
            v.predicate("IsPerson").map(|p| p.role),
            Some(PredicateRole::Class)
        );
        assert!(
            v.predicate("Person")
                .is_some_and(|p| !p.phrases.iter().any(|ph| ph == "person"))
        );
        for name in ["LeftOf", "RightOf", "InFrontOf", "Behind"] {
            assert_eq!(
                v.predicate(name).map(|p| (p.arity, p.role)),
                Some((2, PredicateRole::Relation)),
                "{name}"
            );
        }
    }

    #[test]
    fn builder_rejects_bad_input() {
        assert_eq!(
            Vocabulary::builder().class("Bad Name", &[]).build(),
            Err(VocabularyError::BadName("Bad Name".into()))
        );
        assert_eq!(
            Vocabulary::builder()
                .class("Pole", &[])
                .class("Pole", &[])
                .build(),
            Err(VocabularyError::Duplicate("Pole".into()))
        );
        assert!(matches!(
            Vocabulary::builder()
                .predicate_with_role("Near", 2, PredicateRole::Class, &[])
                .build(),
            Err(VocabularyError::BadArity { .. })
        ));
        assert!(matches!(
            Vocabulary::builder().function("ColorOf", &[]).build(),
            Err(VocabularyError::BadValues { .. })
        ));
        assert_eq!(
            Vocabulary::builder()
                .function_nouns("ColorOf", &["colour"])
                .build(),
            Err(VocabularyError::UnknownFunction("ColorOf".into()))
        );
        assert!(matches!(
            Vocabulary::builder()
                .function("ColorOf", &[("Red", &[]), ("Red", &[])])
                .build(),
            Err(VocabularyError::BadValues { .. })
        ));
    }

    #[test]
    fn function_roles_follow_names() {
        assert_eq!(function_role_for("TypeOf"), FunctionRole::Type);
        assert_eq!(function_role_for("ColorOf"), FunctionRole::Attribute);
        assert_eq!(
            function_role_for("InitialLocation"),
            FunctionRole::Location(Anchor::Initial)
        );
        assert_eq!(
            function_role_for("LastLocation"),
            FunctionRole::Location(Anchor::Last)
        );
    }
}
