//! Per-detection work after the model, on generated input (no `../shared`):
//! colour naming of 15 boxes in a KITTI-sized frame, and the monocular
//! depth estimators (flat ground, size prior, fused) for 1000 boxes.
//!
//! ```sh
//! cargo bench -p perception --bench raw_color_depth
//! ```

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use image::{Rgb, RgbImage};
use perception::BBox2D;
use perception::raw::color::{ColorConfig, name_box};
use perception::raw::ground::GroundConfig;
use perception::raw::mono::{MonoDepthConfig, MonoDepthMethod, estimate};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn boxes(n: usize, seed: u64) -> Vec<BBox2D> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let (left, top) = (
                rng.random_range(0.0..1100.0),
                rng.random_range(150.0..200.0),
            );
            BBox2D {
                left,
                top,
                right: left + rng.random_range(30.0..140.0),
                bottom: top + rng.random_range(25.0..150.0_f64).min(370.0 - top),
            }
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let img = RgbImage::from_fn(1242, 375, |x, y| {
        let n: u8 = rng.random_range(0..40);
        Rgb([
            ((x / 80) * 37 % 200) as u8 + n,
            ((y / 40) * 53 % 200) as u8 + n,
            120 + n,
        ])
    });
    let mut group = c.benchmark_group("raw_color_depth");
    group.sample_size(30);
    let few = boxes(15, 1);
    group.throughput(Throughput::Elements(few.len() as u64));
    group.bench_function("colour_15_boxes", |b| {
        let config = ColorConfig::default();
        b.iter(|| {
            few.iter()
                .filter(|bx| name_box(black_box(&img), bx, &config).is_some())
                .count()
        })
    });
    let camera = perception::kitti::KITTI_2011_09_26_CAMERA;
    let many = boxes(1000, 2);
    group.throughput(Throughput::Elements(many.len() as u64));
    let ground = GroundConfig::default();
    for method in [
        MonoDepthMethod::FlatGround,
        MonoDepthMethod::SizePrior,
        MonoDepthMethod::Fused,
    ] {
        let config = MonoDepthConfig::default().with_method(method);
        group.bench_function(format!("depth_{method:?}_1000_boxes"), |b| {
            b.iter(|| {
                many.iter()
                    .filter_map(|bx| {
                        estimate(black_box(bx), Some("Car"), &camera, &ground, &config)
                    })
                    .map(|e| e.z())
                    .sum::<f64>()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
