//! A translator vocabulary from a LogicPad schema, so that a predicate an
//! expert declares (with `phrases:` and `role:`) becomes askable.

use logicpad::{Frames, PredInfo, PredKind, Role, Schema};

use super::lexer;
use super::vocab::{
    Anchor, FunctionRole, PredicateRole, PredicateSpec, Vocabulary, VocabularyError,
    default_phrase, function_role_for,
};

/// Producer groups whose unary predicates are object classes (nouns).
fn is_class_group(group: &str) -> bool {
    let g = group.to_ascii_lowercase();
    [
        "segmentation",
        "semantic",
        "class",
        "object",
        "detector",
        "detection",
    ]
    .iter()
    .any(|k| g.contains(k))
}

/// `IsCar` when `Car` is a class or type name: an alias with no words of its own.
fn is_alias(name: &str, schema: &Schema, everyday: Option<&Vocabulary>) -> bool {
    let Some(rest) = name.strip_prefix("Is") else {
        return false;
    };
    if !rest.chars().next().is_some_and(|c| c.is_ascii_uppercase()) {
        return false;
    }
    let value_of_schema = schema.predicates().any(|p| {
        p.values
            .as_ref()
            .is_some_and(|vs| vs.iter().any(|v| v == rest))
    });
    schema.get(rest).is_some()
        || value_of_schema
        || everyday.is_some_and(|e| {
            e.predicate(rest).is_some()
                || e.functions()
                    .iter()
                    .any(|f| f.values.iter().any(|v| v.name == rest))
        })
}

fn merged(first: &[String], then: &[String]) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for p in first.iter().chain(then) {
        if !out.contains(p) {
            out.push(p.clone());
        }
    }
    out
}

/// The stems of a name's words: `Disappears`, `Disappeared` and
/// `Disappear` all give `["disappear"]`.
fn stems_of(name: &str) -> Vec<String> {
    lexer::tokenize(&default_phrase(name))
        .into_iter()
        .map(|t| t.stem)
        .collect()
}

/// The anchor of the everyday property named like `name` up to an
/// inflection: the reference LogicPad's `Disappears` is the built-in
/// `Disappear`, whose place is where the object was last seen.
fn inflected_anchor(name: &str, everyday: Option<&Vocabulary>) -> Option<Anchor> {
    let stems = stems_of(name);
    everyday?
        .predicates()
        .iter()
        .filter(|p| p.role == PredicateRole::Property)
        .find(|p| p.anchor.is_some() && stems_of(&p.name) == stems)
        .and_then(|p| p.anchor)
}

fn anchor(frames: Frames) -> Anchor {
    match frames {
        Frames::Initial => Anchor::Initial,
        Frames::Last => Anchor::Last,
    }
}

/// The declared role, when it fits the predicate. The loader drops a role
/// that does not, but a schema may also be built by hand.
fn declared(info: &PredInfo) -> Option<Role> {
    info.role
        .filter(|r| r.misfit(info.kind, info.arity).is_none())
}

