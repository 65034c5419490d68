//! A translator vocabulary from a LogicPad schema, so that a predicate an
//! expert declares (with `phrases:`) becomes askable.

use logicpad::{PredKind, Schema};

use super::vocab::{
    FunctionRole, PredicateRole, PredicateSpec, Vocabulary, VocabularyError, function_role_for,
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
fn is_alias(name: &str, schema: &Schema, builtin: &Vocabulary) -> bool {
    let Some(rest) = name.strip_prefix("Is") else {
        return false;
    };
    if !rest.chars().next().is_some_and(|c| c.is_ascii_uppercase()) {
        return false;
    }
    schema.get(rest).is_some()
        || builtin.predicate(rest).is_some()
        || builtin
            .functions()
            .iter()
            .any(|f| f.values.iter().any(|v| v.name == rest))
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

impl Vocabulary {
    /// The vocabulary of a LogicPad schema.
    ///
    /// Every predicate of the schema is known. Roles: a function by its name
    /// ([`function_role_for`]); a unary atomic predicate of a segmentation or
    /// class group is a class noun; other unary predicates are properties,
    /// binary ones relations; `Is*` aliases are silent unless they have
    /// phrases, then they are class nouns ("person" for `IsPerson`).
    /// Phrases: the schema's `phrases:` first, then the built-in
    /// vocabulary's everyday phrases for the same name (and its role and
    /// anchor when the built-in knows the name), else the default phrase.
    /// Function-level phrases of types and attributes ("colour", "type")
    /// are the nouns of value questions ("What colour is the van?"); those
    /// of locations ("initially") are not used: the grammar reads time
    /// words itself.
    ///
    /// # Errors
    /// [`VocabularyError`] when the schema holds a name or value list the
    /// translator cannot use (a function without values, a bad name).
    pub fn from_schema(schema: &Schema) -> Result<Vocabulary, VocabularyError> {
        let builtin = Vocabulary::builtin();
        let mut b = Vocabulary::builder();
        // Predicates after functions in the builder; the order of groups in
        // the lexicon does not depend on it.
        let mut preds: Vec<PredicateSpec> = Vec::new();
        for info in schema.predicates() {
            let known = builtin.predicate(&info.name);
            if info.kind == PredKind::Function {
                let values = info.values.clone().unwrap_or_default();
                let builtin_f = builtin.function(&info.name);
                let role = builtin_f.map_or_else(|| function_role_for(&info.name), |f| f.role);
                let owned: Vec<(String, Vec<String>)> = values
                    .iter()
                    .map(|v| {
                        let own = info.value_phrases.get(v).cloned().unwrap_or_default();
                        let extra = builtin_f
                            .and_then(|f| f.values.iter().find(|bv| bv.name == *v))
                            .map(|bv| bv.phrases.clone())
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
                        builtin_f.map_or(&[][..], |f| f.nouns.as_slice()),
                    );
                    let nouns: Vec<&str> = nouns.iter().map(String::as_str).collect();
                    b = b.function_nouns(&info.name, &nouns);
                }
                continue;
            }
            let alias = is_alias(&info.name, schema, &builtin);
            let phrases = merged(
                &info.phrases,
                known.map_or(&[][..], |k| k.phrases.as_slice()),
            );
            // The built-in vocabulary keeps tracker predicates silent behind
            // their derived forms (Moving behind Move); a LogicPad may not
            // have those, so here every non-alias predicate has words. An
            // alias with words is a noun: "person" for IsPerson.
            let role = if alias && phrases.is_empty() {
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
            };
            preds.push(PredicateSpec {
                name: info.name.clone(),
                arity: info.arity,
                role,
                phrases,
                anchor: known.and_then(|k| k.anchor),
            });
        }
        preds
            .into_iter()
            .fold(b, |b, p| b.predicate_spec(p))
            .build()
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

    #[test]
    fn the_default_logicpad_gives_a_working_vocabulary() {
        let t = translator();
        assert_eq!(
            q(&t, "Is there a white car on the left?"),
            "TypeOf(x, Car)^ColorOf(x, White)^InitialLocation(x, Left)"
        );
        assert_eq!(
            q(&t, "Are there vehicles on the right?"),
            "Vehicles(x)^InitialLocation(x, Right)"
        );
        assert_eq!(
            q(
                &t,
                "Can you spot a pedestrian at the right in the last few frames?"
            ),
            "Pedestrian(x)^LastLocation(x, Right)"
        );
        assert_eq!(
            q(
                &t,
                "Does the Black Coupe disappear from the left of the scene?"
            ),
            "TypeOf(x, Coupe)^ColorOf(x, Black)^Disappear(x)^LastLocation(x, Left)"
        );
        assert_eq!(
            q(&t, "Is the pedestrian on the sidewalk?"),
            "Pedestrian(x)^Sidewalk(y)^On(x, y)"
        );
        // Everyday people are IsPerson (the LogicPad's phrases); its
        // "person walking" for Pedestrian does not swallow the verb.
        assert_eq!(q(&t, "Is the person walking?"), "IsPerson(x)^Walk(x)");
        assert_eq!(q(&t, "Is there a sitting person?"), "Person(x)");
        assert_eq!(
            t.vocabulary().predicate("IsPerson").map(|p| p.role),
            Some(PredicateRole::Class)
        );
        // The function's own phrases ask for its value.
        assert_eq!(
            q(&t, "What colour is the van?"),
            "TypeOf(x, Van)^ColorOf(x, y)"
        );
        // Relative positions are the LogicPad's relations.
        assert_eq!(
            q(&t, "Which vehicles are to the right of the pedestrian?"),
            "Vehicles(x)^Pedestrian(y)^RightOf(x, y)"
        );
        assert_eq!(
            q(&t, "Are there vehicles on the right of the scene?"),
            "Vehicles(x)^InitialLocation(x, Right)"
        );
        // Place phrases of tracker predicates ("on the left" for AtLeft) do
        // not hide the grammar's places.
        assert!(
            t.skipped_phrases().iter().any(|s| s.contains("AtLeft")),
            "{:?}",
            t.skipped_phrases()
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
        assert_eq!(
            q(&t, "Is the ambulance flashing its lights?"),
            "Ambulance(x)^SirenOn(x)"
        );
        assert_eq!(
            q(&t, "Is there an ambulance in a hurry?"),
            "Ambulance(x)^Rushing(x)"
        );
        assert_eq!(q(&t, "Does the vehicle rush?"), "Vehicles(x)^Rushing(x)");
        assert_eq!(q(&t, "Is the ambulance moving?"), "Ambulance(x)^Moving(x)");
        // This LogicPad has no colours and no locations.
        assert!(matches!(
            t.translate("Is there a white ambulance?"),
            Err(TranslateError::Unplaced { .. })
        ));
    }
}
