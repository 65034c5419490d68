//! Classic relations from the miniKanren literature, ready to use (and used
//! by the tests, examples and benchmarks).

use crate::goal::{Goal, conj, disj, eq, fresh};
use crate::list::{ListGoal, ListKind, Pattern};
pub use crate::list::{membero_rel, nextto_rel};
use crate::term::{Term, sym};

/// `out` is `l` followed by `s`.
pub fn appendo(l: Term, s: Term, out: Term) -> Goal {
    disj([
        conj([eq(l.clone(), Term::Nil), eq(s.clone(), out.clone())]),
        fresh(move |[a, d, res]| {
            conj([
                eq(l.clone(), Term::cons(a.clone(), d.clone())),
                eq(out.clone(), Term::cons(a, res.clone())),
                appendo(d, s.clone(), res),
            ])
        }),
    ])
}

/// `out` is `l` with one occurrence of `x` removed — or `l` itself (The
/// Reasoned Schemer, 2nd ed., frame 2:… `rembero`).
pub fn rembero(x: Term, l: Term, out: Term) -> Goal {
    disj([
        conj([eq(l.clone(), Term::Nil), eq(out.clone(), Term::Nil)]),
        eq(l.clone(), Term::cons(x.clone(), out.clone())),
        fresh(move |[a, d, res]| {
            conj([
                eq(l.clone(), Term::cons(a.clone(), d.clone())),
                eq(out.clone(), Term::cons(a, res.clone())),
                rembero(x.clone(), d, res),
            ])
        }),
    ])
}

/// The Peano numeral for `n`: `z`, `s(z)`, `s(s(z))`, …
pub fn peano(n: u32) -> Term {
    (0..n).fold(sym("z"), |acc, _| Term::app("s", [acc]))
}

/// Peano addition: `n + m = k`.
pub fn pluso(n: Term, m: Term, k: Term) -> Goal {
    disj([
        conj([eq(n.clone(), sym("z")), eq(m.clone(), k.clone())]),
        fresh(move |[n1, k1]| {
            conj([
                eq(n.clone(), Term::app("s", [n1.clone()])),
                eq(k.clone(), Term::app("s", [k1.clone()])),
                pluso(n1, m.clone(), k1),
            ])
        }),
    ])
}

/// `x` is an element of the list `l`.
///
/// Same answers, in the same order, as the relational [`membero_rel`], but
/// over the part of `l` that is already a list it walks the cells directly,
/// trying one unification per element (a failed one allocates nothing);
/// where the list ends in an unbound variable it continues relationally.
pub fn membero(x: Term, l: Term) -> Goal {
    Goal::native(ListGoal {
        kind: ListKind::Member(Pattern::new(x)),
        list: l,
    })
}

/// `a` is immediately followed by `b` in `l`: the answers of [`nextto_rel`],
/// walking the known part of the list directly like [`membero`].
pub fn nextto(a: Term, b: Term, l: Term) -> Goal {
    Goal::native(ListGoal {
        kind: ListKind::NextTo(Pattern::new(a), Pattern::new(b)),
        list: l,
    })
}

/// `a` and `b` are neighbours in `l`, in either order.
pub fn next_to(a: Term, b: Term, l: Term) -> Goal {
    disj([nextto(a.clone(), b.clone(), l.clone()), nextto(b, a, l)])
}

/// Anonymous variables handed out one by one (Prolog's `_`).
struct Anon(std::vec::IntoIter<Term>);

impl Anon {
    fn next(&mut self) -> Term {
        self.0.next().unwrap_or(Term::Nil)
    }

    /// A house `h(Color, Nationality, Pet, Drink, Smoke)`; `""` is `_`.
    fn house(&mut self, slots: [&str; 5]) -> Term {
        Term::app(
            "h",
            slots.map(|s| if s.is_empty() { self.next() } else { sym(s) }),
        )
    }
}

/// The number of `_` in the puzzle below.
const ZEBRA_ANON: usize = 75;

