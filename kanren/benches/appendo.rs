//! appendo: every split of the list [1..N] (`run* (x y) (appendo x y L)`).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use kanren::classic::appendo;
use kanren::{Query, RunConfig, Term};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("appendo_all_splits");
    for n in [100usize, 400] {
        let list = Term::list((1..=n as i64).map(Term::Int));
        for occurs in [true, false] {
            let mut q = Query::new();
            q.set_occurs_check(occurs);
            let (x, y) = (q.var("x"), q.var("y"));
            let id = BenchmarkId::new(
                if occurs {
                    "occurs_check"
                } else {
                    "no_occurs_check"
                },
                n,
            );
            g.bench_with_input(id, &n, |b, &n| {
                b.iter(|| {
                    let count = q
                        .run(
                            appendo(x.clone(), y.clone(), list.clone()),
                            RunConfig::default(),
                        )
                        .filter(|a| a.is_ok())
                        .count();
                    assert_eq!(count, n + 1);
                    black_box(count)
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
