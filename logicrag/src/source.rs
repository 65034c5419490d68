//! Sources, one syntax everywhere: `sim:SCENARIO[@SEED]`, `kitti:DIR`,
//! `json:FILE`, `av2:DIR` (an Argoverse 2 log: 360° annotations, ego pose,
//! map), `facts:PATH` (a text KB file, or a directory with one window per
//! file), `frames:DIR` (raw frames through a model set). A
//! [`SourceSpec`] is parsed once, with each kind's own options inside its
//! variant; [`load`] turns it into a list of [`WindowInput`]s plus what the
//! source can observe.

use crate::facts_text::{FactsTextError, read_facts_file_interned};
use crate::images::FrameImages;
use crate::kb::{Observability, WindowFacts, WindowInput};
use perception::sim::SimRun;
use perception::{FactConfig, PerceptionError, Provenance, Sequence, Source, WindowSpec};
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

/// Where windows come from, parsed once. Each variant holds the options
/// that kind reads and no others, so a flag another kind would ignore
/// cannot be carried along unnoticed ([`SourceSpec::with_sequence`] and
/// [`SourceSpec::with_frames_options`] refuse it).
#[derive(Debug, Clone, PartialEq)]
pub enum SourceSpec {
    /// `sim:SCENARIO[@SEED]`: a built-in scenario (or a scenario file) run
    /// through the simulator with this noise seed.
    Sim {
        /// Scenario name or file.
        scenario: String,
        /// Noise seed.
        seed: u64,
    },
    /// `kitti:DIR`: KITTI tracking labels; a sequence must be chosen.
    Kitti {
        /// The dataset root (with `label_02/`, `calib/`).
        root: PathBuf,
        /// The sequence, e.g. `0000`.
        sequence: Option<String>,
    },
    /// `json:FILE`: tracks in the project's JSON format.
    Json {
        /// The file.
        path: PathBuf,
        /// Which sequence of a multi-sequence file.
        sequence: Option<String>,
    },
    /// `av2:DIR`: an Argoverse 2 log directory (annotations, ego pose and
    /// map Feather/JSON files), read by [`perception::av2`].
    Av2 {
        /// The log directory.
        dir: PathBuf,
    },
    /// `facts:PATH`: a text KB file, or a directory of window files.
    Facts {
        /// File or directory.
        path: PathBuf,
    },
    /// `frames:DIR`: image files through a detector (and optional depth).
    Frames {
        /// The frames directory.
        dir: PathBuf,
        /// Model set YAML (required to load).
        models: Option<PathBuf>,
        /// Camera calibration file (KITTI calib or YAML).
        camera: Option<PathBuf>,
        /// Frames per second.
        fps: Option<f64>,
    },
}

