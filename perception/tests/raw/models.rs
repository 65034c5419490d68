//! The raw-frames path through the real ONNX Runtime, on tiny models generated
//! by `perception/scripts/make_test_models.py`: every decoder and every error
//! path (missing model file, wrong input shape, NaN and empty outputs, a file
//! that is not a model). Skips with a printed notice only when the runtime
//! library is not installed (`pip install onnxruntime==1.31.1`).

use super::common;
use std::path::{Path, PathBuf};

use image::{Rgb, RgbImage};
use perception::ObjectClass;
use perception::raw::RawError;
use perception::raw::config::ModelConfig;
use perception::raw::dense::{DenseModel, DenseOutput};
use perception::raw::detect::Detector;
use perception::raw::runtime::{ModelRunner, Runtime};

fn models() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("models/test")
}

fn runtime() -> Option<Runtime> {
    match Runtime::discover() {
        Ok(rt) => Some(rt),
        Err(e) => {
            common::missing_input(&format!("ONNX Runtime not available: {e}"));
            None
        }
    }
}

fn solid(w: u32, h: u32, rgb: [u8; 3]) -> RgbImage {
    RgbImage::from_pixel(w, h, Rgb(rgb))
}

#[test]
fn gfl_detector_decodes_and_maps_classes() {
    let Some(rt) = runtime() else { return };
    let loaded = ModelConfig::load(&models().join("tiny_gfl.yaml")).unwrap();
    let mut det = Detector::open(&rt, loaded).unwrap();
    // White frame: brightness 1 -> stride-8 cell (1, 1), class 2, score 1;
    // every side 2 bins x 8 px around the centre (12, 12).
    let (found, times) = det.detect(&solid(32, 32, [255, 255, 255])).unwrap();
    assert_eq!(found.len(), 1, "{found:?}");
    let d = &found[0];
    assert_eq!(
        (d.class, d.type_name.as_deref(), d.label.as_str()),
        (ObjectClass::Vehicle, Some("Car"), "car")
    );
    assert!(
        (d.bbox.left - 0.0).abs() < 1e-3 && (d.bbox.right - 28.0).abs() < 1e-3,
        "{:?}",
        d.bbox
    );
    assert!((d.score - 1.0).abs() < 1e-6);
    assert!(times.model > std::time::Duration::ZERO);
    // 64x64 frame letterboxed at scale 0.5: the same box doubles.
    let (found, _) = det.detect(&solid(64, 64, [255, 255, 255])).unwrap();
    assert!(
        (found[0].bbox.right - 56.0).abs() < 1e-3,
        "{:?}",
        found[0].bbox
    );
    // Dark frame: score 0.2 < threshold 0.5.
    let (found, _) = det.detect(&solid(32, 32, [51, 51, 51])).unwrap();
    assert!(found.is_empty(), "{found:?}");
}

#[test]
fn missing_model_file_names_the_config() {
    let Some(rt) = runtime() else { return };
    let loaded = ModelConfig::load(&models().join("tiny_gfl.yaml"))
        .unwrap()
        .with_model(models().join("absent.onnx"));
    let err = Detector::open(&rt, loaded).unwrap_err();
    assert!(matches!(err, RawError::ModelNotFound { .. }), "{err}");
    let msg = err.to_string();
    assert!(
        msg.contains("absent.onnx") && msg.contains("tiny_gfl.yaml"),
        "{msg}"
    );
}

#[test]
fn wrong_input_shape_is_reported_before_running() {
    let Some(rt) = runtime() else { return };
    // The config promises 32x32; this model takes 64x64.
    let loaded = ModelConfig::load(&models().join("tiny_gfl.yaml"))
        .unwrap()
        .with_model(models().join("tiny_gfl_64.onnx"));
    let err = Detector::open(&rt, loaded).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, RawError::InputShape { .. }), "{msg}");
    assert!(
        msg.contains("1×3×64×64") && msg.contains("1×3×32×32") && !msg.contains('['),
        "{msg}"
    );
    // And a direct run with a wrong tensor.
    let mut runner = ModelRunner::open(&rt, &models().join("tiny_gfl.onnx"), 1).unwrap();
    let t = ndarray::ArrayD::<f32>::zeros(vec![1, 3, 16, 16]);
    assert!(matches!(
        runner.run(t.view()),
        Err(RawError::InputShape { .. })
    ));
}

