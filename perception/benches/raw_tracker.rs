//! The Hungarian IoU tracker on generated scenes (no `../shared`): 10 and
//! 40 objects moving across a KITTI-sized frame for 100 frames with box
//! jitter and 5% missed detections; throughput in frames.
//!
//! ```sh
//! cargo bench -p perception --bench raw_tracker
//! ```

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use perception::raw::tracker::{TrackInput, Tracker, TrackerConfig};
use perception::{BBox2D, ObjectClass};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

const FRAMES: u32 = 100;

/// Per frame, the detections of `objects` boxes on straight paths.
fn scene(objects: usize, seed: u64) -> Vec<Vec<TrackInput>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let paths: Vec<(f64, f64, f64, f64, f64, ObjectClass)> = (0..objects)
        .map(|i| {
            let class = if i % 4 == 0 {
                ObjectClass::Pedestrian
            } else {
                ObjectClass::Vehicle
            };
            (
                rng.random_range(0.0..1100.0),
                rng.random_range(150.0..250.0),
                rng.random_range(-4.0..4.0),
                rng.random_range(30.0..120.0),
                rng.random_range(25.0..90.0),
                class,
            )
        })
        .collect();
    let mut frames = Vec::new();
    for f in 0..FRAMES {
        let mut dets = Vec::new();
        for &(x, y, vx, w, h, class) in &paths {
            if rng.random::<f64>() < 0.05 {
                continue;
            }
            let mut j = || rng.random_range(-1.5..1.5);
            let left = x + vx * f64::from(f) + j();
            let top = y + j();
            dets.push(TrackInput {
                class,
                bbox: BBox2D {
                    left,
                    top,
                    right: left + w + j(),
                    bottom: top + h + j(),
                },
            });
        }
        frames.push(dets);
    }
    frames
}

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("raw_tracker");
    group.throughput(Throughput::Elements(u64::from(FRAMES)));
    group.sample_size(30);
    for objects in [10usize, 40] {
        let frames = scene(objects, 3);
        group.bench_function(format!("{objects}_objects_100_frames"), |b| {
            b.iter(|| {
                let mut t = Tracker::new(TrackerConfig::default());
                let mut ids = 0usize;
                for (f, dets) in frames.iter().enumerate() {
                    ids += t.step(f as u32, black_box(dets), None).len();
                }
                ids
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