impl SourceSpec {
    /// The kind's prefix: `sim`, `kitti`, `json`, `av2`, `facts` or `frames`.
    pub fn kind(&self) -> &'static str {
        match self {
            SourceSpec::Sim { .. } => "sim",
            SourceSpec::Kitti { .. } => "kitti",
            SourceSpec::Json { .. } => "json",
            SourceSpec::Av2 { .. } => "av2",
            SourceSpec::Facts { .. } => "facts",
            SourceSpec::Frames { .. } => "frames",
        }
    }

    /// How this kind is written: `sim:SCENARIO[@SEED]`, `frames:DIR`, ….
    pub fn syntax(&self) -> &'static str {
        match self {
            SourceSpec::Sim { .. } => "sim:SCENARIO[@SEED]",
            SourceSpec::Kitti { .. } => "kitti:DIR",
            SourceSpec::Json { .. } => "json:FILE",
            SourceSpec::Av2 { .. } => "av2:DIR",
            SourceSpec::Facts { .. } => "facts:PATH",
            SourceSpec::Frames { .. } => "frames:DIR",
        }
    }

    /// Sets the sequence of a KITTI or JSON source; other kinds have one
    /// sequence, and saying which is an error rather than ignored.
    pub fn with_sequence(mut self, name: Option<String>) -> Result<SourceSpec, SourceError> {
        let Some(name) = name else {
            return Ok(self);
        };
        match &mut self {
            SourceSpec::Kitti { sequence, .. } | SourceSpec::Json { sequence, .. } => {
                *sequence = Some(name);
                Ok(self)
            }
            other => Err(SourceError::Spec {
                spec: other.to_string(),
                message: format!(
                    "--sequence does not apply to {} sources (only kitti: and json: hold several sequences)",
                    other.syntax()
                ),
            }),
        }
    }

    /// Sets the frames pipeline's options; any of them on another kind is
    /// an error naming the flag.
    pub fn with_frames_options(
        mut self,
        models_file: Option<PathBuf>,
        camera_file: Option<PathBuf>,
        frame_rate: Option<f64>,
    ) -> Result<SourceSpec, SourceError> {
        if let SourceSpec::Frames {
            models,
            camera,
            fps,
            ..
        } = &mut self
        {
            if let Some(f) = frame_rate
                && !(f.is_finite() && f > 0.0)
            {
                return Err(SourceError::Spec {
                    spec: self.to_string(),
                    message: format!(
                        "--fps must be a positive number of frames per second, got {f}"
                    ),
                });
            }
            *models = models_file;
            *camera = camera_file;
            *fps = frame_rate;
            return Ok(self);
        }
        for (flag, given) in [
            ("--models", models_file.is_some()),
            ("--camera", camera_file.is_some()),
            ("--fps", frame_rate.is_some()),
        ] {
            if given {
                return Err(SourceError::Spec {
                    spec: self.to_string(),
                    message: format!("{flag} applies to frames:DIR sources only"),
                });
            }
        }
        Ok(self)
    }
}

impl std::str::FromStr for SourceSpec {
    type Err = SourceError;

    /// `facts:` and `frames:` are read here; the sequence kinds (`sim:`,
    /// `kitti:`, `json:`, `av2:`) by perception's own parser, so the two can
    /// never disagree on their syntax.
    fn from_str(spec: &str) -> Result<SourceSpec, SourceError> {
        let err = |message: &str| SourceError::Spec {
            spec: spec.to_string(),
            message: message.to_string(),
        };
        let (kind, rest) = spec.split_once(':').ok_or_else(|| {
            err(
                "expected sim:SCENARIO[@SEED], kitti:DIR, json:FILE, av2:DIR, facts:PATH or frames:DIR",
            )
        })?;
        match kind {
            "facts" | "frames" if rest.is_empty() => Err(err("nothing after the colon")),
            "facts" => Ok(SourceSpec::Facts {
                path: PathBuf::from(rest),
            }),
            "frames" => Ok(SourceSpec::Frames {
                dir: PathBuf::from(rest),
                models: None,
                camera: None,
                fps: None,
            }),
            "sim" | "kitti" | "json" | "av2" => Ok(match Source::parse(spec)? {
                Source::Sim { scenario, seed } => SourceSpec::Sim { scenario, seed },
                Source::Kitti { root } => SourceSpec::Kitti {
                    root,
                    sequence: None,
                },
                Source::Json { path } => SourceSpec::Json {
                    path,
                    sequence: None,
                },
                Source::Av2 { dir } => SourceSpec::Av2 { dir },
            }),
            other => Err(err(&format!(
                "unknown source kind `{other}`: expected sim, kitti, json, av2, facts or frames"
            ))),
        }
    }
}

impl std::fmt::Display for SourceSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SourceSpec::Sim { scenario, seed: 0 } => write!(f, "sim:{scenario}"),
            SourceSpec::Sim { scenario, seed } => write!(f, "sim:{scenario}@{seed}"),
            SourceSpec::Kitti { root, .. } => write!(f, "kitti:{}", root.display()),
            SourceSpec::Json { path, .. } => write!(f, "json:{}", path.display()),
            SourceSpec::Av2 { dir } => write!(f, "av2:{}", dir.display()),
            SourceSpec::Facts { path } => write!(f, "facts:{}", path.display()),
            SourceSpec::Frames { dir, .. } => write!(f, "frames:{}", dir.display()),
        }
    }
}

