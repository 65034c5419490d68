//! The serde documents: scenarios, fact configs, model configs, camera
//! calibrations and tracks, generated or edited from real ones.

use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::select;
use proptest::test_runner::TestRunner;
use std::sync::OnceLock;

use super::doc::{Doc, doc_of_yaml, edited};
use super::{kitti_calib, sample, wild_count, wild_num};

fn builtin_scenarios() -> &'static [Doc] {
    static D: OnceLock<Vec<Doc>> = OnceLock::new();
    D.get_or_init(|| {
        perception::sim::BUILTIN_NAMES
            .iter()
            .filter_map(|n| perception::sim::builtin_text(n))
            .filter_map(doc_of_yaml)
            .collect()
    })
}

fn motion() -> impl Strategy<Value = Doc> {
    let phase = (
        wild_count(),
        wild_count(),
        0u8..4,
        wild_num(),
        proptest::option::of(0u32..8),
    )
        .prop_map(|(from, to, kind, v, other)| {
            let mut e = vec![
                ("from".to_string(), Doc::Raw(from)),
                ("to".to_string(), Doc::Raw(to)),
            ];
            match kind {
                0 => e.push(("accel".into(), Doc::Raw(v))),
                1 => e.push(("speed_to".into(), Doc::Raw(v))),
                2 => e.push(("turn_deg".into(), Doc::Raw(v))),
                _ => {}
            }
            if let Some(o) = other {
                e.push((
                    if kind % 2 == 0 { "enter" } else { "merge_into" }.into(),
                    Doc::Raw(o.to_string()),
                ));
            }
            Doc::Map(e)
        });
    (
        wild_num(),
        wild_num(),
        wild_num(),
        wild_num(),
        vec(phase, 0..3),
    )
        .prop_map(|(x, z, h, s, phases)| {
            Doc::Map(vec![
                ("start".into(), Doc::Seq(vec![Doc::Raw(x), Doc::Raw(z)])),
                ("heading_deg".into(), Doc::Raw(h)),
                ("speed".into(), Doc::Raw(s)),
                ("phases".into(), Doc::Seq(phases)),
            ])
        })
}

fn scenario_doc() -> impl Strategy<Value = Doc> {
    let agent = (
        0u32..8,
        select(
            &[
                "Vehicles",
                "Pedestrian",
                "Person",
                "Cyclist",
                "Misc",
                "Pole",
                "Car",
            ][..],
        ),
        proptest::option::of(select(
            &["Car", "Van", "Truck", "Bus", "SUV", "Bicycle", "Zeppelin"][..],
        )),
        proptest::option::of(select(&["White", "Red", "Black", "Plaid"][..])),
        proptest::option::of(vec(wild_num(), 3)),
        any::<bool>(),
        motion(),
    )
        .prop_map(|(id, class, ty, color, size, parked, m)| {
            let mut e = vec![
                ("id".to_string(), Doc::Raw(id.to_string())),
                ("class".to_string(), Doc::Str(class.to_string())),
            ];
            if let Some(t) = ty {
                e.push(("type".into(), Doc::Str(t.into())));
            }
            if let Some(c) = color {
                e.push(("color".into(), Doc::Str(c.into())));
            }
            if let Some(s) = size {
                e.push((
                    "size".into(),
                    Doc::Seq(s.into_iter().map(Doc::Raw).collect()),
                ));
            }
            if parked {
                e.push(("parked".into(), Doc::Raw("true".into())));
            }
            if let Doc::Map(m) = m {
                e.extend(m);
            }
            Doc::Map(e)
        });
    let road =
        (wild_num(), wild_num(), wild_num(), wild_num(), wild_num()).prop_map(|(x, z, l, w, s)| {
            Doc::Map(vec![
                ("center".into(), Doc::Seq(vec![Doc::Raw(x), Doc::Raw(z)])),
                ("length".into(), Doc::Raw(l)),
                ("width".into(), Doc::Raw(w)),
                ("sidewalk_width".into(), Doc::Raw(s)),
            ])
        });
    let prop = (
        select(&["Pole", "TrafficSign", "Building", "Vegetation", "Vehicles"][..]),
        wild_num(),
        wild_num(),
    )
        .prop_map(|(c, x, z)| {
            Doc::Map(vec![
                ("class".into(), Doc::Str(c.into())),
                ("at".into(), Doc::Seq(vec![Doc::Raw(x), Doc::Raw(z)])),
            ])
        });
    let camera =
        (vec(wild_num(), 4), wild_count(), wild_count(), wild_num()).prop_map(|(k, w, h, hm)| {
            let mut it = k.into_iter().map(Doc::Raw);
            let mut intr = Vec::new();
            for key in ["fx", "fy", "cx", "cy"] {
                intr.push((key.to_string(), it.next().unwrap_or(Doc::Raw("1".into()))));
            }
            intr.push(("image_width".into(), Doc::Raw(w)));
            intr.push(("image_height".into(), Doc::Raw(h)));
            Doc::Map(vec![
                ("intrinsics".into(), Doc::Map(intr)),
                ("height_m".into(), Doc::Raw(hm)),
            ])
        });
    let noise = vec(wild_num(), 5).prop_map(|v| {
        let keys = [
            "position_sigma_m",
            "depth_sigma_fraction",
            "box_jitter_px",
            "miss_probability",
            "id_switch_probability",
        ];
        Doc::Map(
            keys.iter()
                .zip(v)
                .map(|(k, v)| (k.to_string(), Doc::Raw(v)))
                .collect(),
        )
    });
    (
        select(
            &[
                "fuzz",
                "a",
                "",
                "../../x",
                "x y",
                "ünï",
                "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa",
            ][..],
        ),
        wild_count(),
        proptest::option::of(wild_num()),
        proptest::option::of(camera),
        motion(),
        vec(road, 0..2),
        vec(prop, 0..3),
        vec(agent, 0..5),
        proptest::option::of(noise),
    )
        .prop_map(
            |(name, frames, fps, camera, ego, roads, props, agents, noise)| {
                let mut e = vec![
                    ("name".to_string(), Doc::Str(name.to_string())),
                    ("frames".to_string(), Doc::Raw(frames)),
                ];
                if let Some(f) = fps {
                    e.push(("fps".into(), Doc::Raw(f)));
                }
                if let Some(c) = camera {
                    e.push(("camera".into(), c));
                }
                e.push(("ego".into(), ego));
                e.push((
                    "world".into(),
                    Doc::Map(vec![
                        ("roads".into(), Doc::Seq(roads)),
                        ("props".into(), Doc::Seq(props)),
                    ]),
                ));
                e.push(("agents".into(), Doc::Seq(agents)));
                if let Some(n) = noise {
                    e.push(("noise".into(), n));
                }
                Doc::Map(e)
            },
        )
}

