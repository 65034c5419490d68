//! Frames per second of the whole raw-frames pipeline (decode PNG → tiles →
//! NanoDet → GFL decode → NMS → class map → colour → flat ground → tracker →
//! sequence → window facts), with the model's own run time beside everything
//! else. Target: everything that is not the model under 10% of the model.
//!
//! ```text
//! cargo run --release -p perception --example raw_pipeline_fps -- [--repeat N] [--dir FRAMES_DIR]... [--models FILE]
//! ```
//! Defaults: the KITTI frames of `../shared/data/kitti-tracking/image_02/*`
//! and `perception/models/nanodet-m-416-coco.yaml`, 3 repeats.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use perception::raw::detect::StageTimes;
use perception::raw::frames::{FramesOptions, FramesPipeline, ModelSet};
use perception::raw::config::{DetectorDecoder, ModelConfig, OutputSpec};
use perception::raw::runtime::Runtime;
use perception::raw::{color, decode, detect, frames, preprocess};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut models = root.join("models/nanodet-m-416-coco.yaml");
    let mut dirs: Vec<PathBuf> = Vec::new();
    let mut repeat = 3u32;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or_else(|| format!("{a} needs a value"));
        match a.as_str() {
            "--models" => models = PathBuf::from(value()?),
            "--dir" => dirs.push(PathBuf::from(value()?)),
            "--repeat" => repeat = value()?.parse()?,
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    if dirs.is_empty() {
        let images = root.join("../../shared/data/kitti-tracking/image_02");
        let mut found: Vec<PathBuf> = std::fs::read_dir(&images)?.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.is_dir()).collect();
        found.sort();
        dirs = found;
    }
    let runtime = Runtime::discover()?;
    println!("runtime {}", runtime.library().display());
    let cpus = std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1);
    println!("CPU execution provider, {cpus} logical CPUs available");
    // Sessions are created once; a warm-up pass pays for first-run costs.
    let setup = Instant::now();
    let mut pipeline = FramesPipeline::open(&runtime, ModelSet::load(&models)?)?;
    println!("session setup {:.0} ms (once)", setup.elapsed().as_secs_f64() * 1e3);
    let _ = pipeline.run(&dirs[0], &FramesOptions::default(), &mut |_| {})?;
    let mut frames = 0u32;
    let mut times = StageTimes::default();
    let mut wall = Duration::ZERO;
    let mut facts = 0usize;
    for _ in 0..repeat {
        for dir in &dirs {
            let start = Instant::now();
            let mut last = StageTimes::default();
            let seq = pipeline.run(dir, &FramesOptions::default(), &mut |p| last = p.times)?;
            let windows = perception::window_facts(&seq, perception::WindowSpec::PAPER, &Default::default())?;
            wall += start.elapsed();
            facts += windows.iter().map(|w| w.facts.len()).sum::<usize>();
            frames += seq.frame_count;
            times.add(last);
        }
    }
    let n = f64::from(frames.max(1));
    let ms = |d: Duration| d.as_secs_f64() * 1e3 / n;
    let model = ms(times.model);
    let other = ms(times.other);
    let io_and_rest = ms(wall.saturating_sub(times.model + times.other));
    println!("{frames} frames ({} dirs x {repeat}), {facts} facts", dirs.len());
    println!("frames/s (whole pipeline, wall clock): {:.2}", n / wall.as_secs_f64());
    println!("per frame: model {model:.1} ms | pre/post-processing, tracking, colour, 3D {other:.1} ms ({:.1}% of model)", 100.0 * other / model);
    println!("           PNG decoding, sequence + window facts {io_and_rest:.1} ms ({:.1}% of model)", 100.0 * io_and_rest / model);
    stage_breakdown(&runtime, &models, &dirs[0])?;
    println!("non-model total {:.1}% of model time: {}", 100.0 * (other + io_and_rest) / model, if other + io_and_rest < 0.1 * model { "PASS (< 10%)" } else { "FAIL (>= 10%)" });
    Ok(())
}

/// Times each stage of one frame on its own (median of 7 runs), to show
/// where the non-model time goes.
fn stage_breakdown(runtime: &Runtime, models: &std::path::Path, dir: &std::path::Path) -> Result<(), Box<dyn std::error::Error>> {
    let set = ModelSet::load(models)?;
    let loaded = set.detector;
    let _ = ModelConfig::load(&loaded.config_path)?;
    let path = frames::list_frames(dir)?.into_iter().next().ok_or("no frame")?;
    let mut runner = detect::open_model(runtime, &loaded)?;
    let spec = loaded.config.input.clone();
    let OutputSpec::Detector { decoder: DetectorDecoder::NanodetGfl { strides, reg_max, num_classes }, score_threshold, nms_iou, containment, max_detections } = &loaded.config.output else {
        return Err("not a GFL detector".into());
    };
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut t = [vec![], vec![], vec![], vec![], vec![]];
    let mut tensor = preprocess::new_tensor(&spec);
    for _ in 0..7 {
        let s = Instant::now();
        let img = image::open(&path)?.to_rgb8();
        t[0].push(s.elapsed().as_secs_f64());
        let patches = preprocess::plan(&spec, img.width(), img.height());
        let mut raw = Vec::new();
        let (mut fill, mut model, mut dec) = (0.0, 0.0, 0.0);
        for p in &patches {
            let s = Instant::now();
            preprocess::fill(&spec, &img, p, &mut tensor);
            fill += s.elapsed().as_secs_f64();
            let s = Instant::now();
            let outputs = runner.run(tensor.view().into_dyn())?;
            model += s.elapsed().as_secs_f64();
            let s = Instant::now();
            raw.extend(decode::nanodet_gfl(runner.path(), &outputs, strides, *reg_max, *num_classes, spec.width, spec.height, *score_threshold)?.into_iter().map(|d| decode::RawDetection { bbox: p.to_frame(&d.bbox), ..d }));
            dec += s.elapsed().as_secs_f64();
        }
        let s = Instant::now();
        let kept = decode::nms(raw, f64::from(*nms_iou), f64::from(*containment), *max_detections);
        dec += s.elapsed().as_secs_f64();
        let s = Instant::now();
        for d in &kept {
            let _ = color::name_box(&img, &d.bbox, &color::ColorConfig::default());
        }
        t[4].push(s.elapsed().as_secs_f64());
        t[1].push(fill);
        t[2].push(model);
        t[3].push(dec);
    }
    let ms = |v: &Vec<f64>| median(v.clone()) * 1e3;
    println!(
        "stages of one frame (median of 7): PNG decode {:.1} ms | resample+normalise {:.1} ms | model {:.1} ms | GFL decode+NMS {:.1} ms | colour {:.1} ms",
        ms(&t[0]),
        ms(&t[1]),
        ms(&t[2]),
        ms(&t[3]),
        ms(&t[4])
    );
    Ok(())
}
