//! What a window's KB is built from, and views of its facts: [`WindowInput`],
//! [`WindowFacts`] (listed or text-parsed facts) and [`FactRef`] (a fact
//! read back from the KB's columns, without copying).

use super::*;

/// One window's input: its id, frames and base facts with provenance.
#[derive(Debug, Clone)]
pub struct WindowInput {
    /// Stable window id (`0000_000010`, `urban_crossing#2`).
    pub id: String,
    /// Position of the window in its source (0-based).
    pub index: u32,
    /// First frame (inclusive).
    pub first_frame: u32,
    /// Last frame (inclusive).
    pub last_frame: u32,
    /// Base facts (duplicates are dropped when the KB is built, keeping
    /// the first one's provenance).
    pub facts: WindowFacts,
    /// Facts perception measured and did not assert, each with the
    /// probability that it holds all the same
    /// ([`perception::WindowFacts::doubts`]); empty for a certain source.
    pub doubts: Vec<Fact>,
}

/// A window's base facts before reasoning, in the form their source makes.
#[derive(Debug, Clone)]
pub enum WindowFacts {
    /// Owned facts, each with its provenance: perception's sources (every
    /// fact has its own measurement) and tests.
    Listed(Vec<Fact>),
    /// A text KB parsed straight into interned symbols, every fact from one
    /// place: no `String` per name and one provenance for all. Why: the
    /// `facts:` source read two million lines into `Fact`s first, which
    /// cost more time and memory than reasoning over them.
    Parsed {
        /// The facts in file order, duplicates kept.
        facts: ParsedFacts,
        /// Where every one of them came from.
        provenance: Arc<Provenance>,
    },
}

impl From<Vec<Fact>> for WindowFacts {
    fn from(facts: Vec<Fact>) -> WindowFacts {
        WindowFacts::Listed(facts)
    }
}

impl WindowFacts {
    /// Number of facts, duplicates counted.
    pub fn len(&self) -> usize {
        match self {
            WindowFacts::Listed(v) => v.len(),
            WindowFacts::Parsed { facts, .. } => facts.len(),
        }
    }

    /// True when there is no fact.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The facts in source order, duplicates kept, borrowed.
    pub fn iter(&self) -> impl Iterator<Item = FactRef<'_>> {
        let (listed, parsed) = match self {
            WindowFacts::Listed(v) => (Some(v), None),
            WindowFacts::Parsed { facts, provenance } => (None, Some((facts, provenance))),
        };
        let listed = listed.into_iter().flatten().map(|f| FactRef {
            predicate: &f.predicate,
            args: Args::Strings(&f.args),
            provenance: &f.provenance,
        });
        let parsed = parsed.into_iter().flat_map(|(facts, provenance)| {
            facts.iter().map(move |(pred, args)| FactRef {
                predicate: pred.as_str(),
                args: Args::Syms(args),
                provenance,
            })
        });
        listed.chain(parsed)
    }

    /// The facts as owned [`Fact`]s, for callers that keep or hand them on.
    pub fn to_vec(&self) -> Vec<Fact> {
        match self {
            WindowFacts::Listed(v) => v.clone(),
            WindowFacts::Parsed { .. } => self.iter().map(|f| f.to_fact()).collect(),
        }
    }
}

/// A base fact borrowed from a window's KB or input: its predicate,
/// arguments and provenance, without copying a name.
#[derive(Debug, Clone, Copy)]
pub struct FactRef<'a> {
    pub(super) predicate: &'a str,
    pub(super) args: Args<'a>,
    pub(super) provenance: &'a Arc<Provenance>,
}

/// Where a [`FactRef`]'s arguments are stored.
#[derive(Debug, Clone, Copy)]
pub(super) enum Args<'a> {
    /// A tuple of a model relation (every term a symbol: base facts are
    /// stored from text).
    Terms(kanren::Tuple<'a>),
    /// A parsed text KB's symbols.
    Syms(&'a [Sym]),
    /// A listed fact's strings.
    Strings(&'a [String]),
}

impl<'a> Args<'a> {
    pub(super) fn len(&self) -> usize {
        match self {
            Args::Terms(t) => t.len(),
            Args::Syms(s) => s.len(),
            Args::Strings(s) => s.len(),
        }
    }

    pub(super) fn get(&self, i: usize) -> Option<&'a str> {
        match *self {
            Args::Terms(t) => t.get(i).map(|t| match t {
                Term::Sym(s) => s.as_str(),
                Term::Str(s) => &**s,
                // Never stored as a base fact: the KB interns every
                // argument as a symbol.
                _ => "",
            }),
            Args::Syms(s) => s.get(i).map(Sym::as_str),
            Args::Strings(s) => s.get(i).map(String::as_str),
        }
    }
}

/// The arguments of a [`FactRef`], in order.
#[derive(Debug, Clone)]
pub struct FactArgs<'a> {
    pub(super) args: Args<'a>,
    pub(super) next: usize,
}

impl<'a> Iterator for FactArgs<'a> {
    type Item = &'a str;

    fn next(&mut self) -> Option<&'a str> {
        let a = self.args.get(self.next)?;
        self.next += 1;
        Some(a)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.args.len().saturating_sub(self.next);
        (n, Some(n))
    }
}

impl ExactSizeIterator for FactArgs<'_> {}

impl<'a> FactRef<'a> {
    /// Predicate name, e.g. `Moving`.
    pub fn predicate(&self) -> &'a str {
        self.predicate
    }

    /// Constant arguments in order.
    pub fn args(&self) -> FactArgs<'a> {
        FactArgs {
            args: self.args,
            next: 0,
        }
    }

    /// Argument `i` (from 0).
    pub fn arg(&self, i: usize) -> Option<&'a str> {
        self.args.get(i)
    }

    /// Number of arguments.
    pub fn arity(&self) -> usize {
        self.args.len()
    }

    /// Where the fact came from.
    pub fn provenance(&self) -> &'a Provenance {
        self.provenance
    }

    /// The provenance as the shared handle the facts of a window keep.
    #[cfg(test)]
    pub(crate) fn shared_provenance(&self) -> &'a Arc<Provenance> {
        self.provenance
    }

    /// The fact in the reference KB syntax, e.g. `TypeOf(car_3, Car)`
    /// (as [`Fact::to_kb_line`]).
    pub fn to_kb_line(&self) -> String {
        self.to_string()
    }

    /// An owned copy, for callers that keep or hand on a [`Fact`].
    pub(crate) fn to_fact(self) -> Fact {
        Fact {
            predicate: self.predicate.to_string(),
            args: self.args().map(str::to_string).collect(),
            provenance: Arc::clone(self.provenance),
        }
    }
}

impl std::fmt::Display for FactRef<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}(", self.predicate)?;
        for (i, a) in self.args().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            f.write_str(a)?;
        }
        f.write_str(")")
    }
}

/// Serialised exactly as [`Fact`] is (`predicate`, `args`, `provenance`),
/// so JSON output does not depend on where a fact is stored.
impl serde::Serialize for FactRef<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        struct ArgList<'a>(FactArgs<'a>);
        impl serde::Serialize for ArgList<'_> {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.collect_seq(self.0.clone())
            }
        }
        let mut st = s.serialize_struct("Fact", 3)?;
        st.serialize_field("predicate", self.predicate)?;
        st.serialize_field("args", &ArgList(self.args()))?;
        st.serialize_field("provenance", &**self.provenance)?;
        st.end()
    }
}