/// The most window files a `facts:DIR` source reads.
pub(crate) const MAX_FACT_FILES: usize = 20_000;

/// The id of the window that starts at `first_frame` of a sequence:
/// `urban_crossing_000030`, `0000_000010`.
pub fn window_id(sequence: &str, first_frame: u32) -> String {
    format!("{sequence}_{first_frame:06}")
}

/// Which frames to cut into windows.
#[derive(Debug, Clone)]
pub struct LoadOptions {
    /// Window size and stride.
    pub windows: WindowSpec,
    /// One explicit inclusive frame range instead of sliding windows.
    pub frames: Option<(u32, u32)>,
    /// Perception thresholds.
    pub config: FactConfig,
    /// For `sim:` sources, a noise level (a preset, or one scaled as
    /// `high*2`) replacing the scenario's own (`None`: the scenario's).
    pub noise: Option<perception::sim::NoiseLevel>,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            windows: WindowSpec::PAPER,
            frames: None,
            config: FactConfig::default(),
            noise: None,
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
    /// The frames as pictures, where the source has them (`frames:DIR`,
    /// `kitti:DIR` with `image_02/NNNN/`, `sim:` rendering its camera
    /// view), for a multimodal model.
    pub images: Option<FrameImages>,
}

impl Loaded {
    /// The inputs the source skipped, counted with their reason (none for
    /// `facts:` sources).
    pub fn skipped(&self) -> &[perception::Skipped] {
        self.sequence.as_ref().map_or(&[], |s| s.skipped.as_slice())
    }

    /// One line per kind of skipped input, for the user to read:
    /// `av2:LOG skipped 157 inputs: the ego vehicle … (e.g. …)`; an entry
    /// that counts nothing is a note on what the source lacks
    /// (`av2:LOG: no city_SE3_egovehicle.feather: ego motion estimated …`).
    pub fn skipped_notes(&self) -> Vec<String> {
        self.skipped()
            .iter()
            .map(|s| {
                let example = if s.example.is_empty() {
                    String::new()
                } else {
                    format!(" (e.g. {})", s.example)
                };
                if s.count == 0 {
                    return format!("{}: {}{example}", self.label, s.reason);
                }
                format!(
                    "{} skipped {} {}: {}{example}",
                    self.label,
                    s.count,
                    if s.count == 1 { "input" } else { "inputs" },
                    s.reason
                )
            })
            .collect()
    }
}

/// The `TypeOf` values perception knows (`TYPE_VALUES`) that a source
/// whose type names are `assigned` never gives, `Other` aside (the vague
/// value is no claim about a kind): what it cannot see, so that "is there
/// a sedan?" on labels that say only `Car` is unknown, not no.
pub(crate) fn unassigned_types<'a>(
    assigned: impl IntoIterator<Item = &'a str>,
) -> Vec<&'static str> {
    let given: std::collections::BTreeSet<String> = assigned
        .into_iter()
        .map(perception::facts::type_value)
        .collect();
    perception::facts::TYPE_VALUES
        .iter()
        .copied()
        .filter(|v| *v != "Other" && !given.contains(*v))
        .collect()
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
pub(crate) fn frames_unobservable(set: &perception::raw::frames::ModelSet) -> Vec<&'static str> {
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

/// What a frames run reports as it goes.
pub use perception::raw::frames::Progress;

