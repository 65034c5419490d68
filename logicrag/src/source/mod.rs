//! Sources, one syntax everywhere: `sim:SCENARIO[@SEED]`, `kitti:DIR`,
//! `json:FILE`, `av2:DIR` (an Argoverse 2 log: 360° annotations, ego pose,
//! map), `facts:PATH` (a text KB file, or a directory with one window per
//! file), `frames:DIR` (raw frames through a model set). A
//! [`SourceSpec`] is parsed once, with each kind's own options inside its
//! variant; [`load`] turns it into a list of [`WindowInput`]s plus what the
//! source can observe.

use crate::facts_text::FactsTextError;
use crate::images::FrameImages;
use crate::kb::{Observability, WindowInput};
use perception::sim::SimRun;
use perception::{FactConfig, PerceptionError, Sequence, Source, WindowSpec};
use std::path::PathBuf;

mod loaders;
mod observe;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod type_value_tests;

pub(crate) use loaders::load_sequence;
use loaders::{load_facts, load_frames, sequence_windows, unreachable_kind};
pub use observe::KITTI_UNOBSERVABLE;
use observe::{av2_observability, camera_observability, map_observability, unassigned_types};

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
        self.kind_and_syntax().0
    }

    /// How this kind is written: `sim:SCENARIO[@SEED]`, `frames:DIR`, ….
    pub fn syntax(&self) -> &'static str {
        self.kind_and_syntax().1
    }

    /// [`SourceSpec::kind`] and [`SourceSpec::syntax`], one row per kind.
    fn kind_and_syntax(&self) -> (&'static str, &'static str) {
        match self {
            SourceSpec::Sim { .. } => ("sim", "sim:SCENARIO[@SEED]"),
            SourceSpec::Kitti { .. } => ("kitti", "kitti:DIR"),
            SourceSpec::Json { .. } => ("json", "json:FILE"),
            SourceSpec::Av2 { .. } => ("av2", "av2:DIR"),
            SourceSpec::Facts { .. } => ("facts", "facts:PATH"),
            SourceSpec::Frames { .. } => ("frames", "frames:DIR"),
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
    /// A sequence cut into `windows`, labelled by its source, observing
    /// `observability` less the map's predicates when it has no map.
    fn of_sequence(
        sequence: Sequence,
        windows: Vec<WindowInput>,
        observability: Observability,
        sim: Option<SimRun>,
        images: Option<FrameImages>,
    ) -> Loaded {
        Loaded {
            label: sequence.source_label(),
            windows,
            observability: map_observability(&sequence, observability),
            sequence: Some(sequence),
            sim,
            images,
        }
    }

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
    Ok(Loaded::of_sequence(
        sequence,
        windows,
        observability,
        sim,
        images,
    ))
}
