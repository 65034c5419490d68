//! The seed corpus of a target: the small, valid files committed under
//! `fuzz/corpus/<target>/`, the project's own built-in inputs (the default
//! LogicPad, the built-in scenarios, the default config), and the hostile
//! inputs of issue 13, generated here rather than committed as megabytes.
//!
//! Seeds are replayed verbatim first in every run, then serve as the bases
//! of mutations.

use std::path::{Path, PathBuf};

use crate::FuzzError;
use crate::targets::Target;

/// One seed input.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Seed {
    /// The file name, or `gen:<what>` for a generated seed.
    pub name: String,
    /// The bytes.
    pub bytes: Vec<u8>,
}

impl Seed {
    fn generated(name: &str, bytes: impl Into<Vec<u8>>) -> Seed {
        Seed {
            name: format!("gen:{name}"),
            bytes: bytes.into(),
        }
    }
}

/// `fuzz/corpus` of this crate's source tree.
pub fn default_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus")
}

/// The seeds of `target`: committed files (sorted by name), then generated
/// ones. A target without committed seeds is an error: its mutations
/// would start from nothing.
pub fn load(dir: &Path, target: &Target) -> Result<Vec<Seed>, FuzzError> {
    let tdir = dir.join(target.name);
    let io = |source| FuzzError::Io {
        path: tdir.clone(),
        source,
    };
    let mut files: Vec<PathBuf> = std::fs::read_dir(&tdir)
        .map_err(io)?
        .map(|e| e.map(|e| e.path()))
        .collect::<Result<_, _>>()
        .map_err(io)?;
    files.retain(|p| p.is_file());
    files.sort();
    let mut seeds = Vec::with_capacity(files.len() + 16);
    for p in files {
        let bytes = std::fs::read(&p).map_err(|source| FuzzError::Io {
            path: p.clone(),
            source,
        })?;
        let name = p
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        seeds.push(Seed { name, bytes });
    }
    if seeds.is_empty() {
        return Err(FuzzError::EmptyCorpus {
            target: target.name.to_string(),
            dir: tdir,
        });
    }
    let first = seeds[0].bytes.clone();
    seeds.extend(generated(target.name));
    seeds.extend(hostile_everywhere(&first));
    Ok(seeds)
}

/// Inputs every parser must survive: empty, byte order marks, invalid
/// UTF-8, NUL bytes, CR line ends, nesting 100,000 deep, a million-digit
/// number, NaN, and YAML's "billion laughs" (aliases that expand
/// exponentially).
fn hostile_everywhere(first: &[u8]) -> Vec<Seed> {
    let mut bom = "\u{feff}".as_bytes().to_vec();
    bom.extend_from_slice(first);
    let mut double_bom = "\u{feff}\u{feff}".as_bytes().to_vec();
    double_bom.extend_from_slice(first);
    let mut invalid = b"\xff\xfe\xc3\x28".to_vec();
    invalid.extend_from_slice(first);
    let mut invalid_mid = first.to_vec();
    invalid_mid.splice(first.len() / 2..first.len() / 2, *b"\xe2\x82\xed\xa0\x80");
    let mut nul = first.to_vec();
    nul.splice(first.len() / 3..first.len() / 3, *b"\0\0");
    let crlf: Vec<u8> = String::from_utf8_lossy(first)
        .replace('\n', "\r\n")
        .into_bytes();
    let cr: Vec<u8> = String::from_utf8_lossy(first)
        .replace('\n', "\r")
        .into_bytes();
    vec![
        Seed::generated("empty", Vec::new()),
        Seed::generated("bom", bom),
        Seed::generated("double-bom", double_bom),
        Seed::generated("invalid-utf8-start", invalid),
        Seed::generated("invalid-utf8-middle", invalid_mid),
        Seed::generated("nul-bytes", nul),
        Seed::generated("crlf", crlf),
        Seed::generated("cr-only", cr),
        Seed::generated(
            "parens-100000",
            format!("{}{}", "(".repeat(100_000), ")".repeat(100_000)),
        ),
        Seed::generated("brackets-100000-open", "[".repeat(100_000)),
        Seed::generated(
            "braces-100000",
            format!("{}{}", "{\"a\":".repeat(100_000), "}".repeat(100_000)),
        ),
        Seed::generated("yaml-lists-100000", "- ".repeat(100_000)),
        Seed::generated("million-digits", "9".repeat(1_000_000)),
        Seed::generated("nan", "NaN"),
        Seed::generated("billion-laughs", billion_laughs()),
        Seed::generated("one-long-line", "a".repeat(2_000_000)),
        Seed::generated("many-empty-lines", "\n".repeat(1_000_000)),
    ]
}

