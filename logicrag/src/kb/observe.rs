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
    /// Atom patterns observed although an unobservable pattern matches
    /// them (same argument syntax): a camera source observes `Near(x, ego)`
    /// though not `Near(x, y)` between two objects.
    pub observed_atoms: Vec<(String, Vec<Option<String>>)>,
}

/// The constant that names the ego (the recording vehicle) in facts.
pub const EGO: &str = "ego";

/// The 360° relations perception derives only for surround sources (some
/// observation without a pixel box, `perception::Sequence::is_surround`):
/// unobservable on a camera source (`Observability::forward_camera`),
/// whose answers to them are unknown, never no. `Near`, `TurnLeft` and
/// `TurnRight` are observed there for the ego only (atoms, not listed here).
pub const SURROUND_PREDICATES: &[&str] = &[
    "InDirectionOf",
    "SameDirection",
    "Opposite",
    "Perpendicular",
    "HeadingToward",
    "CrossedBy",
    "Stationary",
];

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

    /// Marks the atoms of `pred` matching `args` as observed even where an
    /// unobservable pattern ([`Observability::without_atoms`]) matches them.
    pub fn keeping_atoms(mut self, pred: &str, args: &[Option<&str>]) -> Observability {
        self.observed_atoms.push((
            pred.to_string(),
            args.iter().map(|a| a.map(str::to_string)).collect(),
        ));
        self
    }

    /// What a forward-looking camera cannot see whatever it observes:
    /// anything behind the ego (`Behind(x, ego)`, and its converse
    /// `InFrontOf(ego, x)`, the bearing locations `Behind`, `NearBehind`,
    /// `FarBehind`), so "Is there a truck behind us?" is unknown, not no;
    /// and the 360° relations perception derives only for surround sources
    /// (`SURROUND_PREDICATES`; `Near` between two objects; `TurnLeft`,
    /// `TurnRight` and `Turn` of an object — the ego's own are observed).
    pub(crate) fn forward_camera(self) -> Observability {
        let why = "a forward-looking camera does not see what is behind the ego";
        let behind = ["Behind", "NearBehind", "FarBehind"];
        let o = self
            .without_atoms("Behind", &[None, Some(EGO)], why)
            .without_atoms("InFrontOf", &[Some(EGO), None], why);
        let o = ["InitialLocation", "LastLocation"]
            .iter()
            .flat_map(|f| behind.iter().map(move |v| (*f, *v)))
            .fold(o, |o, (f, v)| o.without_atoms(f, &[None, Some(v)], why));
        let around = "a camera source gets no 360° relations (they need every object's 3D position and heading around the ego: a surround source such as Argoverse 2)";
        let o = o.without(SURROUND_PREDICATES, around);
        // Between an object and the ego: observed from the camera's depth.
        let o = o
            .without_atoms("Near", &[None, None], around)
            .keeping_atoms("Near", &[None, Some(EGO)])
            .keeping_atoms("Near", &[Some(EGO), None]);
        ["TurnLeft", "TurnRight", "Turn"].iter().fold(o, |o, p| {
            o.without_atoms(p, &[None], around)
                .keeping_atoms(p, &[Some(EGO)])
        })
    }

    /// `TypeOf` values the source never assigns (a label set without body
    /// styles cannot tell a sedan from a hatchback): `TypeOf(x, Sedan)`
    /// is then unknown where no object has it, never a silent no. The
    /// taxonomy still works upwards: a KITTI `Car` is a car.
    pub(crate) fn without_type_values(self, values: &[&str], why: &str) -> Observability {
        values.iter().fold(self, |o, v| {
            o.without_atoms("TypeOf", &[None, Some(v)], why)
        })
    }

    /// Why the atom `pred(args)` (`Some(c)`: the constant `c`, `None`: a
    /// variable) may hold unseen although `pred` is observed: the reason
    /// of the first unobservable pattern it matches, or `None`. A pattern's
    /// constant matches that constant only, not a variable: `Behind(x, y)`
    /// over objects stays observed, `Behind(x, ego)` does not.
    ///
    /// A pattern of [`Observability::keeping_atoms`] that matches the atom
    /// keeps it observed: `Near(x, ego)` on a camera source.
    pub(crate) fn blind_atom(&self, pred: &str, args: &[Option<&str>]) -> Option<&str> {
        let matches = |p: &String, pattern: &Vec<Option<String>>| {
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
        };
        if self.observed_atoms.iter().any(|(p, pat)| matches(p, pat)) {
            return None;
        }
        self.unobservable_atoms
            .iter()
            .find(|(p, pattern, _)| matches(p, pattern))
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
        // The old predicates stay fully observed; the 360° ones are not.
        for p in ["Behind", "InFrontOf", "Near", "TurnLeft", "InitialLocation"] {
            assert!(!o.unobservable.contains_key(p), "{p}");
        }
        for p in SURROUND_PREDICATES {
            assert!(o.unobservable.contains_key(*p), "{p}");
        }
    }

    #[test]
    fn a_camera_sees_nearness_and_turns_of_the_ego_only() {
        let o = Observability::everything().forward_camera();
        assert!(o.blind_atom("Near", &[None, Some("ego")]).is_none());
        assert!(o.blind_atom("Near", &[Some("ego"), None]).is_none());
        assert!(o.blind_atom("Near", &[None, None]).is_some());
        assert!(
            o.blind_atom("Near", &[Some("car_1"), Some("truck_2")])
                .is_some()
        );
        assert!(o.blind_atom("TurnLeft", &[Some("ego")]).is_none());
        assert!(o.blind_atom("Turn", &[Some("ego")]).is_none());
        assert!(o.blind_atom("TurnRight", &[None]).is_some());
        assert!(o.blind_atom("Turn", &[Some("car_1")]).is_some());
        // Nothing is behind a forward camera, at any range.
        for v in ["Behind", "NearBehind", "FarBehind"] {
            assert!(o.blind_atom("InitialLocation", &[None, Some(v)]).is_some());
            assert!(o.blind_atom("LastLocation", &[None, Some(v)]).is_some());
        }
        assert!(
            o.blind_atom("InitialLocation", &[None, Some("Left")])
                .is_none()
        );
        // A surround source (no `forward_camera`) sees them all.
        let all = Observability::everything();
        assert!(all.blind_atom("Near", &[None, None]).is_none());
        assert!(all.unobservable.is_empty());
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
