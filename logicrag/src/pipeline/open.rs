//! Opening a pipeline: the one place that assembles a LogicPad, the
//! engine for a source's observability, the source's windows and a
//! translator ([`OpenOptions`], [`Pipeline::open`]). Every front end —
//! each CLI subcommand, the REPL, `serve`, the Python package — opens its
//! pipeline here and only renders what it answers, so none of them can
//! pair a LogicPad with the wrong observability or translator.

use super::Pipeline;
use crate::engine::{Engine, Translate};
use crate::images::FrameImages;
use crate::kb::Observability;
use crate::session::{SessionError, SourceOptions, camera_note, pad_warning};
use crate::source::{Loaded, Progress, SourceSpec};
use logicpad::LogicPad;
use std::path::PathBuf;
use std::sync::Arc;

/// Which LogicPad a pipeline reasons with.
#[derive(Debug, Clone, Default)]
pub enum PadChoice {
    /// The project's built-in LogicPad (`logicpad/LogicPad.yaml`).
    #[default]
    Builtin,
    /// A LogicPad file, read when the pipeline opens; rules with errors
    /// are left out and a note says so.
    File(PathBuf),
    /// A LogicPad already loaded (the REPL's extended one, Python's).
    Loaded(LogicPad),
    /// A LogicPad already made into an engine ([`OpenOptions::prepared`]):
    /// opening many sources with it (an evaluation's runs) reads the file
    /// and builds its vocabulary once.
    Built(Box<Engine>),
}

impl PadChoice {
    /// The LogicPad `--logicpad` names (the built-in one without a path).
    pub fn from_flag(path: Option<PathBuf>) -> PadChoice {
        path.map_or(PadChoice::Builtin, PadChoice::File)
    }

    /// The engine over this LogicPad for a source that observes what
    /// `observability` says, with the warning to show when some of its
    /// rules had to be left out.
    fn engine(
        &self,
        observability: Observability,
    ) -> Result<(Engine, Option<String>), SessionError> {
        let (pad, warning) = match self {
            PadChoice::Builtin => (LogicPad::builtin(), None),
            PadChoice::File(path) => {
                let pad = LogicPad::load(path)?;
                let warning = pad_warning(&pad, path);
                (pad, warning)
            }
            PadChoice::Loaded(pad) => (pad.clone(), None),
            PadChoice::Built(engine) => return Ok((engine.for_source(observability), None)),
        };
        Ok((Engine::new(pad, observability)?, warning))
    }
}

impl OpenOptions {
    /// The same options with the LogicPad read and built once, for opening
    /// many sources; the LogicPad's warning (rules left out) is returned to
    /// be said once.
    pub fn prepared(mut self) -> Result<(OpenOptions, Option<String>), SessionError> {
        let (engine, warning) = self.logicpad.engine(Observability::everything())?;
        self.logicpad = PadChoice::Built(Box::new(engine));
        Ok((self, warning))
    }
}

/// Everything a front end says once to open a pipeline: the source's
/// options, the LogicPad, the translator, and what of the source to keep
/// besides its windows.
#[derive(Debug, Clone, Default)]
pub struct OpenOptions {
    /// The source's options (`--sequence`, `--window`, `--noise`, …).
    pub source: SourceOptions,
    /// The LogicPad.
    pub logicpad: PadChoice,
    /// How questions become queries (`None`: the built-in grammar).
    pub translator: Option<Arc<dyn Translate>>,
    /// Keep the perceived sequence and the simulation (for drawing scenes
    /// and generating question sets); without it they are dropped once
    /// the windows are cut, so a large log is not held twice.
    pub keep_scene: bool,
}

/// What of a source a pipeline keeps besides its windows: pictures for a
/// multimodal model, and (with [`OpenOptions::keep_scene`]) the sequence
/// and simulation for drawing and question sets. Front ends take them.
#[derive(Debug, Default)]
pub struct SourceExtras {
    /// The frames as pictures, where the source has them.
    pub images: Option<FrameImages>,
    /// The perceived sequence (not for `facts:` sources).
    pub sequence: Option<perception::Sequence>,
    /// The simulation (for `sim:` sources).
    pub sim: Option<perception::sim::SimRun>,
    /// The perception thresholds the windows were cut with.
    pub config: perception::FactConfig,
}

impl Pipeline {
    /// A source opened with the default options (the built-in LogicPad,
    /// the grammar): for tests.
    #[cfg(test)]
    pub(crate) fn open_default(source: &str) -> Pipeline {
        let spec = source.parse().expect("a source spec");
        Pipeline::open(spec, &OpenOptions::default(), &mut |_| {}).expect("the source opens")
    }

