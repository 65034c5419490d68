//! Indexed fact joins: `TypeOf(x, car) ^ ColorOf(x, white) ^ SpeedUp(x)` over
//! a KB with a fixed number of relevant vehicles and a growing number of
//! unrelated ones. The time should stay flat as the unrelated facts double.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use kanren::{Goal, Query, Relation, RunConfig, Term, conj, fact, sym};
use std::hint::black_box;
use std::sync::Arc;

struct Kb {
    type_of: Arc<Relation>,
    color_of: Arc<Relation>,
    speed_up: Arc<Relation>,
}

fn kb(relevant: usize, unrelated: usize) -> Kb {
    let mut type_of = Relation::new("type_of", 2);
    let mut color_of = Relation::new("color_of", 2);
    let mut speed_up = Relation::new("speed_up", 1);
    let mut add = |name: String, ty: &str, color: &str, fast: bool| {
        let v = sym(&name);
        let _ = type_of.insert(&[v.clone(), sym(ty)]);
        let _ = color_of.insert(&[v.clone(), sym(color)]);
        if fast {
            let _ = speed_up.insert(&[v]);
        }
    };
    for i in 0..relevant {
        add(
            format!("car{i}"),
            "car",
            if i % 2 == 0 { "white" } else { "red" },
            i % 3 == 0,
        );
    }
    for i in 0..unrelated {
        add(format!("other{i}"), "truck", "blue", i % 2 == 0);
    }
    Kb {
        type_of: Arc::new(type_of),
        color_of: Arc::new(color_of),
        speed_up: Arc::new(speed_up),
    }
}

// white_fast_car(x) :- type_of(x, car), color_of(x, white), speed_up(x).
fn query(kb: &Kb, x: &Term) -> Goal {
    conj([
        fact(&kb.type_of, vec![x.clone(), sym("car")]),
        fact(&kb.color_of, vec![x.clone(), sym("white")]),
        fact(&kb.speed_up, vec![x.clone()]),
    ])
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("indexed_fact_join");
    for unrelated in [10_000usize, 20_000, 40_000, 80_000] {
        let kb = kb(200, unrelated);
        let mut q = Query::new();
        let x = q.var("x");
        g.bench_with_input(
            BenchmarkId::new("unrelated_facts", unrelated),
            &unrelated,
            |b, _| {
                b.iter(|| {
                    let n = q
                        .run(query(&kb, &x), RunConfig::default())
                        .filter(|a| a.is_ok())
                        .count();
                    assert_eq!(n, 34);
                    black_box(n)
                })
            },
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
