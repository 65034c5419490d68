//! The words a question may use: predicates and functions with their English
//! phrases, and the grammatical role each one plays.
//!
//! A [`Vocabulary`] is data, not grammar: the translator's closed-class
//! grammar (determiners, auxiliaries, prepositions, negation) is fixed, while
//! every content word comes from here. An expert who adds a predicate with a
//! phrase makes it askable without touching the parser.

use std::collections::BTreeSet;

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
    #[error("predicate '{name}' has arity {arity}, which does not fit its role {role:?}")]
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
    pub fn predicate_with_role(
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
    pub fn predicate_spec(mut self, spec: PredicateSpec) -> Self {
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
    pub fn function_nouns(mut self, name: &str, nouns: &[&str]) -> Self {
        match self.functions.iter_mut().find(|f| f.name == name) {
            Some(f) => f.nouns.extend(owned(nouns)),
            None => self.unknown.push(name.to_string()),
        }
        self
    }

    /// Adds a function, guessing its role from its name (see
    /// [`function_role_for`]).
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
        })
    }
}

/// The role a function gets when none is given: `TypeOf` (and any name
/// starting with `Type`) holds nouns, a name containing `Location` or
/// `Position` holds places (last frames when it starts with `Last`, `Final`
/// or `End`, first frames otherwise), anything else holds adjectives.
pub fn function_role_for(name: &str) -> FunctionRole {
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
pub fn default_phrase(name: &str) -> String {
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
pub fn camel_words(name: &str) -> Vec<String> {
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

    /// The project's canonical vocabulary: the classes, functions, tracker
    /// and derived predicates that perception emits and the default LogicPad
    /// declares, with the English phrases of everyday driving questions.
    pub fn builtin() -> Vocabulary {
        let locations: &[(&str, &[&str])] = &[
            ("Left", &["left"]),
            ("Right", &["right"]),
            ("Front", &["front", "ahead"]),
            ("NearLeft", &["near left", "close left"]),
            ("FarLeft", &["far left"]),
            ("NearRight", &["near right", "close right"]),
            ("FarRight", &["far right"]),
            ("NearFront", &["near front", "close front"]),
            ("FarFront", &["far front", "far ahead"]),
        ];
        let b = Vocabulary::builder()
            // Classes come first: "pedestrian" is the class, not TypeOf(x, Pedestrian).
            .class("Vehicles", &["vehicle", "automobile"])
            .class("Pedestrian", &["pedestrian", "walker"])
            // `Person` is a *sitting* person in the LogicPad (KITTI's
            // Person_sitting); an everyday "person" is anyone, walking or
            // not: the alias `IsPerson` (Person ∨ Pedestrian).
            .class(
                "Person",
                &["sitting person", "person sitting", "seated person"],
            )
            .class(
                "IsPerson",
                &[
                    "person",
                    "people",
                    "human",
                    "human being",
                    "man",
                    "woman",
                    "child",
                    "kid",
                    "boy",
                    "girl",
                    "guy",
                    "lady",
                    "adult",
                    "passerby",
                    "passer by",
                    "someone",
                    "somebody",
                    "anyone",
                    "anybody",
                ],
            )
            .class(
                "Cyclist",
                &[
                    "cyclist",
                    "bicyclist",
                    "biker",
                    "rider",
                    "bike rider",
                    "bicycle rider",
                ],
            )
            .class("Misc", &["misc", "miscellaneous object"])
            .class("Road", &["road", "street"])
            .class("Sidewalk", &["sidewalk", "pavement", "footpath"])
            .class(
                "LaneMarking",
                &["lane marking", "road marking", "lane line"],
            )
            .class("Pole", &["pole", "lamppost", "lamp post", "post"])
            .class(
                "TrafficSign",
                &["traffic sign", "road sign", "sign", "stop sign"],
            )
            .class(
                "TrafficLight",
                &["traffic light", "traffic signal", "stoplight"],
            )
            .class("Building", &["building", "house"])
            .class(
                "Vegetation",
                &["vegetation", "tree", "bush", "hedge", "plant"],
            )
            .class("Fence", &["fence"])
            .class("Wall", &["wall"])
            .class("Terrain", &["terrain", "grass"])
            .class(
                "ConstructionObj",
                &["construction object", "traffic cone", "cone", "barrier"],
            )
            .silent("Other", 1)
            .function(
                "TypeOf",
                &[
                    ("Car", &["car", "passenger car"]),
                    ("Van", &["van"]),
                    ("Truck", &["truck", "lorry"]),
                    ("Tram", &["tram", "streetcar"]),
                    ("Bus", &["bus"]),
                    (
                        "Motorcycle",
                        &["motorcycle", "motorbike", "motor bike", "scooter"],
                    ),
                    ("Bicycle", &["bicycle", "bike"]),
                    ("SUV", &["suv", "sport utility vehicle"]),
                    ("Sedan", &["sedan", "saloon"]),
                    ("Coupe", &["coupe"]),
                    ("Hatchback", &["hatchback"]),
                    ("Wagon", &["wagon", "station wagon", "estate car"]),
                    ("Minivan", &["minivan", "mini van"]),
                    ("Cab", &["cab", "taxi"]),
                    ("Convertible", &["convertible"]),
                    (
                        "PoliceCar",
                        &["police car", "police vehicle", "patrol car", "cop car"],
                    ),
                    ("Pedestrian", &[]),
                    ("Cyclist", &[]),
                    ("Other", &[]),
                ],
            )
            .function(
                "ColorOf",
                &[
                    ("Black", &["black"]),
                    ("Blue", &["blue"]),
                    ("Brown", &["brown"]),
                    ("Cyan", &["cyan"]),
                    ("Green", &["green"]),
                    ("Grey", &["grey", "gray"]),
                    ("Orange", &["orange"]),
                    ("Red", &["red"]),
                    ("Violet", &["violet", "purple"]),
                    ("White", &["white"]),
                    ("Yellow", &["yellow"]),
                    ("Silver", &["silver"]),
                    ("Other", &[]),
                ],
            )
            .function_nouns("TypeOf", &["type", "kind", "sort", "category"])
            .function_nouns("ColorOf", &["colour", "color"])
            .function("InitialLocation", locations)
            .function("LastLocation", locations)
            // Tracker predicates. The derived predicates below carry the
            // everyday words; these are named in queries and rules.
            .anchored_property(
                "Appear",
                Anchor::Initial,
                &[
                    "appear",
                    "new",
                    "newly appeared",
                    "emerge",
                    "pop up",
                    "show up",
                    "come into view",
                    "enter the scene",
                    "enter from",
                    "come in from",
                    "enter the frame",
                    "enter the view",
                ],
            )
            .anchored_property(
                "Disappear",
                Anchor::Last,
                &[
                    "disappear",
                    "vanish",
                    "leave the scene",
                    "leave the frame",
                    "leave the view",
                    "exit the scene",
                    "exit to",
                    "exit from",
                    "leave to",
                    "leave from",
                    "exit the frame",
                    "go out of view",
                    "get out of view",
                    "out of sight",
                    "out of view",
                    "out of the frame",
                    "out of frame",
                    "out of the picture",
                    "go out of sight",
                    "get out of sight",
                    "disappear from view",
                    "drop out of view",
                ],
            )
            .silent("Moving", 1)
            .silent("SpeedUp", 1)
            .silent("SpeedDown", 1)
            .property(
                "CloseToCamera",
                &[
                    "close to the camera",
                    "near the camera",
                    "close to us",
                    "near us",
                ],
            )
            .silent("AtLeft", 1)
            .silent("AtRight", 1)
            // The paper reads "at the center" as AtCenter(x); left and right
            // are InitialLocation/LastLocation values instead.
            .property("AtCenter", &["center", "centre", "middle", "central"])
            .relation(
                "DistanceIncrease",
                &[
                    "distance increase",
                    "distance grow",
                    "distance larger",
                    "distance bigger",
                    "distance widen",
                ],
            )
            .relation(
                "DistanceDecrease",
                &[
                    "distance decrease",
                    "distance shrink",
                    "distance smaller",
                    "distance reduce",
                    "distance narrow",
                ],
            )
            .relation(
                "DistanceDecreasesToZero",
                &["distance decrease to zero", "distance shrink to zero"],
            )
            .silent("DistanceZeroStart", 2)
            .silent("DistanceZeroEnd", 2)
            .relation("TooClose", &["too close", "dangerously close"])
            .relation("On", &["on", "on top of"])
            // Relative position of two objects in the ego frame. A phrase
            // made of a place and "of" ("to the left of") is read by the
            // grammar: "on the left of the scene" stays a place.
            .relation(
                "LeftOf",
                &[
                    "to the left of",
                    "on the left of",
                    "left of",
                    "at the left of",
                ],
            )
            .relation(
                "RightOf",
                &[
                    "to the right of",
                    "on the right of",
                    "right of",
                    "at the right of",
                ],
            )
            .relation("InFrontOf", &["in front of", "ahead of", "at the front of"])
            .relation("Behind", &["behind", "in back of", "following"])
            // Derived predicates (default LogicPad rules).
            .property(
                "Stopped",
                &[
                    "stopped",
                    "stop",
                    "parked",
                    "park",
                    "stationary",
                    "halted",
                    "motionless",
                    "idle",
                    "standing still",
                    "at rest",
                    "at a standstill",
                    "come to a stop",
                    "come to a halt",
                ],
            )
            .property("Walk", &["walk"])
            .property("Stand", &["stand"])
            .property(
                "Move",
                &["move", "in motion", "drive", "travel", "run", "jog"],
            )
            .property(
                "Accelerate",
                &[
                    "accelerate",
                    "speed up",
                    "get faster",
                    "go faster",
                    "gain speed",
                    "pick up speed",
                    "speed increase",
                    "move faster",
                    "drive faster",
                    "increase speed",
                    "increase its speed",
                ],
            )
            .property(
                "Decelerate",
                &[
                    "decelerate",
                    "slow down",
                    // "slowing" only: the adjective "slow" says nothing
                    // about a change of speed (see `Lexicon::inflected_only`).
                    "slowing",
                    "brake",
                    "hit the brakes",
                    "reduce speed",
                    "reduce its speed",
                    "get slower",
                    "move slower",
                    "drive slower",
                    "go slower",
                    "lose speed",
                    "speed decrease",
                ],
            )
            .property(
                "ConstantSpeed",
                &[
                    "constant speed",
                    "steady speed",
                    "same speed",
                    "uniform speed",
                    "constant velocity",
                    "steady velocity",
                    "speed constant",
                    "speed same",
                    "speed unchanged",
                    "speed steady",
                    "speed not change",
                ],
            )
            .property(
                "IncreasePace",
                &["increase pace", "walk faster", "pace increase"],
            )
            .property(
                "DecreasePace",
                &["decrease pace", "walk slower", "pace decrease"],
            )
            .property(
                "FixedPace",
                &[
                    "fixed pace",
                    "steady pace",
                    "constant pace",
                    "same pace",
                    "pace constant",
                    "pace unchanged",
                ],
            )
            .relation(
                "GettingCloser",
                &[
                    "getting closer",
                    "get closer",
                    "move closer",
                    "come closer",
                    "draw closer",
                    "drive closer",
                    "approach",
                    "close in on",
                    "towards",
                    "toward",
                ],
            )
            .relation("ComeClose", &["come close", "get close", "move close"])
            .relation(
                "GoAway",
                &[
                    "go away",
                    "move away",
                    "drive away",
                    "get farther",
                    "get further",
                    "move farther",
                    "pull away",
                    "recede",
                    "away from",
                    "move apart",
                    "drift apart",
                    "drive apart",
                    "get further apart",
                    "get farther apart",
                    "grow apart",
                    "separate",
                ],
            )
            .relation(
                "ConstantDistance",
                &[
                    "constant distance",
                    "distance constant",
                    "distance same",
                    "distance unchanged",
                    "distance steady",
                    "distance not change",
                    "keep the same distance",
                    "keep a constant distance",
                    "maintain distance",
                    "maintain a constant distance",
                ],
            )
            .relation("Collide", &["collide", "hit", "bump into", "run into"])
            .property("Cross", &["cross", "cross the road", "cross the street"])
            .silent("NotCross", 1)
            .relation("Crash", &["crash"])
            .relation("Merge", &["merge"])
            .relation("Enter", &["enter", "get into", "get in"])
            .relation("Diverge", &["diverge"])
            .relation("Exit", &["exit", "get out of", "get out"])
            .relation("Ride", &["ride"])
            .silent("Appeared", 1)
            .silent("Disappeared", 1);
        let aliases = [
            "IsVehicles",
            "IsPedestrian",
            "IsCyclist",
            "IsBuilding",
            "IsPole",
            "IsTrafficSign",
            "IsTrafficLight",
            "IsRoad",
            "IsSidewalk",
            "IsVegetation",
            "IsFence",
            "IsWall",
            "IsTerrain",
            "IsCar",
            "IsVan",
            "IsTruck",
            "IsBus",
            "IsTram",
            "IsMotorcycle",
        ];
        let b = aliases.iter().fold(b, |b, a| b.silent(a, 1));
        match b.build() {
            Ok(v) => v,
            // The table above is fixed and checked by a unit test; an empty
            // vocabulary is the only non-panicking fallback.
            Err(_) => Vocabulary {
                predicates: Vec::new(),
                functions: Vec::new(),
            },
        }
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
        assert_eq!(v.function("TypeOf").map(|f| f.values.len()), Some(19));
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