fn scenario(runner: &mut TestRunner) -> Doc {
    let bases = builtin_scenarios().to_vec();
    sample(prop_oneof![scenario_doc(), edited(bases)], runner)
}

/// Scenarios as YAML: generated from the format, or edits of the built-ins.
pub fn scenario_yaml(runner: &mut TestRunner) -> Vec<u8> {
    scenario(runner).to_yaml().into_bytes()
}

/// Scenarios as JSON.
pub fn scenario_json(runner: &mut TestRunner) -> Vec<u8> {
    scenario(runner).to_json().into_bytes()
}

pub(super) fn default_config() -> Doc {
    static D: OnceLock<Doc> = OnceLock::new();
    D.get_or_init(|| {
        serde_json::to_value(perception::FactConfig::default())
            .map(|v| Doc::from_json(&v))
            .unwrap_or(Doc::Map(Vec::new()))
    })
    .clone()
}

/// Fact configs: edits of the default, keys dropped, added or made wild.
pub fn config_yaml(runner: &mut TestRunner) -> Vec<u8> {
    sample(edited(vec![default_config(), Doc::Map(Vec::new())]), runner)
        .to_yaml()
        .into_bytes()
}

/// Fact configs as JSON.
pub fn config_json(runner: &mut TestRunner) -> Vec<u8> {
    sample(edited(vec![default_config(), Doc::Map(Vec::new())]), runner)
        .to_json()
        .into_bytes()
}

fn model_bases() -> Vec<Doc> {
    [
        crate::targets::MODEL_DETECTOR,
        crate::targets::MODEL_DEPTH,
        crate::targets::MODEL_FLOW,
        "detector: det.yaml\ndepth: depth.yaml\nflow: flow.yaml\n",
        "name: seg\nmodel: seg.onnx\ninput: { width: 8, height: 8, layout: nchw, colour: rgb, mean: [0, 0, 0], std: [255, 255, 255], resize: { mode: tiles, columns: 3, overlap: 0.1 } }\noutput: { kind: segmentation, num_classes: 3 }\nlabels:\n  - { id: 1, name: red, class: Vehicles, type: Car }\n",
    ]
    .iter()
    .filter_map(|t| doc_of_yaml(t))
    .collect()
}

/// Model configs and model sets: edits of working ones.
pub fn model_config(runner: &mut TestRunner) -> Vec<u8> {
    let d = sample(edited(model_bases()), runner);
    let mut text = d.to_yaml();
    // A set is recognised by a line starting `detector:`; keep it first.
    if text.contains("\ndetector:") && !text.starts_with("detector:") {
        text = format!("detector: det.yaml\n{text}");
    }
    text.into_bytes()
}

/// Camera calibrations: YAML intrinsics (edited) or a KITTI P2 file.
pub fn camera(runner: &mut TestRunner) -> Vec<u8> {
    let base = Doc::Map(
        [
            ("fx", "721.5"),
            ("fy", "721.5"),
            ("cx", "609.6"),
            ("cy", "172.9"),
            ("height_m", "1.65"),
            ("image_width", "1242"),
            ("image_height", "375"),
        ]
        .iter()
        .map(|(k, v)| (k.to_string(), Doc::Raw(v.to_string())))
        .collect(),
    );
    if sample(0u8..3, runner) == 0 {
        kitti_calib(runner)
    } else {
        sample(edited(vec![base]), runner).to_yaml().into_bytes()
    }
}

fn track_bases() -> &'static [Doc] {
    static D: OnceLock<Vec<Doc>> = OnceLock::new();
    D.get_or_init(|| {
        crate::corpus::tracks_seed_text()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .map(|v| vec![Doc::from_json(&v)])
            .unwrap_or_default()
    })
}

/// JSON tracks: edits of a simulated sequence's tracks.
pub fn tracks_json(runner: &mut TestRunner) -> Vec<u8> {
    sample(edited(track_bases().to_vec()), runner)
        .to_json()
        .into_bytes()
}