/// Loads a source: its windows (cut by `opts`) and what it can observe.
/// `progress` sees every frame of a `frames:` run (other kinds load at once).
pub fn load(
    spec: &SourceSpec,
    opts: &LoadOptions,
    progress: &mut dyn FnMut(Progress),
) -> Result<Loaded, SourceError> {
    let source = match spec {
        SourceSpec::Facts { path } => return load_facts(spec, path),
        SourceSpec::Frames {
            dir,
            models,
            camera,
            fps,
        } => {
            return load_frames(
                spec,
                dir,
                models.as_deref(),
                camera.as_deref(),
                *fps,
                opts,
                progress,
            );
        }
        SourceSpec::Sim { scenario, seed } => Source::Sim {
            scenario: scenario.clone(),
            seed: *seed,
        },
        SourceSpec::Kitti { root, .. } => Source::Kitti { root: root.clone() },
        SourceSpec::Json { path, .. } => Source::Json { path: path.clone() },
        SourceSpec::Av2 { dir } => {
            // Said here, naming the directory, before the reader looks for
            // the files inside it.
            if !dir.is_dir() {
                return Err(SourceError::Spec {
                    spec: spec.to_string(),
                    message: format!(
                        "{} is not a directory (an Argoverse 2 log directory holding annotations.feather or annotations_with_ego.feather)",
                        dir.display()
                    ),
                });
            }
            Source::Av2 { dir: dir.clone() }
        }
    };
    let (sequence, sim, observability) = match spec {
        SourceSpec::Sim { .. } => {
            let run = source.simulate_with(opts.noise)?;
            // A cyclist and their bicycle are one object (`Cyclist`): no
            // `TypeOf(x, Bicycle)` is ever absent for want of a bicycle.
            let obs = Observability::everything()
                .without_type_values(
                    &["Bicycle"],
                    "the simulator tracks a cyclist and their bicycle as one object (Cyclist)",
                )
                .forward_camera();
            (run.sequence.clone(), Some(run), obs)
        }
        SourceSpec::Kitti { sequence, .. } => {
            let Some(name) = sequence else {
                return Err(SourceError::Spec {
                    spec: spec.to_string(),
                    message: "a KITTI source needs `--sequence NNNN` (e.g. 0000)".into(),
                });
            };
            let seq = source.load(Some(name))?;
            // The ego's motion is estimated from the labelled objects
            // (perception::ego), as for every camera source: observed.
            let obs = Observability::everything()
                .without(
                    KITTI_UNOBSERVABLE,
                    "KITTI tracking labels carry no colours, scene surfaces or static classes",
                )
                .without_type_values(
                    &unassigned_types(perception::kitti::KITTI_TYPES),
                    "KITTI tracking labels have no such type (Car, Van, Truck, Tram, Pedestrian, Person_sitting, Cyclist, Misc): never a car's body style, a bus or a bicycle",
                )
                .forward_camera();
            (seq, None, obs)
        }
        SourceSpec::Json { sequence, .. } => {
            let seq = source.load(sequence.as_deref())?;
            let obs = camera_observability(&seq, Observability::everything());
            (seq, None, obs)
        }
        SourceSpec::Av2 { .. } => {
            let seq = source.load(None)?;
            let obs = camera_observability(&seq, av2_observability());
            (seq, None, obs)
        }
        SourceSpec::Facts { .. } | SourceSpec::Frames { .. } => unreachable_kind(spec)?,
    };
    let observability = map_observability(&sequence, observability);
    let windows = sequence_windows(&sequence, opts)?;
    // KITTI keeps each sequence's left colour frames in image_02/NNNN/;
    // the simulator renders its camera's view of each frame.
    let images = match spec {
        SourceSpec::Kitti {
            root,
            sequence: Some(name),
        } => FrameImages::numbered(&root.join("image_02").join(name)),
        SourceSpec::Sim { .. } => sim
            .as_ref()
            .map(|run| FrameImages::rendered(&run.states))
            .filter(|images| !images.is_empty()),
        _ => None,
    };
    Ok(Loaded {
        label: sequence.source_label(),
        windows,
        observability,
        sequence: Some(sequence),
        sim,
        images,
    })
}