/// The vocabulary of `schema`. `everyday`, when given, lends every name
/// its phrases after the schema's own, and, to a name whose role the schema
/// does not declare, its role and anchor.
pub(super) fn vocabulary_of(
    schema: &Schema,
    everyday: Option<&Vocabulary>,
) -> Result<Vocabulary, VocabularyError> {
    let mut b = Vocabulary::builder();
    // Predicates after functions in the builder; the order of groups in
    // the lexicon does not depend on it.
    let mut preds: Vec<PredicateSpec> = Vec::new();
    for info in schema.predicates() {
        let role = declared(info);
        let frames = info.frames.map(anchor);
        let known = everyday.and_then(|e| e.predicate(&info.name));
        if info.kind == PredKind::Function {
            let known_f = everyday.and_then(|e| e.function(&info.name));
            let inferred = known_f.map_or_else(|| function_role_for(&info.name), |f| f.role);
            let role = match role {
                Some(Role::Type) => FunctionRole::Type,
                Some(Role::Attribute) => FunctionRole::Attribute,
                Some(Role::Location) => {
                    let by_name = match inferred {
                        FunctionRole::Location(a) => a,
                        _ => Anchor::Initial,
                    };
                    FunctionRole::Location(frames.unwrap_or(by_name))
                }
                // Known to queries, never read from a question's words.
                Some(Role::Silent) => {
                    preds.push(PredicateSpec {
                        name: info.name.clone(),
                        arity: info.arity,
                        role: PredicateRole::Silent,
                        phrases: Vec::new(),
                        anchor: None,
                    });
                    continue;
                }
                Some(Role::Class | Role::Property | Role::Relation) | None => match inferred {
                    FunctionRole::Location(a) => FunctionRole::Location(frames.unwrap_or(a)),
                    other => other,
                },
            };
            let values = info.values.clone().unwrap_or_default();
            let owned: Vec<(String, Vec<String>)> = values
                .iter()
                .map(|v| {
                    let own = info.value_phrases.get(v).cloned().unwrap_or_default();
                    let extra = known_f
                        .and_then(|f| f.values.iter().find(|kv| kv.name == *v))
                        .map(|kv| kv.phrases.clone())
                        .unwrap_or_default();
                    (v.clone(), merged(&own, &extra))
                })
                .collect();
            let refs: Vec<Vec<&str>> = owned
                .iter()
                .map(|(_, ps)| ps.iter().map(String::as_str).collect())
                .collect();
            let pairs: Vec<(&str, &[&str])> = owned
                .iter()
                .zip(refs.iter())
                .map(|((v, _), ps)| (v.as_str(), ps.as_slice()))
                .collect();
            b = b.function_with_role(&info.name, role, &pairs);
            // Function-level phrases of nouns and adjectives ("colour",
            // "type") ask for the value; those of places ("initially")
            // are time words the grammar reads itself.
            if matches!(role, FunctionRole::Type | FunctionRole::Attribute) {
                let nouns = merged(
                    &info.phrases,
                    known_f.map_or(&[][..], |f| f.nouns.as_slice()),
                );
                let nouns: Vec<&str> = nouns.iter().map(String::as_str).collect();
                b = b.function_nouns(&info.name, &nouns);
            }
            continue;
        }
        let phrases = merged(
            &info.phrases,
            known.map_or(&[][..], |k| k.phrases.as_slice()),
        );
        let role = match role {
            Some(Role::Class) => PredicateRole::Class,
            Some(Role::Property) => PredicateRole::Property,
            Some(Role::Relation) => PredicateRole::Relation,
            Some(Role::Silent | Role::Type | Role::Attribute | Role::Location) => {
                PredicateRole::Silent
            }
            None => inferred_role(info, schema, everyday, &phrases),
        };
        let anchor = frames.or_else(|| known.and_then(|k| k.anchor)).or_else(|| {
            (role == PredicateRole::Property)
                .then(|| inflected_anchor(&info.name, everyday))
                .flatten()
        });
        preds.push(PredicateSpec {
            name: info.name.clone(),
            arity: info.arity,
            role,
            phrases,
            anchor,
        });
    }
    preds
        .into_iter()
        .fold(b, |b, p| b.predicate_spec(p))
        .build()
}

/// The role of a predicate whose LogicPad declares none: `Is*` aliases
/// are silent, or class nouns when they have phrases; a name the everyday
/// vocabulary gives words keeps its role there; else binary predicates are
/// relations, unary atomic ones of a segmentation or class group class
/// nouns, other unary ones properties.
fn inferred_role(
    info: &PredInfo,
    schema: &Schema,
    everyday: Option<&Vocabulary>,
    phrases: &[String],
) -> PredicateRole {
    let alias = is_alias(&info.name, schema, everyday);
    let known = everyday.and_then(|e| e.predicate(&info.name));
    // The built-in vocabulary keeps tracker predicates silent behind
    // their derived forms (Moving behind Move); a LogicPad may not have
    // those, so here every non-alias predicate has words. An alias with
    // words is a noun: "person" for IsPerson.
    if alias && phrases.is_empty() {
        PredicateRole::Silent
    } else if alias && info.arity == 1 {
        PredicateRole::Class
    } else if let Some(k) = known.filter(|k| k.role != PredicateRole::Silent) {
        k.role
    } else if info.arity == 2 {
        PredicateRole::Relation
    } else if info.arity == 1
        && info.kind == PredKind::Atomic
        && info.group.as_deref().is_some_and(is_class_group)
    {
        PredicateRole::Class
    } else if info.arity == 1 {
        PredicateRole::Property
    } else {
        PredicateRole::Silent
    }
}