/// Nine levels of ten aliases each: 10⁹ nodes if expanded.
fn billion_laughs() -> String {
    let mut s = String::from("a0: &a0 [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]\n");
    for i in 1..9 {
        let refs = vec![format!("*a{}", i - 1); 10].join(", ");
        s += &format!("a{i}: &a{i} [{refs}]\n");
    }
    s
}

/// `Vehicles(v0) ∧ … ∧ Vehicles(v11)`: 12 independent variables, so the
/// answers are the vehicles to the 12th power.
fn twelve_atoms() -> String {
    (0..12)
        .map(|i| format!("Vehicles(v{i})"))
        .collect::<Vec<_>>()
        .join(" ^ ")
}

/// `Moving(x) ∧ x ≠ c0 ∧ … ∧ x ≠ c20000`.
fn many_disequalities() -> String {
    let mut s = String::from("Moving(x)");
    for i in 0..=20_000 {
        s += &format!(" ^ x != c{i}");
    }
    s
}

/// A rule whose body is 10,000 `==>`-chained atoms.
fn chained_implications() -> String {
    let mut s = String::from("∀x : Vehicles(x)");
    for i in 0..10_000 {
        s += &format!(" ==> A{i}(x)");
    }
    s
}

fn logicpad_with_rule(logic: &str) -> String {
    format!(
        "atomic_predicates:\n  t: [Vehicles(x), Moving(x)]\nderived_predicates:\n  - name: R\n    logic: \"{logic}\"\n"
    )
}

/// A simulated sequence's first frames as JSON tracks (the seed of the
/// tracks generator and corpus); `None` if the simulator fails, which the
/// corpus test reports.
pub fn tracks_seed_text() -> Option<String> {
    let s = perception::sim::Scenario::builtin("braking").ok()?;
    let mut seq = perception::sim::simulate(&s, 1).ok()?.sequence;
    seq.frame_count = 3;
    seq.observations.retain(|o| o.frame < 3);
    perception::json::to_tracks_json(&seq).ok()
}

fn scenario_with(frames: &str, name: &str) -> String {
    let base = perception::sim::builtin_text("braking").unwrap_or("");
    base.replace("name: braking", &format!("name: {name}"))
        .replace("frames: 60", &format!("frames: {frames}"))
}

fn many_agents_yaml(n: usize) -> String {
    let mut s = String::from("name: crowd\nframes: 2\nego: {speed: 1}\nagents:\n");
    for i in 0..n {
        s += &format!(
            "  - {{id: {i}, class: Pedestrian, start: [{}, {}], speed: 1}}\n",
            i % 40,
            5 + i / 40
        );
    }
    s
}

/// `n` labelled objects in frame 0.
fn crowded_kitti_frame(n: usize) -> String {
    (0..n)
        .map(|i| {
            format!(
                "0 {i} Car 0 0 0 {}.0 150.0 {}.0 200.0 1.5 1.6 4.0 {}.0 1.7 {}.0 0\n",
                i % 1000,
                i % 1000 + 20,
                (i % 40) as i64 - 20,
                5 + i / 40
            )
        })
        .collect()
}

