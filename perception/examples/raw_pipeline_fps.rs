//! Frames per second of the whole raw-frames pipeline (decode PNG → tiles →
//! NanoDet → GFL decode → NMS → class map → colour → flat ground → tracker →
//! sequence → window facts), with the model's own run time beside everything
//! else, serial and with the next frame prefetched on a second thread (both
//! in the same run, interleaved). Target: everything that is not the model
//! under 10% of the model.
//!
//! ```text
//! cargo run --release -p perception --example raw_pipeline_fps -- [--repeat N] [--dir FRAMES_DIR]... [--models FILE] [--threads N] [--concat N]
//! ```
//! Defaults: the KITTI frames of `../shared/data/kitti-tracking/image_02/*`
//! and `perception/models/nanodet-m-416-coco.yaml`, 3 repeats. `--concat N`
//! times one long folder (all frames copied N times into a temporary
//! folder); `--threads N` overrides the config's ONNX Runtime intra-op
//! threads.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use perception::raw::config::{DetectorDecoder, ModelConfig, OutputSpec};
use perception::raw::detect::StageTimes;
use perception::raw::frames::{FramesOptions, FramesPipeline, ModelSet};
use perception::raw::runtime::Runtime;
use perception::raw::{color, decode, detect, frames, preprocess};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut models = root.join("models/nanodet-m-416-coco.yaml");
    let mut dirs: Vec<PathBuf> = Vec::new();
    let mut repeat = 3u32;
    let mut threads: Option<usize> = None;
    let mut concat = 0usize;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or_else(|| format!("{a} needs a value"));
        match a.as_str() {
            "--models" => models = PathBuf::from(value()?),
            "--dir" => dirs.push(PathBuf::from(value()?)),
            "--repeat" => repeat = value()?.parse()?,
            "--threads" => threads = Some(value()?.parse()?),
            "--concat" => concat = value()?.parse()?,
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    if dirs.is_empty() {
        let images = root.join("../../shared/data/kitti-tracking/image_02");
        let mut found: Vec<PathBuf> = std::fs::read_dir(&images)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.is_dir())
            .collect();
        found.sort();
        dirs = found;
    }
    // KITTI's image folders hold three frames each, so the first frame of
    // every folder (never prefetched) weighs a third. `--concat N` copies
    // each folder's frames N times into a temporary folder of its own to
    // time long sequences (the tracks are meaningless; the timing is not).
    let concat_dir = std::env::temp_dir().join(format!("raw-pipeline-fps-{}", std::process::id()));
    if concat > 0 {
        let mut long = Vec::new();
        for (i, dir) in dirs.iter().enumerate() {
            let out = concat_dir.join(format!("{i}"));
            std::fs::create_dir_all(&out)?;
            let files = frames::list_frames(dir)?;
            for k in 0..concat * files.len() {
                std::fs::copy(&files[k % files.len()], out.join(format!("{k:06}.png")))?;
            }
            long.push(out);
        }
        println!(
            "timing {} folders, each its frames copied {concat} times, in {}",
            long.len(),
            concat_dir.display()
        );
        dirs = long;
    }
    let runtime = Runtime::discover()?;
    println!("runtime {}", runtime.library().display());
    let cpus = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let mut set = ModelSet::load(&models)?;
    if let Some(t) = threads {
        set.detector.config.threads = t;
    }
    let intra = set.detector.config.threads;
    println!(
        "CPU execution provider, {cpus} logical CPUs; ONNX Runtime intra-op threads: {} (spinning off)",
        if intra == 0 {
            "0 = ONNX Runtime default (one per physical core)".to_string()
        } else {
            intra.to_string()
        }
    );
    // Sessions are created once; a warm-up pass pays for first-run costs.
    let setup = Instant::now();
    let mut pipeline = FramesPipeline::open(&runtime, set)?;
    println!(
        "session setup {:.0} ms (once)",
        setup.elapsed().as_secs_f64() * 1e3
    );
    let _ = pipeline.run(&dirs[0], &FramesOptions::default(), &mut |_| {})?;
    // Both modes in the same run, interleaved repeat by repeat, so machine
    // load affects them alike.
    let mut stats = [Stats::default(), Stats::default()];
    for _ in 0..repeat {
        for (mode, prefetch) in [false, true].into_iter().enumerate() {
            let options = FramesOptions {
                prefetch,
                ..FramesOptions::default()
            };
            stats[mode].start_repeat();
            for dir in &dirs {
                let start = Instant::now();
                let mut last = StageTimes::default();
                let seq = pipeline.run(dir, &options, &mut |p| last = p.times)?;
                let windows = perception::window_facts(
                    &seq,
                    perception::WindowSpec::PAPER,
                    &Default::default(),
                )?;
                let wall = start.elapsed();
                let st = &mut stats[mode];
                st.wall += wall;
                st.facts += windows.iter().map(|w| w.facts.len()).sum::<usize>();
                st.frames += seq.frame_count;
                st.times.add(last);
                if let Some(r) = st.repeats.last_mut() {
                    r.frames += seq.frame_count;
                    r.wall += wall;
                    r.times.add(last);
                }
            }
        }
    }
    let reference_model = stats[0].median(|r| r.times.model);
    for (mode, s) in stats.iter().enumerate() {
        let label = if mode == 0 {
            "serial (decode + resample on the model's thread)"
        } else {
            "prefetch (decode + resample of frame i+1 on a second thread)"
        };
        let wall = s.median(|r| r.wall);
        let model = s.median(|r| r.times.model);
        let other = s.median(|r| r.times.other);
        let rest = s.median(|r| r.wall.saturating_sub(r.times.model + r.times.other));
        println!(
            "{label}: {} frames ({} dirs x {repeat}), {} facts; per-frame figures are medians over the {repeat} repeats",
            s.frames,
            dirs.len(),
            s.facts
        );
        println!(
            "  frames/s (whole pipeline, wall clock): {:.2}  ({wall:.1} ms per frame)",
            1e3 / wall
        );
        println!(
            "  model {model:.1} ms per frame | on the main thread besides the model: {other:.1} ms (decode+NMS, colour, 3D, tracking{}) | sequence, window facts{}: {rest:.1} ms",
            if mode == 0 {
                ", PNG decode, resample"
            } else {
                ""
            },
            if mode == 1 {
                ", waiting for the loader"
            } else {
                ""
            }
        );
        if mode == 1 {
            println!(
                "  prefetch thread: {:.1} ms per frame (PNG decode + resample, wall time of that thread), overlapped with the model",
                s.median(|r| r.times.prefetch)
            );
        }
        println!(
            "  non-model share = (wall - model) / model: {:.1}%  | against the serial run's model time ({reference_model:.1} ms): {:.1}%",
            100.0 * (wall - model) / model,
            100.0 * (wall - reference_model) / reference_model
        );
    }
    stage_breakdown(&runtime, &models, &dirs[0])?;
    if concat > 0 {
        std::fs::remove_dir_all(&concat_dir)?;
    }
    // The larger of the prefetch run's own share and its wall time against
    // the serial run's model time: the second catches a prefetch thread that
    // slows the model down, the first keeps noise in the serial run's model
    // time (it can make the second negative) from hiding real overhead.
    let own = (stats[1].median(|r| r.wall) - stats[1].median(|r| r.times.model))
        / stats[1].median(|r| r.times.model);
    let share = own.max((stats[1].median(|r| r.wall) - reference_model) / reference_model);
    if concat == 0 {
        println!(
            "(the first frame of each folder is never prefetched; with 3-frame folders it weighs a third: `--concat 5` times a long sequence)"
        );
    }
    println!(
        "non-model total (prefetch run, the larger of its own share and its wall vs the serial model time): {:.1}% of model time: {}",
        100.0 * share,
        if share < 0.1 {
            "PASS (< 10%)"
        } else {
            "FAIL (>= 10%)"
        }
    );
    Ok(())
}

