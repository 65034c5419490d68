//! Sources, one syntax everywhere: `sim:SCENARIO[@SEED]`, `kitti:DIR`,
//! `json:FILE`, `facts:PATH` (a text KB file, or a directory with one window
//! per file). Every source becomes a list of [`WindowInput`]s plus what it
//! can observe.

use crate::facts_text::{FactsTextError, read_facts_file};
use crate::kb::{Observability, WindowInput};
use perception::sim::SimRun;
use perception::{Fact, FactConfig, PerceptionError, Provenance, Sequence, Source, WindowSpec};
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Errors while loading a source.
#[derive(Debug, thiserror::Error)]
pub enum SourceError {
    /// Occurs when perception cannot load or analyse a sequence.
    #[error(transparent)]
    Perception(#[from] PerceptionError),
    /// Occurs when a text KB does not parse.
    #[error(transparent)]
    FactsText(#[from] FactsTextError),
    /// Occurs when the source string is not understood or incomplete.
    #[error("source `{spec}`: {message}")]
    Spec {
        /// The source string.
        spec: String,
        /// What is wrong.
        message: String,
    },
    /// Occurs when a `facts:` directory cannot be listed.
    #[error("cannot list {dir}: {source}")]
    Io {
        /// The directory.
        dir: String,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
}

/// Which frames to cut into windows.
#[derive(Debug, Clone)]
pub struct LoadOptions {
    /// KITTI sequence (`0000`); other sources have one sequence.
    pub sequence: Option<String>,
    /// Window size and stride.
    pub windows: WindowSpec,
    /// One explicit inclusive frame range instead of sliding windows.
    pub frames: Option<(u32, u32)>,
    /// Perception thresholds.
    pub config: FactConfig,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            sequence: None,
            windows: WindowSpec::PAPER,
            frames: None,
            config: FactConfig::default(),
        }
    }
}

/// A loaded source: its windows and what it can observe.
#[derive(Debug)]
pub struct Loaded {
    /// `kitti:0000`, `sim:urban_crossing`, `facts:DIR`.
    pub label: String,
    /// Windows in order.
    pub windows: Vec<WindowInput>,
    /// Base predicates this source cannot produce.
    pub observability: Observability,
    /// The perceived sequence (not for `facts:` sources).
    pub sequence: Option<Sequence>,
    /// The simulation (for `sim:` sources): ground truth and scene states.
    pub sim: Option<SimRun>,
}

/// Predicates KITTI tracking labels cannot support: they carry no colour,
/// no static scene classes and no support surfaces.
pub const KITTI_UNOBSERVABLE: &[&str] = &[
    "ColorOf",
    "On",
    "Road",
    "Sidewalk",
    "LaneMarking",
    "Pole",
    "TrafficSign",
    "TrafficLight",
    "Building",
    "Vegetation",
    "Fence",
    "Wall",
    "Terrain",
    "ConstructionObj",
    "Other",
];

/// Predicates a frames run with `set` cannot support: `On` (a detector sees
/// no support surfaces) and every class predicate its detector's label map
/// never produces — with the shipped NanoDet config, surfaces and scenery
/// but also `Cyclist`, `Person` and `Misc` (COCO has one `person` class,
/// mapped to `Pedestrian`). Asking about them must be "unknown", not "no".
pub fn frames_unobservable(set: &perception::raw::frames::ModelSet) -> Vec<&'static str> {
    let seen: std::collections::BTreeSet<&str> = set
        .detector
        .config
        .labels
        .iter()
        .map(|l| l.class.as_str())
        .collect();
    std::iter::once("On")
        .chain(
            perception::raw::config::CLASS_PREDICATES
                .iter()
                .copied()
                .filter(|c| !seen.contains(c)),
        )
        .collect()
}