/// The predicates only a map can support (`Sequence::map`): on a source
/// without one, "is the car on a crosswalk?" is unknown, never no.
pub const MAP_PREDICATES: &[&str] = &[
    "OnCrosswalk",
    "NearCrosswalk",
    "InDrivableArea",
    "Lane",
    "LaneType",
    "OnLane",
    "InIntersection",
    "NearIntersection",
    "SameLane",
    "Following",
];

/// `obs`, with the map's predicates unobservable when `seq` has no map.
fn map_observability(seq: &Sequence, obs: Observability) -> Observability {
    if seq.map.is_some() {
        obs
    } else {
        obs.without(
            MAP_PREDICATES,
            "the source has no map (lanes, crosswalks, drivable areas)",
        )
    }
}

/// `obs` for a sequence that may be a forward camera's or a 360° log's:
/// only a camera (every observation with a pixel box) is blind behind the
/// ego.
fn camera_observability(seq: &Sequence, obs: Observability) -> Observability {
    if seq.is_surround() {
        obs
    } else {
        obs.forward_camera()
    }
}

/// What an Argoverse 2 log's annotations cannot tell: colours, scene
/// surfaces and classes it does not annotate, and the `TypeOf` values
/// (body styles, vans) none of its categories names, directly or through
/// the built-in taxonomy (`RegularVehicle` is a `Car`).
fn av2_observability() -> Observability {
    let taxonomy = crate::context::Sentences::builtin()
        .supertypes("TypeOf")
        .cloned()
        .unwrap_or_default();
    // Each category's type value and every value above it.
    let mut given: std::collections::BTreeSet<String> = std::collections::BTreeSet::new();
    let mut todo: Vec<String> = perception::av2::categories::CATEGORIES
        .iter()
        .map(|(_, _, t)| perception::facts::type_value(t))
        .collect();
    while let Some(t) = todo.pop() {
        if let Some(ups) = taxonomy.get(&t) {
            todo.extend(ups.iter().filter(|u| !given.contains(*u)).cloned());
        }
        given.insert(t);
    }
    Observability::everything()
        .without(
            AV2_UNOBSERVABLE,
            "Argoverse 2 annotations carry no colours, scene surfaces or such classes",
        )
        .without_type_values(
            &unassigned_types(given.iter().map(String::as_str)),
            "no Argoverse 2 category is of this type (AV2 tells no car body styles)",
        )
}

/// Predicates Argoverse 2 annotations cannot support: no colours, no
/// support surfaces, and no static classes beyond bollards (`Pole`),
/// signs (`TrafficSign`) and cones and barrels (`ConstructionObj`); the
/// road's layout is the map's (`MAP_PREDICATES`).
pub const AV2_UNOBSERVABLE: &[&str] = &[
    "ColorOf",
    "On",
    "Road",
    "Sidewalk",
    "LaneMarking",
    "TrafficLight",
    "Building",
    "Vegetation",
    "Fence",
    "Wall",
    "Terrain",
];

/// Cuts a sequence read elsewhere (a tracks table: Python's
/// `Engine.open_tracks`, [`crate::arrow::tracks_from_batches`]) into
/// windows, labelled `<source>:<name>`. It observes everything its
/// observations can show: what is behind the ego unless every observation
/// is a camera's box, the map's predicates only with a map, colours only
/// when some observation has one.
pub fn load_sequence(sequence: Sequence, opts: &LoadOptions) -> Result<Loaded, SourceError> {
    sequence.validate()?;
    let mut observability = camera_observability(&sequence, Observability::everything());
    if sequence.observations.iter().all(|o| o.color.is_none()) {
        observability = observability.without(&["ColorOf"], "the tracks carry no colours");
    }
    let observability = map_observability(&sequence, observability);
    let windows = sequence_windows(&sequence, opts)?;
    Ok(Loaded {
        label: sequence.source_label(),
        windows,
        observability,
        sequence: Some(sequence),
        sim: None,
        images: None,
    })
}

