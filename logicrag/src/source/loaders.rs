//! The loaders of the sequence kinds, a tracks table's sequence, raw
//! frames and fact files, each cut into windows.

use super::observe::{camera_observability, frames_unobservable, unassigned_types};
use super::{LoadOptions, Loaded, MAX_FACT_FILES, Progress, SourceError, SourceSpec, window_id};
use crate::facts_text::read_facts_file_interned;
use crate::images::FrameImages;
use crate::kb::{Observability, WindowFacts, WindowInput};
use perception::{Provenance, Sequence};
use rayon::prelude::*;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Cuts a sequence read elsewhere (a tracks table: Python's
/// `Engine.open_tracks`, [`crate::arrow::tracks_from_batches`]) into
/// windows, labelled `<source>:<name>`. It observes everything its
/// observations can show: what is behind the ego unless every observation
/// is a camera's box, the map's predicates only with a map, colours only
/// when some observation has one.
pub(crate) fn load_sequence(sequence: Sequence, opts: &LoadOptions) -> Result<Loaded, SourceError> {
    sequence.validate()?;
    let mut observability = camera_observability(&sequence, Observability::everything());
    if sequence.observations.iter().all(|o| o.color.is_none()) {
        observability = observability.without(&["ColorOf"], "the tracks carry no colours");
    }
    let windows = sequence_windows(&sequence, opts)?;
    Ok(Loaded::of_sequence(
        sequence,
        windows,
        observability,
        None,
        None,
    ))
}

/// Kinds handled before the sequence kinds; reaching here is a bug in this
/// module, reported as an error rather than a panic.
pub(super) fn unreachable_kind<T>(spec: &SourceSpec) -> Result<T, SourceError> {
    Err(SourceError::Spec {
        spec: spec.to_string(),
        message: "internal: this source kind has its own loader".into(),
    })
}

/// Runs the raw-frames pipeline (`frames:DIR` with a model set file) and
/// cuts its sequence into windows. A `--frames` range past the directory's
/// frame count is refused before any model runs.
pub(super) fn load_frames(
    spec: &SourceSpec,
    dir: &Path,
    models: Option<&Path>,
    camera: Option<&Path>,
    fps: Option<f64>,
    opts: &LoadOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Loaded, SourceError> {
    let Some(models) = models else {
        return Err(SourceError::Spec {
            spec: spec.to_string(),
            message: "a frames: source needs --models FILE (e.g. perception/models/nanodet-m-416-coco.yaml)".into(),
        });
    };
    // Frames are numbered by their order in the directory, not by their
    // file names.
    if let Some((_, last)) = opts.frames {
        let count = perception::raw::frames::list_frames(dir)
            .map_err(|e| SourceError::Perception(e.into()))?
            .len();
        if usize::try_from(last).map_or(true, |l| l >= count) {
            return Err(SourceError::Spec {
                spec: spec.to_string(),
                message: format!(
                    "--frames ending at {last}: the directory has {count} frames, numbered 0–{} by their order in it (file names are not frame numbers)",
                    count.saturating_sub(1)
                ),
            });
        }
    }
    let mut frames = perception::raw::frames::FramesOptions::default();
    if let Some(path) = camera {
        frames.camera = Some(
            perception::raw::camera::Calibration::read(path)
                .map_err(|e| SourceError::Perception(e.into()))?,
        );
    }
    if let Some(f) = fps {
        frames.fps = f;
    }
    let sequence = perception::raw::frames::FramesSource::open(dir, models, &frames, progress)
        .map_err(|e| SourceError::Perception(e.into()))?;
    let windows = sequence_windows(&sequence, opts)?;
    // `open` has read and checked this file already.
    let set = perception::raw::frames::ModelSet::load(models)
        .map_err(|e| SourceError::Perception(e.into()))?;
    // The detector's label map names the types it can tell; every other
    // value of the built-in taxonomy (a body style, a tram) is unseen.
    let untyped = unassigned_types(
        set.detector
            .config
            .labels
            .iter()
            .filter_map(|l| l.type_name.as_deref()),
    );
    let observability = Observability::everything()
        .without(
            &frames_unobservable(&set),
            "the detector's label map has no such class, and a detector sees no support surfaces",
        )
        .without_type_values(&untyped, "the detector's label map has no such type")
        .forward_camera();
    let images = perception::raw::frames::list_frames(dir)
        .ok()
        .map(FrameImages::in_order);
    Ok(Loaded::of_sequence(
        sequence,
        windows,
        observability,
        None,
        images,
    ))
}

/// Cuts a sequence into window inputs (ids `<sequence>_<first frame, 6 digits>`).
pub(crate) fn sequence_windows(
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
            id: window_id(&seq.name, w.first_frame),
            index: w.index,
            first_frame: w.first_frame,
            last_frame: w.last_frame,
            facts: WindowFacts::Listed(w.facts),
            doubts: w.doubts,
        })
        .collect())
}

pub(super) fn load_facts(spec: &SourceSpec, path: &Path) -> Result<Loaded, SourceError> {
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
                // Counted while listing: 100,000 files took 3 GB before
                // anything was said.
                if v.len() > MAX_FACT_FILES {
                    return Err(SourceError::Spec {
                        spec: spec.to_string(),
                        message: format!(
                            "the directory holds more than {MAX_FACT_FILES} fact files (one window each); split it"
                        ),
                    });
                }
            }
        }
        v.sort();
        if v.is_empty() {
            return Err(SourceError::Spec {
                spec: spec.to_string(),
                message: "the directory holds no fact files".into(),
            });
        }
        v
    } else if path.is_file() {
        vec![path.to_path_buf()]
    } else {
        return Err(SourceError::Spec {
            spec: spec.to_string(),
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
                spec: spec.to_string(),
                message: format!(
                    "{} and {} would both be window `{stem}`; rename one",
                    other.display(),
                    f.display()
                ),
            });
        }
    }
    let label = format!("facts:{}", path.display());
    let shared_label: std::sync::Arc<str> = label.as_str().into();
    let windows: Result<Vec<WindowInput>, SourceError> = files
        .par_iter()
        .enumerate()
        .map(|(i, f)| {
            // Parsed straight into interned symbols: no `Fact` (and no
            // `String` per name) is ever made for a text KB.
            let facts = read_facts_file_interned(f)?;
            let id = f
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("window")
                .to_string();
            // Every fact of a text KB window comes from the same place: one
            // provenance, shared (the window id names the file; a per-fact
            // note would cost an allocation per fact for nothing).
            let provenance = std::sync::Arc::new(Provenance {
                window: i as u32,
                frames: (0, 0),
                source: shared_label.clone(),
                measured: None,
                threshold: None,
                note: String::new(),
                probability: None,
            });
            // File order is kept; `WindowKb::build` drops duplicates.
            Ok(WindowInput {
                id,
                index: i as u32,
                first_frame: 0,
                last_frame: 0,
                facts: WindowFacts::Parsed { facts, provenance },
                doubts: Vec::new(),
            })
        })
        .collect();
    Ok(Loaded {
        label,
        windows: windows?,
        // A text KB observes everything as given, the ego included (its
        // `Ego(ego)` and motion facts, or their absence): it is the world as
        // its author states it, not a camera's view.
        observability: Observability::everything(),
        sequence: None,
        sim: None,
        images: None,
    })
}
