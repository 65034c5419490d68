//! The six real KITTI frames through the shipped NanoDet config: car recall
//! and precision (IoU ≥ 0.5, unoccluded, height ≥ 25 px) must both reach 0.8,
//! and the monocular depth of the matched cars (default method: fused flat
//! ground + size prior with the nearest-face → centre correction) is checked
//! against the labels. Skips with a printed notice only when `../shared` or the ONNX
//! Runtime library is absent.

use super::common;
use std::path::Path;

use perception::raw::config::ModelConfig;
use perception::raw::detect::Detector;
use perception::raw::eval::{CarEvalCriteria, evaluate_kitti};
use perception::raw::ground::GroundConfig;
use perception::raw::mono::{MonoDepthConfig, MonoDepthMethod};
use perception::raw::runtime::Runtime;

#[test]
fn nanodet_finds_the_labelled_kitti_cars() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let kitti = crate_dir.join("../../shared/data/kitti-tracking");
    let config = crate_dir.join("models/nanodet-m-416-coco.yaml");
    if !kitti.join("image_02").is_dir() {
        common::missing_input(&format!("{} not present", kitti.display()));
        return;
    }
    let loaded = ModelConfig::load(&config).unwrap();
    if !loaded.model_path.is_file() {
        common::missing_input(&format!("{} not present", loaded.model_path.display()));
        return;
    }
    let rt = match Runtime::discover() {
        Ok(rt) => rt,
        Err(e) => {
            common::missing_input(&format!("{e}"));
            return;
        }
    };
    let mut det = Detector::open(&rt, loaded).unwrap();
    let (eval, frames) = evaluate_kitti(
        &mut det,
        &kitti,
        &CarEvalCriteria::default(),
        &GroundConfig::default(),
        &MonoDepthConfig::default(),
    )
    .unwrap();
    assert_eq!(frames.len(), 6);
    eprintln!(
        "TP {} FN {} FP {} recall {:.3} precision {:.3}",
        eval.true_positives,
        eval.false_negatives,
        eval.false_positives,
        eval.recall(),
        eval.precision()
    );
    assert!(eval.true_positives >= 6, "{eval:?}");
    assert!(
        eval.recall() >= 0.8,
        "recall {:.3}: {eval:?}",
        eval.recall()
    );
    assert!(
        eval.precision() >= 0.8,
        "precision {:.3}: {eval:?}",
        eval.precision()
    );
    // Pedestrians of sequence 0016 are found and mapped too.
    assert!(frames.iter().any(|f| {
        f.detections
            .iter()
            .any(|d| d.class == perception::ObjectClass::Pedestrian)
    }));

    // Depth: the matched cars within 30 m whose ground contact is visible
    // (two, both in 0001/10; docs/models.md has the table). The default
    // method was chosen on the broad label-box evaluation
    // (`raw/depth_labels.rs`), not on these cars. It brings the 12.7 m car,
    // whose ground lies 2.06 m below the camera, from 30.7% (plain flat
    // ground) to under 5%. The 8.1 m car stays at about 15%: it is smaller
    // than the KITTI mean car (h 1.41 m, l 3.16 m against 1.52 m, 3.88 m)
    // and its ground is 0.16 m above the flat-ground plane, so every prior
    // overestimates it; the 10% target is not met on it (stated in the docs).
    let ground = GroundConfig::default();
    let flat = MonoDepthConfig {
        centre_correction: false,
        ..MonoDepthConfig::default().with_method(MonoDepthMethod::FlatGround)
    };
    let checked: Vec<_> = eval.depth_checked().collect();
    assert!(checked.len() >= 2, "{:?}", eval.depth);
    let mut default_max: f64 = 0.0;
    let mut flat_max: f64 = 0.0;
    for d in &checked {
        let err = d.relative_error().unwrap_or(f64::INFINITY);
        let flat_z = d.estimate_with(&ground, &flat).map_or(f64::NAN, |e| e.z());
        eprintln!(
            "box {:?} label Z {:.2} default {:.2} ({:?}, error {:.1}%) plain flat ground {:.2}",
            d.bbox,
            d.label_z,
            d.estimated_z.unwrap_or(f64::NAN),
            d.source,
            100.0 * err,
            flat_z
        );
        assert_eq!(d.source, Some(perception::DepthSource::Fused), "{d:?}");
        default_max = default_max.max(err);
        flat_max = flat_max.max((flat_z - d.label_z).abs() / d.label_z);
        // The geometry is right: plain flat ground redone with the labelled
        // ground height and nearest-face offset lands within 5%.
        let z = d.with_labelled_ground(&ground).unwrap();
        assert!((z - d.label_z).abs() / d.label_z <= 0.05, "{d:?} -> {z}");
    }
    assert!(
        checked
            .iter()
            .any(|d| d.relative_error().is_some_and(|e| e <= 0.05)),
        "{checked:?}"
    );
    assert!(
        default_max <= 0.16,
        "default method's largest error {:.1}%: {checked:?}",
        100.0 * default_max
    );
    assert!(
        default_max < 0.6 * flat_max,
        "default {default_max} vs flat ground {flat_max}"
    );
}