/// Runs the raw-frames pipeline (`frames:DIR` with a model set file) and
/// cuts its sequence into windows; `frames` holds the pipeline's settings
/// (camera calibration, frame rate, …), `progress` sees every frame.
pub fn load_frames(
    spec: &str,
    models: &Path,
    opts: &LoadOptions,
    frames: &perception::raw::frames::FramesOptions,
    progress: &mut dyn FnMut(perception::raw::frames::Progress),
) -> Result<Loaded, SourceError> {
    let Some(dir) = spec.strip_prefix("frames:") else {
        return Err(SourceError::Spec {
            spec: spec.into(),
            message: "expected frames:DIR".into(),
        });
    };
    let sequence =
        perception::raw::frames::FramesSource::open(Path::new(dir), models, frames, progress)
            .map_err(|e| SourceError::Perception(e.into()))?;
    let windows = sequence_windows(&sequence, opts)?;
    // `open` has read and checked this file already.
    let set = perception::raw::frames::ModelSet::load(models)
        .map_err(|e| SourceError::Perception(e.into()))?;
    let observability = Observability::everything().without(
        &frames_unobservable(&set),
        "the detector's label map has no such class, and a detector sees no support surfaces",
    );
    Ok(Loaded {
        label: sequence.source_label(),
        windows,
        observability,
        sequence: Some(sequence),
        sim: None,
    })
}

/// Loads a source string.
pub fn load(spec: &str, opts: &LoadOptions) -> Result<Loaded, SourceError> {
    if let Some(path) = spec.strip_prefix("facts:") {
        return load_facts(spec, Path::new(path));
    }
    if spec.starts_with("frames:") {
        return Err(SourceError::Spec {
            spec: spec.to_string(),
            message: "the raw-frames source needs `--models FILE`; use `logicrag facts --source frames:DIR --models FILE`"
                .into(),
        });
    }
    let source = Source::parse(spec)?;
    let (sequence, sim, observability) = match &source {
        Source::Sim { .. } => {
            let run = source.simulate()?;
            (run.sequence.clone(), Some(run), Observability::everything())
        }
        Source::Kitti { .. } => {
            let name = match &opts.sequence {
                Some(s) => s.clone(),
                None => {
                    return Err(SourceError::Spec {
                        spec: spec.to_string(),
                        message: "a KITTI source needs `--sequence NNNN` (e.g. 0000)".into(),
                    });
                }
            };
            let seq = source.load(Some(&name))?;
            let obs = Observability::everything().without(
                KITTI_UNOBSERVABLE,
                "KITTI tracking labels carry no colours, scene surfaces or static classes",
            );
            (seq, None, obs)
        }
        Source::Json { .. } => (
            source.load(opts.sequence.as_deref())?,
            None,
            Observability::everything(),
        ),
    };
    let windows = sequence_windows(&sequence, opts)?;
    Ok(Loaded {
        label: sequence.source_label(),
        windows,
        observability,
        sequence: Some(sequence),
        sim,
    })
}

/// Cuts a sequence into window inputs (ids `<sequence>_<first frame, 6 digits>`).
pub fn sequence_windows(
    seq: &Sequence,
    opts: &LoadOptions,
) -> Result<Vec<WindowInput>, SourceError> {
    let wf = match opts.frames {
        Some((a, b)) => vec![perception::range_facts(seq, a, b, &opts.config)?],
        None => perception::window_facts(seq, opts.windows, &opts.config)?,
    };
    Ok(wf
        .into_iter()
        .map(|w| WindowInput {
            id: format!("{}_{:06}", seq.name, w.first_frame),
            index: w.index,
            first_frame: w.first_frame,
            last_frame: w.last_frame,
            facts: w.facts,
        })
        .collect())
}

