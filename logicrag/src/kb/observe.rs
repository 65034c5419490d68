//! What a source can observe ([`Observed`], [`Observability`]): the line
//! between "no" and "unknown".

use super::*;

/// How completely a source can observe a predicate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Observed {
    /// The source never produces it: an absent fact says nothing.
    Never,
    /// Some of its rules rest on unobservable predicates: a present fact is
    /// proved, an absent one says nothing.
    Partly,
    /// Fully observed: the closed-world assumption holds.
    Fully,
}

/// What a source can observe, as the set of base predicates it cannot produce.
/// Derived predicates inherit from their rules.
///
/// Finer than a predicate, [`Observability::unobservable_atoms`] names
/// atoms of an otherwise observed predicate that the source cannot see:
/// `Behind(x, ego)` from a forward-looking camera (whatever is behind the
/// ego is out of view), while `Behind(car_1, truck_2)` is observed.
#[derive(Debug, Clone, Default)]
pub struct Observability {
    /// Base predicates this source never produces, with the reason.
    pub unobservable: BTreeMap<String, String>,
    /// Atom patterns this source never produces although it observes their
    /// predicate, with the reason: `(predicate, arguments, why)` where an
    /// argument `Some(c)` is the constant `c` and `None` is anything.
    pub unobservable_atoms: Vec<(String, Vec<Option<String>>, String)>,
}

/// The constant that names the ego (the recording vehicle) in facts.
pub const EGO: &str = "ego";

impl Observability {
    /// A source that observes everything its LogicPad declares.
    pub fn everything() -> Observability {
        Observability::default()
    }

    /// Marks predicates as unobservable for a reason.
    pub fn without(mut self, preds: &[&str], why: &str) -> Observability {
        for p in preds {
            self.unobservable.insert((*p).to_string(), why.to_string());
        }
        self
    }

    /// Marks the atoms of `pred` whose arguments match `args` (`Some(c)`:
    /// the constant `c`; `None`: anything) as unobservable for a reason,
    /// though `pred` itself is observed.
    pub fn without_atoms(mut self, pred: &str, args: &[Option<&str>], why: &str) -> Observability {
        self.unobservable_atoms.push((
            pred.to_string(),
            args.iter().map(|a| a.map(str::to_string)).collect(),
            why.to_string(),
        ));
        self
    }

    /// The atoms a forward-looking camera cannot see whatever it observes:
    /// anything behind the ego (`Behind(x, ego)`, and its converse
    /// `InFrontOf(ego, x)`). Perception never emits them (the camera never
    /// sees behind it), so "Is there a truck behind us?" is unknown, not no.
    pub fn forward_camera(self) -> Observability {
        let why = "a forward-looking camera does not see what is behind the ego";
        self.without_atoms("Behind", &[None, Some(EGO)], why)
            .without_atoms("InFrontOf", &[Some(EGO), None], why)
    }

    /// `TypeOf` values the source never assigns (a label set without body
    /// styles cannot tell a sedan from a hatchback): `TypeOf(x, Sedan)`
    /// is then unknown where no object has it, never a silent no. The
    /// taxonomy still works upwards: a KITTI `Car` is a car.
    pub fn without_type_values(self, values: &[&str], why: &str) -> Observability {
        values.iter().fold(self, |o, v| {
            o.without_atoms("TypeOf", &[None, Some(v)], why)
        })
    }

    /// Why the atom `pred(args)` (`Some(c)`: the constant `c`, `None`: a
    /// variable) may hold unseen although `pred` is observed: the reason
    /// of the first unobservable pattern it matches, or `None`. A pattern's
    /// constant matches that constant only, not a variable: `Behind(x, y)`
    /// over objects stays observed, `Behind(x, ego)` does not.
    pub fn blind_atom(&self, pred: &str, args: &[Option<&str>]) -> Option<&str> {
        self.unobservable_atoms
            .iter()
            .find(|(p, pattern, _)| {
                p == pred
                    && pattern.len() == args.len()
                    && pattern
                        .iter()
                        .zip(args)
                        .all(|(want, got)| match (want, got) {
                            (Some(w), Some(g)) => w == g,
                            (Some(_), None) => false,
                            (None, _) => true,
                        })
            })
            .map(|(_, _, why)| why.as_str())
    }

    /// The base predicates under `pred` (itself, or those its rules rest on,
    /// through derived ones) that this source cannot observe, each with the
    /// source's reason: what an "unknown" answer tells the user.
    pub(crate) fn blind_spots(&self, pad: &LogicPad, pred: &str) -> Vec<(String, String)> {
        let mut out = Vec::new();
        rests_on(pad.program(), vec![pred.to_string()], |p| {
            match self.unobservable.get(p) {
                Some(why) => {
                    out.push((p.to_string(), why.clone()));
                    false
                }
                None => true,
            }
        });
        out.sort();
        out
    }

