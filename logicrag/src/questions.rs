//! Built-in question sets, generated from a simulated scenario's ground
//! truth (its event log and true scene), never from perception's facts, so
//! that evaluating perception + translator + reasoning against them is a
//! real test. Categories follow the paper: U1 object query, U2 velocity,
//! U3 change in velocity, U4 appearance/disappearance, B1 relative
//! position, B2 relative distance change.
//!
//! A question is only asked when its truth is clear: the object phrase
//! names exactly one object of the window, the event covers the whole
//! window and is at least twice the perception threshold
//! ([`perception::sim::truth::expected_facts`]), and locations are away from the
//! Left/Front/Right boundaries.

use perception::sim::truth::{expected_facts, forbidden_facts};
use perception::sim::{EventKind, SimRun};
use perception::{FactConfig, ObjectClass, WindowFacts};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// One question with its expected answer.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Question {
    /// Window id (`<scenario>_<first frame>`).
    pub window: String,
    /// The question in English.
    pub question: String,
    /// Expected answer.
    pub answer: bool,
    /// U1..U4, B1, B2.
    pub category: String,
}

/// Margin (fraction of the image width) kept away from the location
/// boundaries before a location question is asked.
pub(crate) const LOCATION_MARGIN: f64 = 0.05;

struct Obj {
    name: String,
    class: ObjectClass,
    phrase: String,
}

fn noun(class: ObjectClass, type_name: Option<&str>) -> Option<String> {
    match class {
        ObjectClass::Vehicle => Some(match type_name {
            Some("SUV") => "SUV".to_string(),
            Some(t) => split_camel(t).to_lowercase(),
            None => "vehicle".into(),
        }),
        ObjectClass::Pedestrian => Some("pedestrian".into()),
        ObjectClass::Cyclist => Some("cyclist".into()),
        _ => None,
    }
}

/// "a" or "an" before a phrase.
fn article(phrase: &str) -> &'static str {
    match phrase.chars().next() {
        Some(c) if "aeiouAEIOU".contains(c) => "an",
        _ => "a",
    }
}