    /// Opens `source` (a `--source` string, parsed)
    /// with `options`: the LogicPad read, the source loaded (`progress`
    /// sees every frame of a `frames:` run), the engine built for what the
    /// source observes, the translator set. What the user should know
    /// (a LogicPad with rules left out, an assumed camera, inputs the
    /// source skipped) is in [`Pipeline::notes`].
    pub fn open(
        source: SourceSpec,
        options: &OpenOptions,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Pipeline, SessionError> {
        // The options and the LogicPad first: a mistake in either is
        // reported before minutes of perception.
        let spec = options.source.spec(source)?;
        let load = options.source.load_options()?;
        // Built for everything first, narrowed to what the source
        // observes once it is loaded (sharing the vocabulary).
        let (engine, warning) = options.logicpad.engine(Observability::everything())?;
        let mut notes: Vec<String> = warning.into_iter().collect();
        notes.extend(camera_note(&spec));
        let loaded = crate::source::load(&spec, &load, progress)?;
        let mut p = Pipeline::assemble(&engine, loaded, options, load.config);
        notes.append(&mut p.notes);
        p.notes = notes;
        Ok(p)
    }

    /// Opens a sequence built by the caller (Python's Arrow tracks) as a
    /// source, cut into windows by `options.source`.
    pub fn open_sequence(
        sequence: perception::Sequence,
        options: &OpenOptions,
    ) -> Result<Pipeline, SessionError> {
        let (engine, warning) = options.logicpad.engine(Observability::everything())?;
        let load = options.source.load_options()?;
        let loaded = crate::source::load_sequence(sequence, &load)?;
        let mut p = Pipeline::assemble(&engine, loaded, options, load.config);
        p.notes.splice(0..0, warning);
        Ok(p)
    }

    /// A pipeline without a source, whose engine observes everything: for
    /// front ends that translate or compose rules against the LogicPad's
    /// vocabulary only (`translate`, `rule`, Python's `Engine`).
    pub fn sourceless(options: &OpenOptions) -> Result<Pipeline, SessionError> {
        let (engine, warning) = options.logicpad.engine(Observability::everything())?;
        let mut p = Pipeline::new("(no source)", engine, Vec::new());
        if let Some(t) = &options.translator {
            p.translator = Arc::clone(t);
        }
        p.notes.extend(warning);
        Ok(p)
    }

    /// The engine, source and translator put together; the source's
    /// skipped inputs become notes.
    fn assemble(
        engine: &Engine,
        loaded: Loaded,
        options: &OpenOptions,
        config: perception::FactConfig,
    ) -> Pipeline {
        let notes = loaded.skipped_notes();
        let engine = engine.for_source(loaded.observability);
        let mut p = Pipeline::new(loaded.label, engine, loaded.windows);
        if let Some(t) = &options.translator {
            p.translator = Arc::clone(t);
        }
        p.notes = notes;
        p.extras = SourceExtras {
            images: loaded.images,
            sequence: loaded.sequence.filter(|_| options.keep_scene),
            sim: loaded.sim.filter(|_| options.keep_scene),
            config,
        };
        p
    }

    /// The same windows and translator under another LogicPad, reasoned
    /// again now (the REPL's `:logicpad` and `:rule`). Only a pipeline
    /// that kept its inputs (not one made [`Pipeline::into_reasoned`])
    /// has windows to reason. Of the [`SourceExtras`] only the thresholds
    /// come along: a front end takes the pictures and the scene before.
    pub fn with_logicpad(&self, pad: LogicPad) -> Result<Pipeline, SessionError> {
        let engine = Engine::new(pad, self.engine.observability().clone())?;
        let mut p = self.subset(|_| true);
        p.engine = engine;
        p.build(&|| {})?;
        Ok(p)
    }

    /// What of the source the pipeline kept besides its windows.
    pub fn extras(&self) -> &SourceExtras {
        &self.extras
    }

    /// Drops the kept sequence and simulation (a front end that has drawn
    /// what it needs from them).
    pub fn drop_scene(&mut self) {
        self.extras.sequence = None;
        self.extras.sim = None;
    }

    /// The source's pictures, taken (a front end that sends them to a
    /// model holds them itself).
    pub fn take_images(&mut self) -> Option<FrameImages> {
        self.extras.images.take()
    }
}