/// Kinds handled before the sequence kinds; reaching here is a bug in this
/// module, reported as an error rather than a panic.
fn unreachable_kind<T>(spec: &SourceSpec) -> Result<T, SourceError> {
    Err(SourceError::Spec {
        spec: spec.to_string(),
        message: "internal: this source kind has its own loader".into(),
    })
}

/// Runs the raw-frames pipeline (`frames:DIR` with a model set file) and
/// cuts its sequence into windows. A `--frames` range past the directory's
/// frame count is refused before any model runs.
fn load_frames(
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
    let observability = map_observability(&sequence, observability);
    let images = perception::raw::frames::list_frames(dir)
        .ok()
        .map(FrameImages::in_order);
    Ok(Loaded {
        label: sequence.source_label(),
        windows,
        observability,
        sequence: Some(sequence),
        sim: None,
        images,
    })
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

fn load_facts(spec: &SourceSpec, path: &Path) -> Result<Loaded, SourceError> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_av2_spec_parses_through_perception_and_prints_back() {
        let spec: SourceSpec = "av2:logs/3b3570b4".parse().expect("parses");
        assert_eq!(
            spec,
            SourceSpec::Av2 {
                dir: PathBuf::from("logs/3b3570b4")
            }
        );
        assert_eq!(spec.to_string(), "av2:logs/3b3570b4");
        assert_eq!((spec.kind(), spec.syntax()), ("av2", "av2:DIR"));
        assert_eq!(
            spec.to_string().parse::<SourceSpec>().ok(),
            Some(spec.clone())
        );
        // One sequence per log: naming one is refused, not ignored.
        let e = spec
            .clone()
            .with_sequence(Some("0000".into()))
            .expect_err("a log has one sequence");
        assert!(e.to_string().contains("--sequence"), "{e}");
        assert!("av2:".parse::<SourceSpec>().is_err());
        let e = "nuscenes:x".parse::<SourceSpec>().expect_err("unknown");
        assert!(e.to_string().contains("av2"), "{e}");
        let e = "x".parse::<SourceSpec>().expect_err("no colon");
        assert!(e.to_string().contains("av2:DIR"), "{e}");
    }

    #[test]
    fn a_missing_av2_directory_is_named() {
        let spec: SourceSpec = "av2:/nonexistent/log-dir".parse().expect("parses");
        let e = load(&spec, &LoadOptions::default(), &mut |_| {})
            .expect_err("no such directory")
            .to_string();
        assert!(
            e.contains("/nonexistent/log-dir") && e.contains("not a directory"),
            "{e}"
        );
    }

    #[test]
    fn a_source_without_a_map_cannot_observe_the_map_s_predicates() {
        let spec: SourceSpec = "sim:urban_crossing".parse().expect("parses");
        let loaded = load(&spec, &LoadOptions::default(), &mut |_| {}).expect("loads");
        for p in MAP_PREDICATES {
            assert!(loaded.observability.unobservable.contains_key(*p), "{p}");
        }
        assert!(loaded.skipped().is_empty() && loaded.skipped_notes().is_empty());
    }

    #[test]
    fn the_map_predicates_are_the_logicpad_s_map_group_and_lane_type() {
        // The list cannot drift from the built-in LogicPad's `map:` group.
        let pad = logicpad::LogicPad::builtin();
        let mut declared: Vec<&str> = pad
            .schema()
            .predicates()
            .filter(|p| p.group.as_deref() == Some("map") || p.name == "LaneType")
            .map(|p| p.name.as_str())
            .collect();
        declared.sort_unstable();
        let mut ours = MAP_PREDICATES.to_vec();
        ours.sort_unstable();
        assert_eq!(ours, declared);
    }

    #[test]
    fn an_av2_log_cannot_tell_colours_nor_body_styles_but_tells_cars() {
        let obs = av2_observability();
        assert!(obs.unobservable.contains_key("ColorOf"));
        let blind = |v: &str| obs.blind_atom("TypeOf", &[None, Some(v)]).is_some();
        for v in ["Sedan", "SUV", "Van"] {
            assert!(blind(v), "{v}");
        }
        // Through the taxonomy: a RegularVehicle is a Car, a BoxTruck a Truck.
        for v in [
            "Car",
            "Truck",
            "Bus",
            "Pedestrian",
            "RegularVehicle",
            "Bicycle",
        ] {
            assert!(!blind(v), "{v}");
        }
    }

    #[test]
    fn two_fact_files_with_one_stem_are_an_error_not_one_lost_window() {
        let dir = std::env::temp_dir().join(format!("logicrag-stems-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("w1.facts"), "Vehicles(car_1)\n").unwrap();
        std::fs::write(dir.join("w1.txt"), "Pedestrian(p_1)\n").unwrap();
        std::fs::write(dir.join("w2.facts"), "Vehicles(car_2)\n").unwrap();
        let spec: SourceSpec = format!("facts:{}", dir.display()).parse().unwrap();
        let e = load(&spec, &LoadOptions::default(), &mut |_| {})
            .err()
            .map(|e| e.to_string());
        std::fs::remove_file(dir.join("w1.txt")).unwrap();
        let ok = load(&spec, &LoadOptions::default(), &mut |_| {});
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
    fn a_byte_order_mark_is_not_a_bad_first_line() {
        // Regression: facts, KITTI and query files refused a UTF-8 BOM that
        // YAML files accepted.
        let dir = std::env::temp_dir().join(format!("logicrag-bom-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("w.facts"), "\u{feff}Vehicles(car_1)\n").unwrap();
        let spec: SourceSpec = format!("facts:{}", dir.join("w.facts").display())
            .parse()
            .unwrap();
        let loaded = load(&spec, &LoadOptions::default(), &mut |_| {});
        std::fs::remove_dir_all(&dir).unwrap();
        let loaded = loaded.expect("a BOM is skipped");
        let first = loaded.windows[0].facts.iter().next().expect("one fact");
        assert_eq!(first.args().collect::<Vec<_>>(), ["car_1"]);
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

#[cfg(test)]
mod type_value_tests {
    use super::unassigned_types;

    #[test]
    fn kitti_never_gives_a_body_style_of_the_taxonomy_nor_a_bus() {
        let unseen = unassigned_types(perception::kitti::KITTI_TYPES);
        // Every car body style of the built-in LogicPad's taxonomy (its
        // rules `TypeOf(x, Sedan) ==> TypeOf(x, Car)`): the two lists
        // cannot drift apart.
        let words = crate::context::Sentences::builtin();
        let taxonomy = words.supertypes("TypeOf").cloned().unwrap_or_default();
        let styles: Vec<&String> = taxonomy
            .iter()
            .filter(|(_, up)| up.contains("Car"))
            .map(|(sub, _)| sub)
            .collect();
        assert!(styles.len() >= 9, "{styles:?}");
        for s in styles {
            assert!(unseen.contains(&s.as_str()), "{s}: {unseen:?}");
        }
        for v in ["Bus", "Motorcycle", "Bicycle"] {
            assert!(unseen.contains(&v), "{v}: {unseen:?}");
        }
        for v in [
            "Car",
            "Van",
            "Truck",
            "Tram",
            "Pedestrian",
            "Cyclist",
            "Other",
        ] {
            assert!(!unseen.contains(&v), "{v}: {unseen:?}");
        }
    }

    #[test]
    fn a_detector_sees_the_types_its_label_map_names() {
        let unseen = unassigned_types(["Pedestrian", "Car", "Bus", "truck"]);
        for v in ["Car", "Bus", "Truck", "Pedestrian"] {
            assert!(!unseen.contains(&v), "{v}: {unseen:?}");
        }
        for v in ["Van", "Tram", "Sedan", "Cyclist", "Bicycle"] {
            assert!(unseen.contains(&v), "{v}: {unseen:?}");
        }
    }
}