/// One repeat of one mode over every directory.
#[derive(Default, Clone, Copy)]
struct Repeat {
    frames: u32,
    wall: Duration,
    times: StageTimes,
}

/// Totals and repeats of one mode.
#[derive(Default)]
struct Stats {
    frames: u32,
    facts: usize,
    wall: Duration,
    times: StageTimes,
    repeats: Vec<Repeat>,
}

impl Stats {
    fn start_repeat(&mut self) {
        self.repeats.push(Repeat::default());
    }

    /// Median over the repeats of a per-frame figure, milliseconds.
    fn median(&self, f: impl Fn(&Repeat) -> Duration) -> f64 {
        let mut v: Vec<f64> = self
            .repeats
            .iter()
            .map(|r| f(r).as_secs_f64() * 1e3 / f64::from(r.frames.max(1)))
            .collect();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f64::NAN)
    }
}

/// Times each stage of one frame on its own (median of 7 runs), to show
/// where the non-model time goes.
fn stage_breakdown(
    runtime: &Runtime,
    models: &std::path::Path,
    dir: &std::path::Path,
) -> Result<(), Box<dyn std::error::Error>> {
    let set = ModelSet::load(models)?;
    let loaded = set.detector;
    let _ = ModelConfig::load(&loaded.config_path)?;
    let path = frames::list_frames(dir)?
        .into_iter()
        .next()
        .ok_or("no frame")?;
    let mut runner = detect::open_model(runtime, &loaded)?;
    let spec = loaded.config.input.clone();
    let OutputSpec::Detector {
        decoder:
            DetectorDecoder::NanodetGfl {
                strides,
                reg_max,
                num_classes,
            },
        score_threshold,
        nms_iou,
        containment,
        max_detections,
    } = &loaded.config.output
    else {
        return Err("not a GFL detector".into());
    };
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut t = [vec![], vec![], vec![], vec![], vec![], vec![]];
    let mut tensor = preprocess::new_tensor(&spec);
    let model_path = loaded.model_path.clone();
    for _ in 0..7 {
        let s = Instant::now();
        let img = image::open(&path)?.into_rgb8();
        t[0].push(s.elapsed().as_secs_f64());
        let patches = preprocess::plan(&spec, img.width(), img.height());
        let mut raw = Vec::new();
        let (mut fill, mut model, mut dec, mut copy) = (0.0, 0.0, 0.0, 0.0);
        for p in &patches {
            let s = Instant::now();
            preprocess::fill(&spec, &img, p, &mut tensor);
            fill += s.elapsed().as_secs_f64();
            let s = Instant::now();
            let mut dec_inner = 0.0;
            let found = runner.run_with(tensor.view().into_dyn(), |outs| {
                let s = Instant::now();
                let r = decode::nanodet_gfl(
                    &model_path,
                    outs,
                    strides,
                    *reg_max,
                    *num_classes,
                    spec.width,
                    spec.height,
                    *score_threshold,
                );
                dec_inner = s.elapsed().as_secs_f64();
                r
            })?;
            let total = s.elapsed().as_secs_f64();
            let session = runner.last_session_time().as_secs_f64();
            model += session;
            dec += dec_inner;
            copy += total - session - dec_inner;
            raw.extend(found.into_iter().map(|d| decode::RawDetection {
                bbox: p.to_frame(&d.bbox),
                ..d
            }));
        }
        let s = Instant::now();
        let kept = decode::nms(
            raw,
            f64::from(*nms_iou),
            f64::from(*containment),
            *max_detections,
        );
        dec += s.elapsed().as_secs_f64();
        let s = Instant::now();
        for d in &kept {
            let _ = color::name_box(&img, &d.bbox, &color::ColorConfig::default());
        }
        t[4].push(s.elapsed().as_secs_f64());
        t[1].push(fill);
        t[2].push(model);
        t[3].push(dec);
        t[5].push(copy);
    }
    let ms = |v: &Vec<f64>| median(v.clone()) * 1e3;
    println!(
        "stages of one frame (median of 7): PNG decode {:.1} ms | resample+normalise {:.1} ms | model {:.1} ms | output extraction+finite check {:.1} ms | GFL decode+NMS {:.1} ms | colour {:.1} ms",
        ms(&t[0]),
        ms(&t[1]),
        ms(&t[2]),
        ms(&t[5]),
        ms(&t[3]),
        ms(&t[4])
    );
    Ok(())
}