/// The zebra puzzle (five houses), in the classic member/nextto formulation
/// and constraint order of `shared/bench/zebra.pl`: `hs` is the list of the
/// five houses `h(Color, Nationality, Pet, Drink, Smoke)`.
pub fn zebrao(hs: Term) -> Goal {
    zebra_with(hs, membero, nextto)
}

/// [`zebrao`] with the textbook relational [`membero_rel`] and [`nextto_rel`].
pub fn zebrao_rel(hs: Term) -> Goal {
    zebra_with(hs, membero_rel, nextto_rel)
}

fn zebra_with(
    hs: Term,
    membero: fn(Term, Term) -> Goal,
    nextto: fn(Term, Term, Term) -> Goal,
) -> Goal {
    let next_to = move |a: Term, b: Term, l: Term| {
        disj([nextto(a.clone(), b.clone(), l.clone()), nextto(b, a, l)])
    };
    fresh(move |vars: [Term; ZEBRA_ANON]| {
        let mut a = Anon(Vec::from(vars).into_iter());
        let houses = Term::list([
            a.house(["", "norwegian", "", "", ""]),
            a.next(),
            a.house(["", "", "", "milk", ""]),
            a.next(),
            a.next(),
        ]);
        let hs = hs.clone();
        let mut member = |slots: [&str; 5]| membero(a.house(slots), hs.clone());
        let g1 = member(["red", "english", "", "", ""]);
        let g2 = member(["", "spanish", "dog", "", ""]);
        let g3 = member(["green", "", "", "coffee", ""]);
        let g4 = member(["", "ukrainian", "", "tea", ""]);
        let ivory = a.house(["ivory", "", "", "", ""]);
        let green = a.house(["green", "", "", "", ""]);
        let g5 = nextto(ivory, green, hs.clone());
        let mut member = |slots: [&str; 5]| membero(a.house(slots), hs.clone());
        let g6 = member(["", "", "snails", "", "oldgold"]);
        let g7 = member(["yellow", "", "", "", "kools"]);
        let mut near = |x: [&str; 5], y: [&str; 5]| {
            let (x, y) = (a.house(x), a.house(y));
            next_to(x, y, hs.clone())
        };
        let g8 = near(["", "", "", "", "chesterfield"], ["", "", "fox", "", ""]);
        let g9 = near(["", "", "", "", "kools"], ["", "", "horse", "", ""]);
        let mut member = |slots: [&str; 5]| membero(a.house(slots), hs.clone());
        let g10 = member(["", "", "", "orange_juice", "lucky_strike"]);
        let g11 = member(["", "japanese", "", "", "parliament"]);
        let mut near = |x: [&str; 5], y: [&str; 5]| {
            let (x, y) = (a.house(x), a.house(y));
            next_to(x, y, hs.clone())
        };
        let g12 = near(["", "norwegian", "", "", ""], ["blue", "", "", "", ""]);
        let mut member = |slots: [&str; 5]| membero(a.house(slots), hs.clone());
        let g13 = member(["", "", "zebra", "", ""]);
        let g14 = member(["", "", "", "water", ""]);
        conj([
            eq(hs.clone(), houses),
            g1,
            g2,
            g3,
            g4,
            g5,
            g6,
            g7,
            g8,
            g9,
            g10,
            g11,
            g12,
            g13,
            g14,
        ])
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::{Query, RunConfig};

    #[test]
    fn zebra_uses_exactly_its_anonymous_variables() {
        // Every `_` must get its own variable: running out would silently
        // turn one into `[]` and change the puzzle.
        let mut q = Query::new();
        let hs = q.var("hs");
        let answers: Vec<_> = q.run(zebrao(hs), RunConfig::default()).collect();
        assert_eq!(answers.len(), 1);
        let text = answers[0]
            .as_ref()
            .map(|a| a.to_string())
            .unwrap_or_default();
        assert!(!text.contains("[]"), "{text}");
        assert!(
            text.contains("h(green, japanese, zebra, coffee, parliament)"),
            "{text}"
        );
        assert!(
            text.contains("h(yellow, norwegian, fox, water, kools)"),
            "{text}"
        );
    }
}
