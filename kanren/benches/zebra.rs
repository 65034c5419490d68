//! The zebra puzzle, all solutions.

use criterion::{Criterion, criterion_group, criterion_main};
use kanren::classic::zebrao;
use kanren::{Query, RunConfig};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("zebra_all_solutions");
    g.sample_size(10);
    for occurs in [true, false] {
        let mut q = Query::new();
        q.set_occurs_check(occurs);
        let hs = q.var("houses");
        g.bench_function(
            if occurs {
                "occurs_check"
            } else {
                "no_occurs_check"
            },
            |b| {
                b.iter(|| {
                    let n = q
                        .run(zebrao(hs.clone()), RunConfig::default())
                        .filter(|a| a.is_ok())
                        .count();
                    assert_eq!(n, 1);
                    black_box(n)
                })
            },
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
