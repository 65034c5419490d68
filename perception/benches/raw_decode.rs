//! Raw-frames post-processing on generated model outputs (no model, no
//! runtime, no `../shared`): the NanoDet-m 416 GFL decoder over one tile's
//! outputs (strides 8/16/32, 80 classes, reg_max 10; 3549 cells of which a
//! few dozen score above the threshold, as on KITTI), the output finite
//! check, and per-class NMS with the tile-seam containment rule over three
//! tiles' detections.
//!
//! ```sh
//! cargo bench -p perception --bench raw_decode
//! ```

use std::hint::black_box;
use std::path::Path;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use perception::raw::decode::{self, RawDetection};
use perception::raw::runtime::{ModelOutput, check_output};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

const INPUT: u32 = 416;
const STRIDES: [u32; 3] = [8, 16, 32];
const REG_MAX: u32 = 10;
const CLASSES: usize = 80;
const THRESHOLD: f32 = 0.45;

/// One tile's outputs: scores mostly low (sigmoid outputs of background),
/// `hot` cells with one class above the threshold, random box logits.
fn outputs(seed: u64, hot: usize) -> Vec<ModelOutput> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut out = Vec::new();
    for s in STRIDES {
        let cells = ((INPUT / s) * (INPUT / s)) as usize;
        let mut scores: Vec<f32> = (0..cells * CLASSES)
            .map(|_| rng.random::<f32>() * 0.2)
            .collect();
        for _ in 0..hot {
            let cell = rng.random_range(0..cells);
            let class = [0usize, 2, 7][rng.random_range(0..3)];
            scores[cell * CLASSES + class] = 0.5 + 0.5 * rng.random::<f32>();
        }
        let regs: Vec<f32> = (0..cells * 4 * (REG_MAX as usize + 1))
            .map(|_| rng.random::<f32>() * 4.0 - 2.0)
            .collect();
        out.push(ModelOutput {
            name: format!("cls{s}"),
            shape: vec![1, cells, CLASSES],
            data: scores,
        });
        out.push(ModelOutput {
            name: format!("reg{s}"),
            shape: vec![1, cells, 4 * (REG_MAX as usize + 1)],
            data: regs,
        });
    }
    out
}

fn decode_tile(outs: &[ModelOutput]) -> Vec<RawDetection> {
    decode::nanodet_gfl(
        Path::new("generated.onnx"),
        outs,
        &STRIDES,
        REG_MAX,
        CLASSES,
        INPUT,
        INPUT,
        THRESHOLD,
    )
    .unwrap_or_default()
}

fn bench(c: &mut Criterion) {
    let tiles: Vec<Vec<ModelOutput>> = (0..3).map(|i| outputs(11 + i, 12)).collect();
    let mut group = c.benchmark_group("raw_decode");
    group.throughput(Throughput::Elements(1));
    group.sample_size(30);
    group.bench_function("gfl_decode_one_tile", |b| {
        b.iter(|| decode_tile(black_box(&tiles[0])).len())
    });
    group.bench_function("finite_check_one_tile", |b| {
        b.iter(|| {
            black_box(&tiles[0])
                .iter()
                .all(|o| check_output(Path::new("generated.onnx"), o).is_ok())
        })
    });
    let all: Vec<RawDetection> = tiles.iter().flat_map(|t| decode_tile(t)).collect();
    assert!(
        all.len() >= 30,
        "generated outputs give {} detections",
        all.len()
    );
    group.bench_function("nms_three_tiles", |b| {
        b.iter(|| decode::nms(black_box(all.clone()), 0.5, 0.8, 100).len())
    });
    group.bench_function("decode_and_nms_three_tiles", |b| {
        b.iter(|| {
            let dets: Vec<RawDetection> = tiles
                .iter()
                .flat_map(|t| decode_tile(black_box(t)))
                .collect();
            decode::nms(dets, 0.5, 0.8, 100).len()
        })
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
