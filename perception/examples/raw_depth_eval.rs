//! Monocular depth methods on KITTI's labelled 2D boxes taken as perfect
//! detections: every `label_02/<seq>.txt` of the tracking root, cars with
//! occlusion 0, truncation ≤ 0.15, box height ≥ 25 px and labelled Z ≤ 30 m
//! (boxes cut by the image's bottom edge left out, as for detections).
//! Prints the median relative depth error and the fraction within 10% per
//! method. Needs no model and no runtime.
//!
//! ```text
//! cargo run --release -p perception --example raw_depth_eval -- [--kitti DIR]
//! ```

use std::path::PathBuf;

use perception::raw::eval::{LabelBoxCriteria, depth_method_variants, label_box_depth_eval};
use perception::raw::ground::GroundConfig;
use perception::raw::mono::MonoDepthConfig;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut kitti =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/kitti-tracking");
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--kitti" => kitti = PathBuf::from(args.next().ok_or("--kitti needs a value")?),
            other => return Err(format!("unknown argument {other}").into()),
        }
    }
    let criteria = LabelBoxCriteria::default();
    let base = MonoDepthConfig::default();
    let eval = label_box_depth_eval(
        &kitti,
        &criteria,
        &GroundConfig::default(),
        &depth_method_variants(&base),
    )?;
    println!(
        "{} sequences, {} {} boxes (occlusion <= {}, truncation <= {}, height >= {} px, Z <= {} m); {} more cut by the image bottom, left out",
        eval.sequences,
        eval.boxes,
        criteria.type_name,
        criteria.max_occlusion,
        criteria.max_truncation,
        criteria.min_height_px,
        criteria.max_z_m,
        eval.cut_by_image
    );
    println!("default method: {:?}", base.method);
    println!(
        "| method | estimated | median error | within {:.0}% | provenance |",
        100.0 * criteria.tolerance
    );
    println!("|---|---|---|---|---|");
    for s in &eval.scores {
        let sources: Vec<String> = s
            .sources
            .iter()
            .map(|(k, n)| format!("{k:?} {n}"))
            .collect();
        println!(
            "| {} | {} / {} | {:.1}% | {:.1}% | {} |",
            s.name,
            s.estimated,
            s.boxes,
            100.0 * s.median_error,
            100.0 * s.within,
            sources.join(", ")
        );
    }
    Ok(())
}
