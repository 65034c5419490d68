//! Runs the configured detector over the six real KITTI frames in
//! `../shared/data/kitti-tracking` and prints car recall / precision (IoU ≥
//! 0.5, unoccluded, height ≥ 25 px) and the monocular depth of the matched
//! cars against the labelled Z by every method (flat ground, size prior,
//! fused; each with and without the nearest-face → centre correction).
//!
//! ```text
//! cargo run --release -p perception --example raw_kitti_eval -- \
//!     [--config perception/models/nanodet-m-416-coco.yaml] [--model FILE] \
//!     [--resize letterbox|stretch|tiles:N] [--threshold S] [--kitti DIR]
//! ```

use std::path::PathBuf;
use std::process::ExitCode;

use perception::raw::config::{ModelConfig, OutputSpec, ResizeMode};
use perception::raw::detect::{Detector, StageTimes};
use perception::raw::eval::{CarEvalCriteria, depth_method_variants, evaluate_kitti};
use perception::raw::ground::GroundConfig;
use perception::raw::mono::MonoDepthConfig;
use perception::raw::runtime::Runtime;

fn main() -> ExitCode {
    match run() {
        Ok(pass) => {
            if pass {
                ExitCode::SUCCESS
            } else {
                ExitCode::from(2)
            }
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<bool, Box<dyn std::error::Error>> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let mut config = root.join("models/nanodet-m-416-coco.yaml");
    let mut kitti = root.join("../../shared/data/kitti-tracking");
    let mut model = None;
    let mut resize = None;
    let mut threshold = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut value = || args.next().ok_or_else(|| format!("{a} needs a value"));
        match a.as_str() {
            "--config" => config = PathBuf::from(value()?),
            "--model" => model = Some(PathBuf::from(value()?)),
            "--kitti" => kitti = PathBuf::from(value()?),
            "--threshold" => threshold = Some(value()?.parse::<f32>()?),
            "--resize" => {
                let v = value()?;
                resize = Some(match v.as_str() {
                    "letterbox" => ResizeMode::Letterbox,
                    "stretch" => ResizeMode::Stretch,
                    t => {
                        let n = t
                            .strip_prefix("tiles:")
                            .ok_or("--resize letterbox|stretch|tiles:N")?;
                        ResizeMode::Tiles {
                            columns: n.parse()?,
                            overlap: 0.1,
                        }
                    }
                })
            }
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    let mut loaded = ModelConfig::load(&config)?;
    if let Some(m) = model {
        loaded = loaded.with_model(m);
    }
    if let Some(r) = resize {
        loaded.config.input.resize = r;
    }
    if let (
        Some(t),
        OutputSpec::Detector {
            score_threshold, ..
        },
    ) = (threshold, &mut loaded.config.output)
    {
        *score_threshold = t;
    }
    let runtime = Runtime::discover()?;
    println!("runtime: {}", runtime.library().display());
    println!(
        "model:   {} ({:?})",
        loaded.model_path.display(),
        loaded.config.input.resize
    );
    let mut detector = Detector::open(&runtime, loaded)?;
    let criteria = CarEvalCriteria::default();
    let (eval, frames) = evaluate_kitti(
        &mut detector,
        &kitti,
        &criteria,
        &GroundConfig::default(),
        &MonoDepthConfig::default(),
    )?;
    let mut times = StageTimes::default();
    for f in &frames {
        times.add(f.times);
        let cars = f
            .detections
            .iter()
            .filter(|d| d.type_name.as_deref() == Some("Car"))
            .count();
        println!(
            "{}/{:06}: {} detections ({} cars)",
            f.sequence,
            f.frame,
            f.detections.len(),
            cars
        );
    }
    for (frame, b, s) in &eval.false_positive_boxes {
        println!(
            "  false positive frame {frame}: [{:.0} {:.0} {:.0} {:.0}] score {s:.2}",
            b.left, b.top, b.right, b.bottom
        );
    }
    for (frame, b) in &eval.missed {
        println!(
            "  missed car     frame {frame}: [{:.0} {:.0} {:.0} {:.0}]",
            b.left, b.top, b.right, b.bottom
        );
    }
    println!(
        "cars (IoU >= {}, occlusion <= {}, height >= {} px): TP {} FN {} FP {} (ignored {})",
        criteria.min_iou,
        criteria.max_occlusion,
        criteria.min_height_px,
        eval.true_positives,
        eval.false_negatives,
        eval.false_positives,
        eval.ignored
    );
    println!("recall    {:.3}", eval.recall());
    println!("precision {:.3}", eval.precision());
    let mono = MonoDepthConfig::default();
    let ground = GroundConfig::default();
    let variants = depth_method_variants(&mono);
    println!(
        "monocular depth of matched cars (labelled Z <= {} m), default method {:?}:",
        criteria.depth_max_m, mono.method
    );
    for d in &eval.depth {
        if d.cut_by_image {
            println!(
                "  frame {:>2}: label Z {:>5.1} m  box cut by the image bottom: no ground contact, not checked",
                d.frame, d.label_z
            );
            continue;
        }
        let mut line = format!("  frame {:>2}: label Z {:>5.1} m |", d.frame, d.label_z);
        for (name, config) in &variants {
            match d.estimate_with(&ground, config) {
                Some(e) => {
                    line += &format!(
                        " {name} {:.1} m ({:+.1}%, {:?}) |",
                        e.z(),
                        100.0 * (e.z() - d.label_z) / d.label_z,
                        e.source
                    )
                }
                None => line += &format!(" {name} none |"),
            }
        }
        println!("{line}");
        println!(
            "      [diagnosis: labelled ground {:.2} m below camera; flat ground redone with it and the labelled nearest-face offset {:.2} m: {:.1} m]",
            d.label_ground_y,
            d.label_half_depth,
            d.with_labelled_ground(&ground).unwrap_or(f64::NAN)
        );
    }
    let checked = eval.depth_checked().count();
    println!(
        "max depth error {:.1}% over {checked} cars",
        100.0 * eval.max_depth_error()
    );
    let n = frames.len().max(1) as f64;
    println!(
        "time per frame: model {:.1} ms, other {:.1} ms",
        times.model.as_secs_f64() * 1e3 / n,
        times.other.as_secs_f64() * 1e3 / n
    );
    let detection_pass = eval.recall() >= 0.8 && eval.precision() >= 0.8;
    let depth_pass = checked > 0 && eval.max_depth_error() <= 0.10;
    println!(
        "detection (recall, precision >= 0.8): {}",
        if detection_pass { "PASS" } else { "FAIL" }
    );
    println!(
        "monocular depth, default method (<= 10% up to {} m): {}",
        criteria.depth_max_m,
        if depth_pass { "PASS" } else { "FAIL" }
    );
    Ok(detection_pass && depth_pass)
}