fn split_camel(s: &str) -> String {
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && c.is_uppercase() {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// Generates the question set of a simulation for the given windows
/// (computed with `config`), balanced yes/no per category.
pub fn generate(run: &SimRun, windows: &[WindowFacts], config: &FactConfig) -> Vec<Question> {
    let name = &run.sequence.name;
    let width = f64::from(run.sequence.camera.intrinsics.image_width);
    let demanded = expected_pairs(run, windows, config);
    let forbidden = contradictions_truth(run, windows);
    let mut out = Vec::new();
    for w in windows {
        let id = crate::source::window_id(name, w.first_frame);
        let (a, b) = (w.first_frame, w.last_frame);
        // Objects truly visible in the window, with their phrase.
        let mut objs: Vec<Obj> = Vec::new();
        let mut seen = BTreeSet::new();
        for f in a..=b {
            let Some(state) = run.states.get(f as usize) else {
                continue;
            };
            for o in state.objects.iter().filter(|o| o.visible) {
                if !seen.insert(o.name.clone()) {
                    continue;
                }
                if let Some(n) = noun(o.class, o.type_name.as_deref()) {
                    let phrase = match &o.color {
                        Some(c) if o.class == ObjectClass::Vehicle => {
                            format!("{} {n}", c.to_lowercase())
                        }
                        _ => n,
                    };
                    objs.push(Obj {
                        name: o.name.clone(),
                        class: o.class,
                        phrase,
                    });
                }
            }
        }
        let mut count: BTreeMap<&str, usize> = BTreeMap::new();
        for o in &objs {
            *count.entry(o.phrase.as_str()).or_insert(0) += 1;
        }
        let unique = |o: &&Obj| count.get(o.phrase.as_str()) == Some(&1);
        let phrase_of: BTreeMap<&str, &str> = objs
            .iter()
            .filter(unique)
            .map(|o| (o.name.as_str(), o.phrase.as_str()))
            .collect();
        let mut push = |q: String, ans: bool, cat: &str| {
            out.push(Question {
                window: id.clone(),
                question: q,
                answer: ans,
                category: cat.into(),
            });
        };
        let holds = |list: &[(u32, String)], fact: &str| {
            list.iter().any(|(wi, f)| *wi == w.index && f == fact)
        };

        // U1: presence, and presence at a clear initial location.
        let present: BTreeSet<&str> = objs.iter().map(|o| o.phrase.as_str()).collect();
        for o in objs.iter().filter(unique) {
            push(
                format!("Is there {} {} in the scene?", article(&o.phrase), o.phrase),
                true,
                "U1",
            );
            if let Some(loc) = initial_location(run, &o.name, a, b, width, config) {
                push(
                    format!("Is there {} {} on the {loc}?", article(&o.phrase), o.phrase),
                    true,
                    "U1",
                );
                let other = if loc == "left" { "right" } else { "left" };
                push(
                    format!(
                        "Is there {} {} on the {other}?",
                        article(&o.phrase),
                        o.phrase
                    ),
                    false,
                    "U1",
                );
            }
        }
        for absent in absent_phrases(run, &present) {
            push(
                format!("Is there {} {absent} in the scene?", article(&absent)),
                false,
                "U1",
            );
        }

        for o in objs.iter().filter(unique) {
            let x = o.name.as_str();
            let p = o.phrase.as_str();
            let mover = matches!(
                o.class,
                ObjectClass::Vehicle | ObjectClass::Pedestrian | ObjectClass::Cyclist
            );
            if !mover {
                continue;
            }
            // U2: velocity.
            if holds(&demanded, &format!("Moving({x})")) {
                push(format!("Is the {p} moving?"), true, "U2");
            }
            if holds(&forbidden, &format!("Moving({x})")) {
                push(format!("Is the {p} moving?"), false, "U2");
                if o.class == ObjectClass::Vehicle {
                    push(format!("Is the {p} stopped?"), true, "U2");
                }
            }
            // U3: change in velocity.
            if holds(&demanded, &format!("SpeedUp({x})")) {
                push(format!("Is the {p} accelerating?"), true, "U3");
                push(format!("Is the {p} slowing down?"), false, "U3");
            }
            if holds(&demanded, &format!("SpeedDown({x})")) {
                push(format!("Is the {p} slowing down?"), true, "U3");
                push(format!("Is the {p} accelerating?"), false, "U3");
            }
            let constant = holds(&forbidden, &format!("SpeedUp({x})"))
                && holds(&forbidden, &format!("SpeedDown({x})"));
            if constant
                && holds(&demanded, &format!("Moving({x})"))
                && o.class == ObjectClass::Vehicle
            {
                push(
                    format!("Does the {p} move at a constant speed?"),
                    true,
                    "U3",
                );
            }
            // U4: appearance and disappearance.
            if holds(&demanded, &format!("Appear({x})")) {
                push(format!("Does the {p} appear?"), true, "U4");
            } else if visible_through(run, x, a.saturating_sub(config.appear_lookback_frames), a)
                && a > 0
            {
                push(format!("Does the {p} appear?"), false, "U4");
            }
        }

        // B1: relative position (support surfaces, two objects at opposite sides).
        for o in objs
            .iter()
            .filter(unique)
            .filter(|o| o.class == ObjectClass::Pedestrian)
        {
            let x = o.name.as_str();
            let on_road = demanded
                .iter()
                .any(|(wi, f)| *wi == w.index && f.starts_with(&format!("On({x}, road")));
            let on_walk = demanded
                .iter()
                .any(|(wi, f)| *wi == w.index && f.starts_with(&format!("On({x}, sidewalk")));
            if on_road && !on_walk {
                push(format!("Is the {} on the road?", o.phrase), true, "B1");
                push(format!("Is the {} on the sidewalk?", o.phrase), false, "B1");
            }
            if on_walk && !on_road {
                push(format!("Is the {} on the sidewalk?", o.phrase), true, "B1");
                push(format!("Is the {} on the road?", o.phrase), false, "B1");
            }
        }
        let located: Vec<(&Obj, &str)> = objs
            .iter()
            .filter(unique)
            .filter_map(|o| initial_location(run, &o.name, a, b, width, config).map(|l| (o, l)))
            .collect();
        for (i, (o1, l1)) in located.iter().enumerate() {
            for (o2, l2) in located.iter().skip(i + 1) {
                if l1 != l2 && *l1 != "front" && *l2 != "front" {
                    let (a1, a2) = (article(&o1.phrase), article(&o2.phrase));
                    push(
                        format!(
                            "Is there {a1} {} on the {l1} and {a2} {} on the {l2}?",
                            o1.phrase, o2.phrase
                        ),
                        true,
                        "B1",
                    );
                    push(
                        format!(
                            "Is there {a1} {} on the {l2} and {a2} {} on the {l1}?",
                            o1.phrase, o2.phrase
                        ),
                        false,
                        "B1",
                    );
                }
            }
        }

        // B2: relative distance change.
        for e in &run.events {
            let (Some(y), true) = (e.other.as_deref(), e.covers(a, b)) else {
                continue;
            };
            let (Some(px), Some(py)) = (phrase_of.get(e.object.as_str()), phrase_of.get(y)) else {
                continue;
            };
            match e.kind {
                EventKind::Approach
                    if holds(&demanded, &format!("DistanceDecrease({}, {y})", e.object)) =>
                {
                    push(
                        format!("Is the {px} getting closer to the {py}?"),
                        true,
                        "B2",
                    );
                }
                EventKind::Recede
                    if holds(&forbidden, &format!("DistanceDecrease({}, {y})", e.object)) =>
                {
                    push(
                        format!("Is the {px} getting closer to the {py}?"),
                        false,
                        "B2",
                    );
                }
                _ => {}
            }
        }
    }
    out.sort_by(|a, b| {
        (&a.category, &a.window, &a.question).cmp(&(&b.category, &b.window, &b.question))
    });
    out.dedup_by(|a, b| a.window == b.window && a.question == b.question);
    balance(out)
}

/// Facts the truth forbids, as `(window index, fact)`.
fn contradictions_truth(run: &SimRun, windows: &[WindowFacts]) -> Vec<(u32, String)> {
    forbidden_facts(run, windows)
        .into_iter()
        .map(|f| (f.window, f.fact))
        .collect()
}

fn expected_pairs(
    run: &SimRun,
    windows: &[WindowFacts],
    config: &FactConfig,
) -> Vec<(u32, String)> {
    expected_facts(run, windows, config)
        .into_iter()
        .map(|f| (f.window, f.fact))
        .collect()
}

fn visible_through(run: &SimRun, name: &str, first: u32, last: u32) -> bool {
    (first..=last).all(|f| {
        run.visible
            .get(f as usize)
            .is_some_and(|v| v.contains(name))
    })
}

/// The clear initial location (left/front/right) of an object in a window:
/// its true box centre at its first visible frame, at least
/// [`LOCATION_MARGIN`] away from the boundaries.
fn initial_location(
    run: &SimRun,
    name: &str,
    a: u32,
    b: u32,
    width: f64,
    config: &FactConfig,
) -> Option<&'static str> {
    for f in a..=b {
        let state = run.states.get(f as usize)?;
        if let Some(o) = state.objects.iter().find(|o| o.name == name && o.visible) {
            let bbox = o.bbox.as_ref()?;
            let frac = bbox.center_x() / width;
            return if frac < config.left_fraction - LOCATION_MARGIN {
                Some("left")
            } else if frac > config.right_fraction + LOCATION_MARGIN {
                Some("right")
            } else if frac > config.left_fraction + LOCATION_MARGIN
                && frac < config.right_fraction - LOCATION_MARGIN
            {
                Some("front")
            } else {
                None
            };
        }
    }
    None
}

/// Object phrases that name nothing in the whole scenario.
fn absent_phrases(run: &SimRun, present: &BTreeSet<&str>) -> Vec<String> {
    let mut all = BTreeSet::new();
    for s in &run.states {
        for o in &s.objects {
            if let Some(n) = noun(o.class, o.type_name.as_deref()) {
                all.insert(n.clone());
                if let Some(c) = &o.color {
                    all.insert(format!("{} {n}", c.to_lowercase()));
                }
            }
        }
    }
    let candidates = [
        "red bus",
        "yellow truck",
        "green motorcycle",
        "blue van",
        "orange car",
    ];
    candidates
        .iter()
        .filter(|c| !all.contains(**c) && !present.contains(**c))
        .take(1)
        .map(|c| c.to_string())
        .collect()
}

/// Keeps yes and no equally often within each category (the first
/// questions of the larger class, in the set's sorted order).
fn balance(qs: Vec<Question>) -> Vec<Question> {
    let mut by_cat: BTreeMap<String, (Vec<Question>, Vec<Question>)> = BTreeMap::new();
    for q in qs {
        let e = by_cat.entry(q.category.clone()).or_default();
        if q.answer { e.0.push(q) } else { e.1.push(q) }
    }
    let mut out = Vec::new();
    for (_, (yes, no)) in by_cat {
        let n = yes.len().min(no.len()).max(1);
        out.extend(spread(yes, n));
        out.extend(spread(no, n));
    }
    out
}

/// Takes `n` items spread evenly over the list (deterministic).
fn spread(v: Vec<Question>, n: usize) -> Vec<Question> {
    if v.len() <= n {
        return v;
    }
    let len = v.len();
    v.into_iter()
        .enumerate()
        .filter(|(i, _)| (i * n) / len != ((i + 1) * n) / len)
        .map(|(_, q)| q)
        .collect()
}
