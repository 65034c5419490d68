//! KITTI labels → window facts for all 21 sequences (10-frame windows),
//! reported as frames per second (criterion throughput in elements =
//! frames). Target: >= 20,000 frames/s on one core in release mode.
//!
//! ```sh
//! cargo bench -p perception --bench kitti_facts
//! ```
//! Needs `../shared/data/kitti-tracking`.

use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use perception::{FactConfig, Sequence, WindowSpec, kitti, window_facts};

fn load_all() -> Vec<Sequence> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/kitti-tracking");
    let names = kitti::list_sequences(&root)
        .unwrap_or_else(|e| panic!("KITTI labels needed for this bench: {e}"));
    names
        .iter()
        .map(|n| {
            kitti::load(&root, n)
                .unwrap_or_else(|e| panic!("{e}"))
                .sequence
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let seqs = load_all();
    let frames: u64 = seqs.iter().map(|s| u64::from(s.frame_count)).sum();
    let config = FactConfig::default();
    let mut group = c.benchmark_group("kitti_labels_to_facts");
    group.throughput(Throughput::Elements(frames));
    group.sample_size(20);
    group.bench_function("all_21_sequences", |b| {
        b.iter(|| {
            let mut n = 0usize;
            for s in &seqs {
                n += window_facts(s, WindowSpec::PAPER, &config)
                    .map(|w| w.len())
                    .unwrap_or(0);
            }
            n
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
