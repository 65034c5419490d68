//! Raw-frames pre-processing on generated input (no `../shared` needed): a
//! KITTI-sized 1242×375 frame cut into the shipped NanoDet config's three
//! 416×416 tiles and resampled into its tensors, the same frame letterboxed,
//! and PNG decoding of a generated frame of that size.
//!
//! ```sh
//! cargo bench -p perception --bench raw_preprocess
//! ```

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use image::{Rgb, RgbImage};
use perception::raw::config::{ModelConfig, ResizeMode};
use perception::raw::detect::Preparer;
use perception::raw::preprocess;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A road-like frame: smooth gradients plus seeded pixel noise (pure noise
/// would make PNG decoding unrealistically slow, flat colour unrealistically
/// fast).
fn frame(width: u32, height: u32) -> RgbImage {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    RgbImage::from_fn(width, height, |x, y| {
        let n: i32 = rng.random_range(-6..=6);
        let v = |base: u32| (base as i32 + n).clamp(0, 255) as u8;
        Rgb([
            v(x * 200 / width + 20),
            v(y * 180 / height + 30),
            v((x + y) % 160 + 40),
        ])
    })
}

fn bench(c: &mut Criterion) {
    let config = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/nanodet-m-416-coco.yaml");
    let loaded = ModelConfig::load(&config).unwrap_or_else(|e| panic!("{e}"));
    let tiles = loaded.config.input.clone();
    let img = frame(1242, 375);
    let mut group = c.benchmark_group("raw_preprocess");
    group.throughput(Throughput::Elements(1));
    group.sample_size(30);

    let mut tensor = preprocess::new_tensor(&tiles);
    let patches = preprocess::plan(&tiles, img.width(), img.height());
    assert_eq!(
        patches.len(),
        3,
        "the shipped config tiles KITTI frames in three"
    );
    group.bench_function("tiles3_fill_1242x375", |b| {
        b.iter(|| {
            for p in &patches {
                preprocess::fill(&tiles, black_box(&img), p, &mut tensor);
            }
            tensor[[0, 0, 0, 0]]
        })
    });

    let preparer = detector_preparer(&loaded);
    let mut recycled = Vec::new();
    group.bench_function("tiles3_prepare_reusing_tensors", |b| {
        b.iter(|| {
            let prepared = preparer.prepare(black_box(&img), std::mem::take(&mut recycled));
            recycled = prepared.tensors;
            recycled.len()
        })
    });

    let mut letterbox = tiles.clone();
    letterbox.resize = ResizeMode::Letterbox;
    let mut tensor = preprocess::new_tensor(&letterbox);
    let patch = preprocess::plan(&letterbox, img.width(), img.height())[0];
    group.bench_function("letterbox_fill_1242x375", |b| {
        b.iter(|| {
            preprocess::fill(&letterbox, black_box(&img), &patch, &mut tensor);
            tensor[[0, 0, 0, 0]]
        })
    });

    let mut png = Vec::new();
    img.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
        .unwrap_or_else(|e| panic!("{e}"));
    group.bench_function("png_decode_1242x375", |b| {
        b.iter(|| {
            image::load_from_memory_with_format(black_box(&png), image::ImageFormat::Png)
                .map(|i| i.into_rgb8().width())
                .unwrap_or(0)
        })
    });
    group.finish();
}

/// The detector's preparer without opening a model (no runtime needed).
fn detector_preparer(loaded: &perception::raw::config::LoadedConfig) -> Preparer {
    Preparer::new(loaded.config.input.clone())
}

criterion_group!(benches, bench);
criterion_main!(benches);