fn generated(target: &str) -> Vec<Seed> {
    let q12 = twelve_atoms();
    let neq = many_disequalities();
    let chain = chained_implications();
    let deep_query = format!("{}Moving(x){}", "(".repeat(100_000), ")".repeat(100_000));
    let deep_not = format!("{}Moving(x)", "¬".repeat(100_000));
    let deep_exists = format!("{}Moving(x)", "∃y: ".repeat(20_000));
    // Sixty diagnostics, all deep in one 2 MB line: each rendered excerpt,
    // line and column searched the whole line (a 4 MB one took 30 s).
    let deep_diagnostics = format!(
        "{}hicles(x0) {}",
        "9".repeat(2_000_000),
        (1..60)
            .map(|i| format!("∨ Vehicles(x{i})"))
            .collect::<Vec<_>>()
            .join(" ")
    );
    let long_or = (0..5_000)
        .map(|i| format!("Vehicles(x{i})"))
        .collect::<Vec<_>>()
        .join(" ∨ ");
    match target {
        "fol" => vec![
            Seed::generated("chained-implications-10000", chain),
            Seed::generated("deep-parentheses", deep_query),
            Seed::generated("deep-negation", deep_not),
            Seed::generated("deep-exists", deep_exists),
            Seed::generated("long-disjunction", long_or),
            Seed::generated("twelve-atoms", q12),
        ],
        "query" | "llm_reply" => vec![
            Seed::generated("twelve-atoms", q12.clone()),
            Seed::generated("disequalities-20000", neq),
            Seed::generated("deep-parentheses", deep_query),
            Seed::generated("deep-negation", deep_not),
            Seed::generated("deep-exists", deep_exists),
            Seed::generated("long-disjunction", long_or),
            Seed::generated("universal-twelve", format!("∀x: Vehicles(x) → {q12}")),
            Seed::generated("diagnostics-deep-in-a-long-line", deep_diagnostics),
        ],
        "translate" => vec![
            Seed::generated("twelve-atoms", q12),
            Seed::generated("disequalities-20000", neq),
            Seed::generated(
                "long-question",
                format!("Is there a {}car?", "white ".repeat(20_000)),
            ),
            Seed::generated(
                "many-ands",
                format!("Is there a car{}?", " and a car".repeat(5_000)),
            ),
        ],
        "queries_tsv" => vec![
            Seed::generated("twelve-atoms", format!("w0\t{q12}\n")),
            Seed::generated("disequalities-20000", format!("w1\t{neq}\n")),
            Seed::generated("lines-20000", "w0\tVehicles(x)\n".repeat(20_000)),
            Seed::generated("unknown-window", "nowhere\tVehicles(x)\n"),
        ],
        "translate_csv" => vec![
            Seed::generated(
                "rows-5000",
                format!("Question\n{}", "Is there a white car?\n".repeat(5_000)),
            ),
            Seed::generated(
                "unterminated-quote",
                "Question\n\"Is there a car?\n".repeat(1_000),
            ),
        ],
        "logicpad" => vec![
            Seed::generated("builtin", logicpad::BUILTIN_SOURCE),
            Seed::generated("chained-implications-10000", logicpad_with_rule(&chain)),
            Seed::generated(
                "deep-parentheses",
                logicpad_with_rule(&format!(
                    "{}Moving(x){} ==> R(x)",
                    "(".repeat(50_000),
                    ")".repeat(50_000)
                )),
            ),
            Seed::generated("rule-chain-3000", {
                let mut s = String::from(
                    "atomic_predicates:\n  t: [Vehicles(x)]\nderived_predicates:\n  - name: R0\n    logic: \"∀x : Vehicles(x) ==> R0(x)\"\n",
                );
                for i in 1..3000 {
                    s += &format!(
                        "  - name: R{i}\n    logic: \"∀x : R{}(x) ∧ ¬Q{i}(x) ==> R{i}(x)\"\n",
                        i - 1
                    );
                }
                s
            }),
            Seed::generated(
                "negation-cycle",
                "atomic_predicates:\n  t: [Vehicles(x)]\nderived_predicates:\n  - name: A\n    logic: \"∀x : Vehicles(x) ∧ ¬B(x) ==> A(x)\"\n  - name: B\n    logic: \"∀x : Vehicles(x) ∧ ¬A(x) ==> B(x)\"\n",
            ),
            Seed::generated(
                "wide-arity",
                format!(
                    "atomic_predicates:\n  t:\n    - W({})\n",
                    (0..2000)
                        .map(|i| format!("a{i}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ),
        ],
        "facts" => vec![
            Seed::generated(
                "facts-100000",
                (0..100_000)
                    .map(|i| format!("Vehicles(car_{i})\n"))
                    .collect::<String>(),
            ),
            Seed::generated(
                "args-10000",
                format!(
                    "P({})\n",
                    (0..10_000)
                        .map(|i| format!("c{i}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            ),
            Seed::generated("arity-clash", "Vehicles(car_1)\nVehicles(car_1, car_2)\n"),
        ],
        "kitti_labels" => vec![
            Seed::generated("objects-2000-one-frame", crowded_kitti_frame(2000)),
            Seed::generated("objects-256-one-frame", crowded_kitti_frame(256)),
            Seed::generated(
                "frame-u32-max",
                "4294967295 0 Car 0 0 0 10 10 20 20 1.5 1.6 4 0 1.7 10 0\n",
            ),
            Seed::generated(
                "frame-u32-overflow",
                "4294967296 0 Car 0 0 0 10 10 20 20 1.5 1.6 4 0 1.7 10 0\n",
            ),
            Seed::generated(
                "track-overflow",
                "0 4294967296 Car 0 0 0 10 10 20 20 1.5 1.6 4 0 1.7 10 0\n",
            ),
            Seed::generated(
                "frame-99999",
                "0 0 Car 0 0 0 10 10 20 20 1.5 1.6 4 0 1.7 10 0\n99999 0 Car 0 0 0 10 10 20 20 1.5 1.6 4 0 1.7 10 0\n",
            ),
            Seed::generated(
                "nan-and-huge",
                "0 0 Car 0 0 NaN 10 10 1e300 20 1e308 1.6 4 0 1.7 1e-320 inf\n",
            ),
            Seed::generated(
                "frames-20000",
                (0..20_000)
                    .map(|f| format!("{f} 0 Car 0 0 0 10 10 20 20 1.5 1.6 4 0 1.7 10 0\n"))
                    .collect::<String>(),
            ),
        ],
        "kitti_calib" => vec![
            Seed::generated(
                "p2-nan",
                "P2: NaN 0 609.5 44.8 0 NaN 172.8 0.2 0 0 1 0.003\n",
            ),
            Seed::generated(
                "p2-huge",
                "P2: 1e308 0 1e308 44.8 0 1e308 1e308 0.2 0 0 1 0.003\n",
            ),
            Seed::generated("p2-zero", "P2: 0 0 0 0 0 0 0 0 0 0 0 0\n"),
            Seed::generated(
                "p2-negative",
                "P2: -721.5 0 -609.5 44.8 0 -721.5 -172.8 0.2 0 0 1 0.003\n",
            ),
            Seed::generated(
                "p2-tiny",
                "P2: 1e-320 0 1e-320 0 0 1e-320 1e-320 0 0 0 1 0\n",
            ),
        ],
        "tracks_json" => {
            let mut v = vec![
                Seed::generated(
                    "frame-u32-max",
                    r#"{"format":"logicrag-tracks/1","name":"x","camera":{"intrinsics":{"fx":721.5,"fy":721.5,"cx":609.6,"cy":172.9,"image_width":1242,"image_height":375},"height_m":1.65},"observations":[{"frame":4294967295,"track_id":1,"class":"Vehicles","bbox":{"left":1,"top":1,"right":2,"bottom":2}}]}"#,
                ),
                Seed::generated(
                    "frame-count-huge",
                    r#"{"format":"logicrag-tracks/1","name":"x","frame_count":4294967295,"camera":{"intrinsics":{"fx":721.5,"fy":721.5,"cx":609.6,"cy":172.9,"image_width":1242,"image_height":375},"height_m":1.65},"observations":[]}"#,
                ),
                Seed::generated(
                    "fps-tiny",
                    r#"{"format":"logicrag-tracks/1","name":"x","fps":1e-300,"camera":{"intrinsics":{"fx":721.5,"fy":721.5,"cx":609.6,"cy":172.9,"image_width":1242,"image_height":375},"height_m":1.65},"observations":[]}"#,
                ),
                Seed::generated(
                    "huge-numbers",
                    r#"{"format":"logicrag-tracks/1","name":"x","camera":{"intrinsics":{"fx":1e308,"fy":1e308,"cx":1e308,"cy":1e308,"image_width":4294967295,"image_height":4294967295},"height_m":1e308},"observations":[{"frame":0,"track_id":1,"class":"Vehicles","bbox":{"left":-1e308,"top":-1e308,"right":1e308,"bottom":1e308},"position":[1e308,1e308,1e308],"size":[1e308,1e308,1e308],"yaw":1e308}]}"#,
                ),
            ];
            if let Some(t) = tracks_seed_text() {
                v.push(Seed::generated("simulated-braking", t));
            }
            v
        }
        "scenario_yaml" => {
            let mut v: Vec<Seed> = perception::sim::BUILTIN_NAMES
                .iter()
                .filter_map(|n| {
                    perception::sim::builtin_text(n)
                        .map(|t| Seed::generated(&format!("builtin-{n}"), t))
                })
                .collect();
            v.push(Seed::generated(
                "frames-1000000",
                scenario_with("1000000", "braking"),
            ));
            v.push(Seed::generated(
                "frames-u32-max",
                scenario_with("4294967295", "braking"),
            ));
            v.push(Seed::generated(
                "name-traversal",
                scenario_with("60", "../../x"),
            ));
            v.push(Seed::generated("agents-2000", many_agents_yaml(2000)));
            v.push(Seed::generated("agents-255", many_agents_yaml(255)));
            v.push(Seed::generated(
                "fps-nan",
                scenario_with("60", "braking").replace("fps: 10", "fps: .nan"),
            ));
            v
        }
        "scenario_json" => {
            let mut v: Vec<Seed> = perception::sim::BUILTIN_NAMES
                .iter()
                .filter_map(|n| perception::sim::Scenario::builtin(n).ok())
                .filter_map(|s| {
                    serde_json::to_string(&s)
                        .ok()
                        .map(|t| Seed::generated(&format!("builtin-{}", s.name), t))
                })
                .collect();
            v.push(Seed::generated(
                "frames-1000000",
                r#"{"name":"big","frames":1000000,"ego":{"speed":10}}"#,
            ));
            v.push(Seed::generated(
                "name-traversal",
                r#"{"name":"../../x","frames":10,"ego":{"speed":10}}"#,
            ));
            v.push(Seed::generated("phase-u32-max", r#"{"name":"p","frames":10,"ego":{"speed":10,"phases":[{"from":0,"to":4294967295,"accel":1}]}}"#));
            v
        }
        "config_yaml" => vec![
            Seed::generated("savgol-window-1000000001", "savgol_window: 1000000001\n"),
            Seed::generated(
                "savgol-order-max",
                "savgol_window: 101\nsavgol_order: 4294967295\n",
            ),
            Seed::generated(
                "nan-threshold",
                "moving_speed_vehicle_mps: .nan\nnear_far_m: .inf\n",
            ),
            Seed::generated(
                "lookback-max",
                "appear_lookback_frames: 4294967295\ndisappear_lookahead_frames: 4294967295\n",
            ),
            Seed::generated(
                "default",
                serde_json::to_value(perception::FactConfig::default())
                    .ok()
                    .and_then(|v| serde_json::to_string_pretty(&v).ok())
                    .unwrap_or_default(),
            ),
        ],
        "config_json" => vec![
            Seed::generated(
                "savgol-window-1000000001",
                r#"{"savgol_window": 1000000001}"#,
            ),
            Seed::generated(
                "min-observations-max",
                r#"{"min_observations": 4294967295}"#,
            ),
            Seed::generated(
                "fractions-inverted",
                r#"{"left_fraction": 0.9, "right_fraction": 0.1}"#,
            ),
            Seed::generated(
                "default",
                serde_json::to_string(&perception::FactConfig::default()).unwrap_or_default(),
            ),
        ],
        "model_config" => vec![
            Seed::generated(
                "huge-input",
                crate::targets::MODEL_DETECTOR.replace(
                    "width: 32, height: 32",
                    "width: 4294967295, height: 4294967295",
                ),
            ),
            Seed::generated(
                "many-strides",
                crate::targets::MODEL_DETECTOR.replace(
                    "strides: [8, 16]",
                    &format!("strides: [{}]", vec!["1"; 10_000].join(", ")),
                ),
            ),
            Seed::generated(
                "reg-max-huge",
                crate::targets::MODEL_DETECTOR.replace("reg_max: 3", "reg_max: 4294967295"),
            ),
            Seed::generated(
                "classes-huge",
                crate::targets::MODEL_DETECTOR
                    .replace("num_classes: 3", "num_classes: 18446744073709551615"),
            ),
            Seed::generated("set-self", "detector: fuzz.yaml\n"),
            Seed::generated("set-dev-zero", "detector: /dev/zero\n"),
        ],
        "camera" => vec![
            Seed::generated(
                "nan",
                "fx: .nan\nfy: .nan\ncx: .nan\ncy: .nan\nheight_m: .nan\n",
            ),
            Seed::generated(
                "huge",
                "fx: 1e308\nfy: 1e308\ncx: 1e308\ncy: 1e308\nheight_m: 1.65\nimage_width: 4294967295\nimage_height: 4294967295\n",
            ),
            Seed::generated(
                "zero-size",
                "fx: 700\nfy: 700\ncx: 0\ncy: 0\nheight_m: 1.65\nimage_width: 0\nimage_height: 0\n",
            ),
            Seed::generated(
                "p2-nan",
                "P2: NaN 0 609.5 44.8 0 NaN 172.8 0.2 0 0 1 0.003\n",
            ),
        ],
        "source_spec" => vec![
            Seed::generated("seed-overflow", "sim:urban_crossing@18446744073709551616"),
            Seed::generated("range-overflow", "0-4294967296"),
            Seed::generated("range-reversed", "9-0"),
            Seed::generated("long-path", format!("kitti:{}", "a/".repeat(100_000))),
        ],
        "av2_feather" => vec![
            Seed::generated("garbage", "not an arrow file"),
            Seed::generated("magic-only", b"ARROW1\0\0ARROW1".to_vec()),
            Seed::generated("footer-length-huge", {
                let mut b = b"ARROW1\0\0".to_vec();
                b.extend_from_slice(&[0u8; 16]);
                b.extend_from_slice(&i32::MAX.to_le_bytes());
                b.extend_from_slice(b"ARROW1");
                b
            }),
            Seed::generated("feather-v1-magic", b"FEA1\0\0\0\0FEA1".to_vec()),
        ],
        "av2_map" => vec![
            Seed::generated("empty-object", "{}"),
            Seed::generated(
                "layers-as-lists",
                r#"{"lane_segments": [], "pedestrian_crossings": [], "drivable_areas": []}"#,
            ),
            Seed::generated(
                "lane-one-point",
                r#"{"lane_segments": {"1": {"id": 1, "lane_type": "VEHICLE", "left_lane_boundary": [{"x": 0, "y": 0}], "right_lane_boundary": [{"x": 1, "y": 0}, {"x": 2, "y": 0}]}}, "pedestrian_crossings": {}, "drivable_areas": {}}"#,
            ),
            Seed::generated(
                "huge-coordinates",
                r#"{"lane_segments": {}, "pedestrian_crossings": {"2": {"id": 2, "edge1": [{"x": 1e308, "y": -1e308, "z": 0}, {"x": -1e308, "y": 1e308, "z": 0}], "edge2": [{"x": 1e308, "y": 1e308, "z": 0}, {"x": 0, "y": 0, "z": 0}]}}, "drivable_areas": {}}"#,
            ),
            Seed::generated("deep-nesting", "[".repeat(100_000)),
        ],
        _ => Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_target_has_committed_and_generated_seeds() {
        for t in crate::targets::ALL {
            let seeds = load(&default_dir(), t).expect("corpus loads");
            let committed = seeds.iter().filter(|s| !s.name.starts_with("gen:")).count();
            assert!(committed > 0, "{} has no committed seed", t.name);
            assert!(seeds.len() > committed, "{} has no generated seed", t.name);
        }
    }

    #[test]
    fn the_tracks_seed_is_simulated() {
        assert!(tracks_seed_text().is_some_and(|t| t.contains("logicrag-tracks/1")));
    }

    #[test]
    fn hostile_seeds_of_the_issue_are_there() {
        let names = |t: &str| -> Vec<String> {
            let target = crate::targets::find(t).expect("target");
            load(&default_dir(), target)
                .expect("corpus")
                .into_iter()
                .map(|s| s.name)
                .collect()
        };
        assert!(names("query").contains(&"gen:twelve-atoms".to_string()));
        assert!(names("query").contains(&"gen:disequalities-20000".to_string()));
        assert!(names("scenario_yaml").contains(&"gen:frames-1000000".to_string()));
        assert!(names("scenario_yaml").contains(&"gen:name-traversal".to_string()));
        assert!(names("kitti_labels").contains(&"gen:objects-2000-one-frame".to_string()));
        assert!(names("logicpad").contains(&"gen:chained-implications-10000".to_string()));
        assert!(names("config_yaml").contains(&"gen:savgol-window-1000000001".to_string()));
        assert!(names("camera").contains(&"gen:invalid-utf8-start".to_string()));
    }
}