fn load_facts(spec: &str, path: &Path) -> Result<Loaded, SourceError> {
    let files: Vec<PathBuf> = if path.is_dir() {
        let mut v = Vec::new();
        let rd = std::fs::read_dir(path).map_err(|source| SourceError::Io {
            dir: path.display().to_string(),
            source,
        })?;
        for entry in rd {
            let entry = entry.map_err(|source| SourceError::Io {
                dir: path.display().to_string(),
                source,
            })?;
            let p = entry.path();
            let hidden = p
                .file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with('.'));
            if p.is_file() && !hidden {
                v.push(p);
            }
        }
        v.sort();
        if v.is_empty() {
            return Err(SourceError::Spec {
                spec: spec.into(),
                message: "the directory holds no fact files".into(),
            });
        }
        v
    } else if path.is_file() {
        vec![path.to_path_buf()]
    } else {
        return Err(SourceError::Spec {
            spec: spec.into(),
            message: format!("{} is neither a file nor a directory", path.display()),
        });
    };
    // A window is named by its file's stem; two files with one stem would
    // make two windows with one id, and lookups by id would see only one.
    let mut stems: HashMap<&str, &Path> = HashMap::new();
    for f in &files {
        let stem = f.file_stem().and_then(|s| s.to_str()).unwrap_or("window");
        if let Some(other) = stems.insert(stem, f) {
            return Err(SourceError::Spec {
                spec: spec.into(),
                message: format!(
                    "{} and {} would both be window `{stem}`; rename one",
                    other.display(),
                    f.display()
                ),
            });
        }
    }
    let label = format!("facts:{}", path.display());
    let windows: Result<Vec<WindowInput>, SourceError> = files
        .par_iter()
        .enumerate()
        .map(|(i, f)| {
            let text_facts = read_facts_file(f)?;
            let id = f
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("window")
                .to_string();
            let mut facts: Vec<Fact> = text_facts
                .into_iter()
                .map(|t| Fact {
                    predicate: t.predicate,
                    args: t.args,
                    provenance: Provenance {
                        window: i as u32,
                        frames: (0, 0),
                        source: label.clone(),
                        measured: None,
                        threshold: None,
                        // The window id names the file; a per-fact note
                        // would cost an allocation per fact for nothing.
                        note: String::new(),
                    },
                })
                .collect();
            if !facts.is_sorted_by(|a, b| a.key() <= b.key()) {
                facts.sort_unstable_by(|a, b| a.key().cmp(&b.key()));
            }
            facts.dedup_by(|a, b| a.key() == b.key());
            Ok(WindowInput {
                id,
                index: i as u32,
                first_frame: 0,
                last_frame: 0,
                facts,
            })
        })
        .collect();
    Ok(Loaded {
        label,
        windows: windows?,
        observability: Observability::everything(),
        sequence: None,
        sim: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_fact_files_with_one_stem_are_an_error_not_one_lost_window() {
        let dir = std::env::temp_dir().join(format!("logicrag-stems-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("w1.facts"), "Vehicles(car_1)\n").unwrap();
        std::fs::write(dir.join("w1.txt"), "Pedestrian(p_1)\n").unwrap();
        std::fs::write(dir.join("w2.facts"), "Vehicles(car_2)\n").unwrap();
        let spec = format!("facts:{}", dir.display());
        let e = load(&spec, &LoadOptions::default())
            .err()
            .map(|e| e.to_string());
        std::fs::remove_file(dir.join("w1.txt")).unwrap();
        let ok = load(&spec, &LoadOptions::default());
        std::fs::remove_dir_all(&dir).unwrap();
        let e = e.expect("duplicate stems must be refused");
        assert!(
            e.contains("w1.facts") && e.contains("w1.txt") && e.contains("`w1`"),
            "{e}"
        );
        let ids: Vec<String> = ok.unwrap().windows.iter().map(|w| w.id.clone()).collect();
        assert_eq!(ids, ["w1", "w2"]);
    }

    #[test]
    fn a_frames_run_cannot_observe_classes_its_detector_does_not_label() {
        // Regression: `Cyclist`, `Person` and `Misc` counted as observed for
        // the COCO detector, which has no such class, so "is there a
        // cyclist?" was answered "no" instead of "unknown".
        let models = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../perception/models/nanodet-m-416-coco.yaml");
        let set = perception::raw::frames::ModelSet::load(&models).unwrap();
        let un = frames_unobservable(&set);
        for p in ["On", "Cyclist", "Person", "Misc", "Road", "Building"] {
            assert!(un.contains(&p), "{p} should be unobservable: {un:?}");
        }
        for p in [
            "Vehicles",
            "Pedestrian",
            "TrafficLight",
            "TrafficSign",
            "ColorOf",
        ] {
            assert!(!un.contains(&p), "{p} is observed: {un:?}");
        }
    }
}