    /// Observability of every predicate of a program (fixpoint over the rules:
    /// a derived predicate is fully observed when every rule for it rests on
    /// fully observed predicates only; partly when at least one rule does, or
    /// when it has any rule at all that can fire on observed facts).
    ///
    /// The fixpoint is the greatest one: a recursive rule over fully observed
    /// facts (`Reach(x, y) ∧ Edge(y, z) ==> Reach(x, z)`) computes its
    /// predicate exactly, so it must not hold its own predicate down.
    pub fn classify(&self, pad: &LogicPad) -> BTreeMap<String, Observed> {
        let program = pad.program();
        let schema = pad.schema();
        let mut status: BTreeMap<String, Observed> = BTreeMap::new();
        for p in schema.predicates() {
            // Derived predicates start fully observed and fall in the fixpoint below.
            let s = if self.unobservable.contains_key(&p.name) {
                Observed::Never
            } else {
                Observed::Fully
            };
            status.insert(p.name.clone(), s);
        }
        // Derived predicates: iterate to a fixpoint (recursion converges
        // because a rule's status is monotone in its body's, so statuses only fall).
        loop {
            let mut changed = false;
            for p in schema.predicates().filter(|p| p.kind == PredKind::Derived) {
                if self.unobservable.contains_key(&p.name) {
                    continue;
                }
                let Some(pid) = program.pred_id(&p.name) else {
                    continue;
                };
                let rules: Vec<_> = program
                    .rules()
                    .iter()
                    .filter(|r| r.head.pred == pid)
                    .collect();
                let rule_status = |r: &&logicpad::Rule| -> Observed {
                    let mut worst = Observed::Fully;
                    for a in r.body.iter().chain(r.negated.iter()) {
                        let name = program.pred_name(a.pred).unwrap_or_default();
                        let s = status.get(name).copied().unwrap_or(Observed::Never);
                        let s = if r.negated.contains(a) && s != Observed::Fully {
                            // ¬P on a partly observed P can be wrongly true.
                            Observed::Never
                        } else {
                            s
                        };
                        worst = worst.min(s);
                    }
                    worst
                };
                let statuses: Vec<Observed> = rules.iter().map(rule_status).collect();
                let new = if statuses.is_empty() {
                    Observed::Never
                } else if statuses.iter().all(|s| *s == Observed::Fully) {
                    Observed::Fully
                } else if statuses.iter().any(|s| *s != Observed::Never) {
                    Observed::Partly
                } else {
                    Observed::Never
                };
                let old = status.get(&p.name).copied().unwrap_or(Observed::Never);
                if new < old {
                    status.insert(p.name.clone(), new);
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        status
    }
}

/// The predicates `roots` rest on: themselves, and through the rules for
/// each (positive and negated bodies) everything under them, visiting each
/// once; `descend(p)` says whether to go under `p`.
pub(crate) fn rests_on(
    program: &logicpad::Program,
    roots: Vec<String>,
    mut descend: impl FnMut(&str) -> bool,
) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut stack = roots;
    while let Some(p) = stack.pop() {
        if !seen.insert(p.clone()) || !descend(&p) {
            continue;
        }
        let Some(pid) = program.pred_id(&p) else {
            continue;
        };
        for r in program.rules().iter().filter(|r| r.head.pred == pid) {
            for a in r.body.iter().chain(r.negated.iter()) {
                if let Some(name) = program.pred_name(a.pred) {
                    stack.push(name.to_string());
                }
            }
        }
    }
    seen
}

#[cfg(test)]
mod atom_tests {
    use super::*;

    #[test]
    fn a_forward_camera_cannot_see_behind_the_ego_but_sees_behind_other_objects() {
        let o = Observability::everything().forward_camera();
        assert!(o.blind_atom("Behind", &[None, Some("ego")]).is_some());
        assert!(
            o.blind_atom("Behind", &[Some("truck_2"), Some("ego")])
                .is_some()
        );
        assert!(o.blind_atom("InFrontOf", &[Some("ego"), None]).is_some());
        // Pairs of objects are seen, whichever they are.
        assert!(o.blind_atom("Behind", &[None, None]).is_none());
        assert!(
            o.blind_atom("Behind", &[Some("car_1"), Some("truck_2")])
                .is_none()
        );
        assert!(o.blind_atom("InFrontOf", &[None, Some("ego")]).is_none());
        assert!(o.blind_atom("LeftOf", &[None, Some("ego")]).is_none());
        // The predicate itself stays fully observed.
        assert!(o.unobservable.is_empty());
    }

    #[test]
    fn type_values_a_label_set_lacks_are_unseen_and_the_others_seen() {
        let o = Observability::everything()
            .without_type_values(&["Sedan", "SUV", "PoliceCar"], "labels say Car");
        assert!(o.blind_atom("TypeOf", &[None, Some("Sedan")]).is_some());
        assert!(
            o.blind_atom("TypeOf", &[Some("car_1"), Some("PoliceCar")])
                .is_some()
        );
        // `Car` itself, and the value asked for ("which type …?"), are seen.
        assert!(o.blind_atom("TypeOf", &[None, Some("Car")]).is_none());
        assert!(o.blind_atom("TypeOf", &[None, None]).is_none());
        assert!(o.blind_atom("ColorOf", &[None, Some("Sedan")]).is_none());
    }
}