impl Vocabulary {
    /// The vocabulary of a LogicPad schema.
    ///
    /// Every predicate of the schema is known, in the schema's (name)
    /// order, which breaks ties between equal phrases. Roles: the declared `role:` (and `frames:`) first;
    /// where none is declared, the built-in vocabulary's role for the same
    /// name, else an inference — a function by its name
    /// (`function_role_for`); a unary atomic predicate of a segmentation
    /// or class group is a class noun; other unary predicates are
    /// properties, binary ones relations; `Is*` aliases are silent unless
    /// they have phrases, then they are class nouns ("person" for
    /// `IsPerson`). Phrases: the schema's `phrases:` first, then the
    /// built-in vocabulary's everyday phrases for the same name, else the
    /// default phrase. Function-level phrases of types and attributes
    /// ("colour", "type") are the nouns of value questions ("What colour is
    /// the van?"); those of locations ("initially") are not used: the
    /// grammar reads time words itself.
    ///
    /// # Errors
    /// [`VocabularyError`] when the schema holds a name or value list the
    /// translator cannot use (a function without values, a bad name).
    pub fn from_schema(schema: &Schema) -> Result<Vocabulary, VocabularyError> {
        vocabulary_of(schema, Some(&Vocabulary::builtin()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::translate::{TranslateError, Translator};
    use logicpad::LogicPad;

    fn translator() -> Translator {
        let pad = LogicPad::builtin();
        let vocab = Vocabulary::from_schema(pad.schema()).unwrap_or_else(|e| panic!("{e}"));
        Translator::new(vocab)
    }

    fn q(t: &Translator, s: &str) -> String {
        t.translate(s)
            .map(|t| t.query)
            .unwrap_or_else(|e| format!("ERROR {e}"))
    }

    /// Asserts that each question translates to its query.
    fn check(t: &Translator, cases: &[(&str, &str)]) {
        for (question, query) in cases {
            assert_eq!(q(t, question), *query, "{question}");
        }
    }

    #[test]
    fn the_default_logicpad_gives_a_working_vocabulary() {
        let t = translator();
        check(
            &t,
            &[
                (
                    "Is there a white car on the left?",
                    "TypeOf(x, Car)^ColorOf(x, White)^InitialLocation(x, Left)",
                ),
                (
                    "Are there vehicles on the right?",
                    "Vehicles(x)^InitialLocation(x, Right)",
                ),
                (
                    "Can you spot a pedestrian at the right in the last few frames?",
                    "Pedestrian(x)^LastLocation(x, Right)",
                ),
                (
                    "Does the Black Coupe disappear from the left of the scene?",
                    "TypeOf(x, Coupe)^ColorOf(x, Black)^Disappear(x)^LastLocation(x, Left)",
                ),
                (
                    "Is the pedestrian on the sidewalk?",
                    "Pedestrian(x)^Sidewalk(y)^On(x, y)",
                ),
                // Everyday people are IsPerson (the LogicPad's phrases); its
                // "person walking" for Pedestrian does not swallow the verb.
                ("Is the person walking?", "IsPerson(x)^Walk(x)"),
                ("Is there a sitting person?", "Person(x)"),
            ],
        );
        assert_eq!(
            t.vocabulary().predicate("IsPerson").map(|p| p.role),
            Some(PredicateRole::Class)
        );
        // The function's own phrases ask for its value.
        check(
            &t,
            &[
                ("What colour is the van?", "TypeOf(x, Van)^ColorOf(x, y)"),
                // Relative positions are the LogicPad's relations.
                (
                    "Which vehicles are to the right of the pedestrian?",
                    "Vehicles(x)^Pedestrian(y)^RightOf(x, y)",
                ),
                (
                    "Are there vehicles on the right of the scene?",
                    "Vehicles(x)^InitialLocation(x, Right)",
                ),
            ],
        );
        // Left and right are location values: the tracker's AtLeft is
        // silent, and its place never hides the grammar's.
        assert_eq!(
            t.vocabulary().predicate("AtLeft").map(|p| p.role),
            Some(PredicateRole::Silent)
        );
        assert_eq!(
            q(&t, "Is the car on the left?"),
            "TypeOf(x, Car)^InitialLocation(x, Left)"
        );
    }

    #[test]
    fn a_predicate_declared_with_phrases_becomes_askable() {
        let src = "atomic_predicates:\n  semantic_segmentation:\n    - predicate: Vehicles(x)\n      phrases: [vehicle]\n    - predicate: Ambulance(x)\n      phrases: [ambulance]\n  tracker:\n    - predicate: Moving(x)\n    - predicate: SirenOn(x)\n      phrases: [siren on, flashing its lights]\nderived_predicates:\n  - name: Rushing\n    phrases: [rush, in a hurry]\n    logic: \"∀x : Ambulance(x) ∧ SirenOn(x) ∧ Moving(x) ==> Rushing(x)\"\n";
        let pad = match LogicPad::parse(src, "expert.yaml", false) {
            Ok(p) => p,
            Err(e) => panic!("{e:?}"),
        };
        let t = Translator::new(
            Vocabulary::from_schema(pad.schema()).unwrap_or_else(|e| panic!("{e}")),
        );
        check(
            &t,
            &[
                (
                    "Is the ambulance flashing its lights?",
                    "Ambulance(x)^SirenOn(x)",
                ),
                (
                    "Is there an ambulance in a hurry?",
                    "Ambulance(x)^Rushing(x)",
                ),
                ("Does the vehicle rush?", "Vehicles(x)^Rushing(x)"),
                ("Is the ambulance moving?", "Ambulance(x)^Moving(x)"),
            ],
        );
        // This LogicPad has no colours and no locations.
        assert!(matches!(
            t.translate("Is there a white ambulance?"),
            Err(TranslateError::Unplaced { .. })
        ));
    }

    #[test]
    fn a_declared_role_comes_before_the_inference() {
        // Without roles, a unary atomic predicate of a segmentation group is a
        // class noun and a derived one a property; declared roles say
        // otherwise, and `frames:` anchors a property's places.
        let src = "atomic_predicates:\n  semantic_segmentation:\n    - predicate: Vehicles(x)\n      role: class\n      phrases: [vehicle]\n    - predicate: Parked(x)\n      role: property\n      phrases: [parked]\n  tracker:\n    - predicate: Leave(x)\n      role: property\n      frames: last\n      phrases: [leave]\nfunctions:\n  Where:\n    predicate: Where(x, place)\n    role: location\n    frames: last\n    values:\n      - Left: [left]\nderived_predicates:\n  - name: Ambulance\n    role: class\n    phrases: [ambulance]\n    logic: \"∀x : Vehicles(x) ∧ Parked(x) ==> Ambulance(x)\"\n  - name: Hidden\n    role: silent\n    logic: \"∀x : Vehicles(x) ==> Hidden(x)\"\n";
        let pad = match LogicPad::parse(src, "roles.yaml", true) {
            Ok(p) => p,
            Err(e) => panic!("{e:?}"),
        };
        let v = Vocabulary::from_schema(pad.schema()).unwrap_or_else(|e| panic!("{e}"));
        let role = |n: &str| v.predicate(n).map(|p| p.role);
        assert_eq!(role("Parked"), Some(PredicateRole::Property));
        assert_eq!(role("Ambulance"), Some(PredicateRole::Class));
        assert_eq!(role("Hidden"), Some(PredicateRole::Silent));
        assert_eq!(
            v.function("Where").map(|f| f.role),
            Some(FunctionRole::Location(Anchor::Last))
        );
        let t = Translator::new(v);
        check(
            &t,
            &[
                ("Is there a parked vehicle?", "Vehicles(x)^Parked(x)"),
                ("Is there an ambulance?", "Ambulance(x)"),
                // `Where` holds the last frames only.
                (
                    "Is the vehicle on the left at the end?",
                    "Vehicles(x)^Where(x, Left)",
                ),
            ],
        );
        assert!(q(&t, "Is the vehicle on the left?").contains("no location function"));
        assert_eq!(
            q(&t, "Does the ambulance leave from the left?"),
            "Ambulance(x)^Leave(x)^Where(x, Left)"
        );
        assert!(q(&t, "Is there a hidden vehicle?").starts_with("ERROR"));
    }

    #[test]
    fn the_builtin_vocabulary_is_read_from_the_builtin_logicpad() {
        let pad = LogicPad::builtin();
        let own = vocabulary_of(pad.schema(), None)
            .unwrap_or_else(|e| panic!("{e}"))
            .with_rules(pad.program());
        assert_eq!(Vocabulary::builtin(), own);
        // The classes a property is defined for come from its rules; a
        // disjunction is several rules, a derived class its own classes.
        assert_eq!(own.guards("Cross"), ["Pedestrian"]);
        assert_eq!(own.guards("Walk"), ["Pedestrian"]);
        assert_eq!(
            own.guards("Move"),
            ["Vehicles", "Pedestrian", "Cyclist", "Ego"]
        );
        // Turning needs no class (any mover's); relations and
        // classes have no guards.
        assert!(own.guards("Turn").is_empty());
        assert!(own.guards("Ride").is_empty());
        assert!(own.guards("IsPerson").is_empty());
        // Without rules nothing is guarded.
        let bare = Vocabulary::from_schema(pad.schema()).unwrap_or_else(|e| panic!("{e}"));
        assert!(bare.guards("Cross").is_empty());
        assert_eq!(
            bare.with_rules(pad.program()).guards("Cross"),
            ["Pedestrian"]
        );
        // The everyday words live in the YAML, roles and anchors too.
        assert!(
            own.predicate("Stopped")
                .is_some_and(|p| p.phrases.iter().any(|ph| ph == "parked"))
        );
        assert_eq!(
            own.predicate("Disappear").and_then(|p| p.anchor),
            Some(Anchor::Last)
        );
        assert_eq!(
            own.predicate("Moving").map(|p| p.role),
            Some(PredicateRole::Silent)
        );
    }
}