#[test]
fn nan_outputs_are_an_error() {
    let Some(rt) = runtime() else { return };
    let loaded = ModelConfig::load(&models().join("tiny_gfl.yaml"))
        .unwrap()
        .with_model(models().join("tiny_gfl_nan.onnx"));
    let mut det = Detector::open(&rt, loaded).unwrap();
    let err = det.detect(&solid(32, 32, [255, 255, 255])).unwrap_err();
    let msg = err.to_string();
    assert!(matches!(err, RawError::OutputNotFinite { .. }), "{msg}");
    assert!(msg.contains("reg8") && msg.contains("NaN"), "{msg}");
}

#[test]
fn empty_outputs_are_an_error() {
    let Some(rt) = runtime() else { return };
    let mut runner = ModelRunner::open(&rt, &models().join("empty_output.onnx"), 1).unwrap();
    let t = ndarray::ArrayD::<f32>::zeros(vec![1, 3, 8, 8]);
    let err = runner.run(t.view()).unwrap_err();
    assert!(matches!(err, RawError::OutputEmpty { .. }), "{err}");
    assert!(err.to_string().contains("(shape 1×3×8×0)"), "{err}");
}

#[test]
fn a_file_that_is_not_a_model_is_an_ort_error() {
    let Some(rt) = runtime() else { return };
    let dir = std::env::temp_dir().join(format!("pframes-notmodel-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("garbage.onnx");
    std::fs::write(&path, b"this is not a protobuf").unwrap();
    let err = ModelRunner::open(&rt, &path, 1).unwrap_err();
    assert!(matches!(err, RawError::Ort { .. }), "{err}");
    assert!(err.to_string().contains("garbage.onnx"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn wrong_output_layout_for_the_decoder_is_reported() {
    let Some(rt) = runtime() else { return };
    // A segmentation model described as a GFL detector: no score outputs.
    let text = std::fs::read_to_string(models().join("tiny_gfl.yaml"))
        .unwrap()
        .replace("width: 32, height: 32", "width: 8, height: 8")
        .replace("strides: [8, 16]", "strides: [8]");
    let loaded = ModelConfig::parse(&text, &models().join("as_gfl.yaml"))
        .unwrap()
        .with_model(models().join("tiny_seg.onnx"));
    let mut det = Detector::open(&rt, loaded).unwrap();
    let err = det.detect(&solid(8, 8, [0, 0, 0])).unwrap_err();
    assert!(matches!(err, RawError::OutputShape { .. }), "{err}");
    assert!(err.to_string().contains("no score output"), "{err}");
}

#[test]
fn segmentation_depth_and_flow_models_decode_to_frame_size() {
    let Some(rt) = runtime() else { return };
    // 16x8 frame: left half red, right half green.
    let mut img = solid(16, 8, [0, 200, 0]);
    for y in 0..8 {
        for x in 0..8 {
            img.put_pixel(x, y, Rgb([200, 0, 0]));
        }
    }
    let mut seg = DenseModel::open(
        &rt,
        ModelConfig::load(&models().join("tiny_seg.yaml")).unwrap(),
    )
    .unwrap();
    let DenseOutput::Semantic(m) = seg.run(&img, None).unwrap() else {
        panic!("not semantic")
    };
    assert_eq!((m.width, m.height), (16, 8));
    assert_eq!(m.get(2, 3, 0), Some(1));
    assert_eq!(m.get(13, 3, 0), Some(2));

    let mut blue = solid(16, 8, [0, 0, 255]);
    blue.put_pixel(0, 0, Rgb([0, 0, 0]));
    let mut depth = DenseModel::open(
        &rt,
        ModelConfig::load(&models().join("tiny_depth.yaml")).unwrap(),
    )
    .unwrap();
    let DenseOutput::Depth(d) = depth.run(&blue, None).unwrap() else {
        panic!("not depth")
    };
    assert!(
        (d.get(8, 4, 0).unwrap() - 40.0).abs() < 1e-4,
        "blue 1.0 x scale 40"
    );

    // Flow: dx = 8 x (R_cur - R_prev) in 8-px model units; the frame is 16
    // px wide, so frame dx doubles.
    let prev = solid(16, 8, [0, 0, 0]);
    let cur = solid(16, 8, [255, 0, 0]);
    let mut flow = DenseModel::open(
        &rt,
        ModelConfig::load(&models().join("tiny_flow.yaml")).unwrap(),
    )
    .unwrap();
    let DenseOutput::Flow(f) = flow.run(&cur, Some(&prev)).unwrap() else {
        panic!("not flow")
    };
    assert!(
        (f.get(3, 3, 0).unwrap() - 16.0).abs() < 1e-4,
        "{:?}",
        f.get(3, 3, 0)
    );
    assert!((f.get(3, 3, 1).unwrap()).abs() < 1e-6);
    // A detector config is refused by the dense runner.
    let err = DenseModel::open(
        &rt,
        ModelConfig::load(&models().join("tiny_gfl.yaml")).unwrap(),
    )
    .unwrap_err();
    assert!(err.to_string().contains("output.kind"), "{err}");
}

#[test]
fn frames_directory_becomes_a_tracked_sequence_and_window_facts() {
    let Some(rt) = runtime() else { return };
    let dir = std::env::temp_dir().join(format!("pframes-frames-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for i in 0..6 {
        // Bright frames except frame 3 (the detector misses it): the tracker
        // must keep the id through the miss.
        let v = if i == 3 { 40 } else { 250 };
        solid(32, 32, [v, v, v])
            .save(dir.join(format!("{i:06}.png")))
            .unwrap();
    }
    let set = perception::raw::frames::ModelSet::load(&models().join("tiny_gfl.yaml")).unwrap();
    let mut seen = Vec::new();
    let seq =
        perception::raw::frames::FramesSource::run(&rt, &dir, set, &Default::default(), &mut |p| {
            seen.push(p.done)
        })
        .unwrap();
    assert_eq!(seen, vec![1, 2, 3, 4, 5, 6]);
    assert_eq!(seq.frame_count, 6);
    assert_eq!(seq.source, "frames");
    let frames: Vec<u32> = seq.observations.iter().map(|o| o.frame).collect();
    assert_eq!(frames, vec![0, 1, 2, 4, 5]);
    assert!(
        seq.observations
            .iter()
            .all(|o| o.track_id == 0 && o.color.as_deref() == Some("White"))
    );
    assert_eq!(seq.object_name(0), "car_0");
    let facts = perception::window_facts(
        &seq,
        perception::WindowSpec { size: 6, stride: 6 },
        &Default::default(),
    )
    .unwrap();
    assert_eq!(facts.len(), 1);
    assert!(
        facts[0].contains("Vehicles", &["car_0"]),
        "{}",
        facts[0].to_kb()
    );
    assert!(
        facts[0].contains("ColorOf", &["car_0", "White"]),
        "{}",
        facts[0].to_kb()
    );
    // Prefetching (the default) and running frame by frame agree exactly.
    let set = perception::raw::frames::ModelSet::load(&models().join("tiny_gfl.yaml")).unwrap();
    let serial = perception::raw::frames::FramesOptions {
        prefetch: false,
        ..Default::default()
    };
    let again =
        perception::raw::frames::FramesSource::run(&rt, &dir, set, &serial, &mut |_| {}).unwrap();
    assert_eq!(again, seq);
    // A frame that does not decode is an error naming it, in both modes,
    // and the prefetch thread stops cleanly.
    std::fs::write(dir.join("000004.png"), b"not a png").unwrap();
    for prefetch in [true, false] {
        let set = perception::raw::frames::ModelSet::load(&models().join("tiny_gfl.yaml")).unwrap();
        let options = perception::raw::frames::FramesOptions {
            prefetch,
            ..Default::default()
        };
        let mut done = 0;
        let err = perception::raw::frames::FramesSource::run(&rt, &dir, set, &options, &mut |p| {
            done = p.done
        })
        .unwrap_err();
        assert!(
            matches!(&err, RawError::Image { path, .. } if path.ends_with("000004.png")),
            "{err}"
        );
        assert_eq!(done, 4, "prefetch {prefetch}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_calibration_is_used_and_must_fit_the_frames() {
    let Some(rt) = runtime() else { return };
    let dir = std::env::temp_dir().join(format!("pframes-calib-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for i in 0..3 {
        solid(32, 32, [250, 250, 250])
            .save(dir.join(format!("{i:06}.png")))
            .unwrap();
    }
    let calib = perception::raw::camera::Calibration::new(
        40.0,
        41.0,
        15.5,
        14.0,
        1.2,
        std::path::Path::new("cam.yaml"),
    )
    .unwrap();
    let options = perception::raw::frames::FramesOptions {
        camera: Some(calib),
        fps: 25.0,
        ..Default::default()
    };
    let set = perception::raw::frames::ModelSet::load(&models().join("tiny_gfl.yaml")).unwrap();
    let seq =
        perception::raw::frames::FramesSource::run(&rt, &dir, set, &options, &mut |_| {}).unwrap();
    let k = seq.camera.intrinsics;
    assert_eq!((k.fx, k.fy, k.cx, k.cy), (40.0, 41.0, 15.5, 14.0));
    assert_eq!((k.image_width, k.image_height), (32, 32));
    assert_eq!(seq.camera.height_m, 1.2);
    assert_eq!(seq.fps, 25.0);
    // A calibration made for larger frames (principal point outside these)
    // would scale every depth: refused, naming the first frame.
    let big = perception::raw::camera::Calibration::new(
        721.5,
        721.5,
        609.6,
        172.9,
        1.65,
        std::path::Path::new("0001.txt"),
    )
    .unwrap();
    let options = perception::raw::frames::FramesOptions {
        camera: Some(big),
        ..Default::default()
    };
    let set = perception::raw::frames::ModelSet::load(&models().join("tiny_gfl.yaml")).unwrap();
    let err = perception::raw::frames::FramesSource::run(&rt, &dir, set, &options, &mut |_| {})
        .unwrap_err();
    assert!(
        matches!(&err, RawError::Frames { path, message }
            if path.ends_with("000000.png") && message.contains("another resolution")),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// A 64x64 white frame whose two detector boxes ([8, 40]² and [24, 56]²,
/// from `tiny_gfl_two`) have blue `b1` and `b2` in their lower halves, where
/// depth is sampled.
fn two_box_frame(b1: u8, b2: u8) -> RgbImage {
    let mut img = solid(64, 64, [255, 255, 255]);
    for (x0, x1, y0, y1, b) in [(8, 40, 24, 40, b1), (24, 56, 40, 56, b2)] {
        for y in y0..y1 {
            for x in x0..x1 {
                img.put_pixel(x, y, Rgb([255, 255, b]));
            }
        }
    }
    img
}

#[test]
fn a_relative_depth_model_is_fitted_per_frame_onto_the_monocular_estimates() {
    use perception::DepthSource;
    use perception::raw::frames::{FramesOptions, FramesSource, ModelSet};
    let Some(rt) = runtime() else { return };
    let dir = std::env::temp_dir().join(format!("pframes-reldepth-{}", std::process::id()));
    let frames = dir.join("frames");
    std::fs::create_dir_all(&frames).unwrap();
    // On this tiny frame the monocular estimate puts the upper box nearer
    // (the size prior's near/far-edge geometry), so the map agrees: the
    // larger inverse depth is there.
    let (b1, b2) = (192u8, 64u8);
    for i in 0..3 {
        two_box_frame(b1, b2)
            .save(frames.join(format!("{i:06}.png")))
            .unwrap();
    }
    let options = FramesOptions::default();
    let run = |set: ModelSet| FramesSource::run(&rt, &frames, set, &options, &mut |_| {}).unwrap();
    // Monocular alone: the estimates the relative map is aligned to.
    let mono = run(ModelSet::load(&models().join("tiny_gfl_two.yaml")).unwrap());
    assert_eq!(mono.observations.len(), 6, "{:?}", mono.observations);
    // By box: 0 the upper (b1), 1 the lower (b2).
    let mut mono_z = [f64::NAN; 2];
    for o in &mono.observations[..2] {
        mono_z[usize::from(o.bbox.is_some_and(|b| b.bottom > 48.0))] =
            o.position.map_or(f64::NAN, |p| p[2]);
    }
    assert!(
        mono.observations[..2]
            .iter()
            .all(|o| o.depth_source == Some(DepthSource::Fused)),
        "{:?}",
        mono.observations
    );
    // The map sees each car's near face: the monocular centre less the
    // car's centre offset is what it is fitted to.
    let offset = perception::raw::mono::centre_offset_m(&options.mono, Some("Car"));
    assert!(offset > 1.0, "{offset}");
    let near: Vec<f64> = mono_z.iter().map(|z| z - offset).collect();
    // The model's value in each box is blue / 255: inverse depth by default
    // (the shipped config says so explicitly), depth with `relative: depth`.
    let inverse_yaml = models().join("tiny_rel_depth.yaml");
    let depth_text = std::fs::read_to_string(&inverse_yaml)
        .unwrap()
        .replace(
            "model: tiny_rel_depth.onnx",
            &format!("model: {}", models().join("tiny_rel_depth.onnx").display()),
        )
        .replace("relative: inverse_depth", "relative: depth");
    let depth_yaml = dir.join("rel_as_depth.yaml");
    std::fs::write(&depth_yaml, depth_text).unwrap();
    let value = |b: u8| f64::from(b) / 255.0;
    let v = [value(b1), value(b2)];
    // Two anchors are too few for a line (MIN_LINE_ANCHORS), so both
    // readings fit one scale, the median (here the mean) of the anchors'
    // ratios: inverse depth `1/Z_near = a·v`, depth `Z_near = s·v`. The map
    // decides the cars' depth ratio, not their monocular estimates.
    let a = 0.5 * (near[0].recip() / v[0] + near[1].recip() / v[1]);
    let scale = 0.5 * (near[0] / v[0] + near[1] / v[1]);
    let cases = [
        (
            inverse_yaml,
            [(a * v[0]).recip() + offset, (a * v[1]).recip() + offset],
        ),
        (depth_yaml, [scale * v[0] + offset, scale * v[1] + offset]),
    ];
    for (yaml, want_z) in cases {
        let set_file = dir.join("set.yaml");
        std::fs::write(
            &set_file,
            format!(
                "detector: {}\ndepth: {}\n",
                models().join("tiny_gfl_two.yaml").display(),
                yaml.display()
            ),
        )
        .unwrap();
        let seq = run(ModelSet::load(&set_file).unwrap());
        assert_eq!(seq.observations.len(), 6);
        for o in &seq.observations {
            assert_eq!(o.depth_source, Some(DepthSource::RelativeAligned), "{o:?}");
            let k = usize::from(o.bbox.is_some_and(|b| b.bottom > 48.0));
            let z = o.position.map_or(f64::NAN, |p| p[2]);
            assert!(
                (z / want_z[k] - 1.0).abs() < 1e-3,
                "{yaml:?}: box {k}: {z} vs {}",
                want_z[k]
            );
        }
        let json = perception::json::to_tracks_json(&seq).unwrap();
        assert!(json.contains("\"depth_source\": \"relative_aligned\""));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
