//! A directory of camera frames (or of dense maps) into a [`Sequence`]:
//! detection (or dense instances) → tracker → 3D → colour, ready for the same
//! [`crate::window_facts`] as every other source.
//!
//! The models file given to [`FramesSource::open`] is either one detector
//! config (see [`super::config`]) or a set:
//!
//! ```yaml
//! detector: nanodet-m-416-coco.yaml   # relative to this file
//! depth: my-depth.yaml                # optional: metric depth replaces the monocular estimate;
//!                                     # relative depth is fitted onto it per frame
//! flow: my-flow.yaml                  # optional: flow-guided tracking
//! ```

use std::path::{Path, PathBuf};

use image::RgbImage;
use ndarray::Array4;
use serde::Deserialize;

use super::RawError;
use super::camera::Calibration;
use super::color::{ColorConfig, name_box};
use super::config::{DepthMode, LoadedConfig, ModelConfig, OutputSpec, RelativeDepth};
use super::decode::DenseMap;
use super::dense::{ClassTable, DenseFrame, DenseModel, DenseOutput, InstanceConfig, instances};
use super::detect::{Detector, PreparedFrame, Preparer, StageTimes};
use super::ground::GroundConfig;
use super::mono::{DepthEstimate, MonoDepthConfig, centre_offset_m, estimate};
use super::relative::{align, is_anchor};
use super::runtime::Runtime;
use super::tracker::{TrackInput, Tracker, TrackerConfig};
use crate::model::{
    BBox2D, CameraConfig, CameraIntrinsics, DepthSource, MAX_FRAMES, ObjectClass, Observation,
    Sequence, check_frame_count,
};

/// Camera height assumed when the caller gives no camera: KITTI's mounting
/// height (metres).
pub const DEFAULT_CAMERA_HEIGHT_M: f64 = 1.65;

/// Settings of the frames pipeline.
#[derive(Debug, Clone, PartialEq)]
pub struct FramesOptions {
    /// The camera's calibration (the frames give the image size); when
    /// `None`, [`assumed_camera`]: a pinhole with `fx = fy =` image width
    /// (about 53° horizontal field of view), principal point at the image
    /// centre and [`DEFAULT_CAMERA_HEIGHT_M`] — an assumption, recorded as
    /// the sequence's camera, that makes 3D only roughly metric.
    pub camera: Option<Calibration>,
    /// Frame rate of the frames, per second.
    pub fps: f64,
    /// Sequence name; the directory name when `None`.
    pub name: Option<String>,
    /// Tracker settings.
    pub tracker: TrackerConfig,
    /// Flat-ground settings.
    pub ground: GroundConfig,
    /// Monocular depth (flat ground / size prior / fused) when no metric
    /// depth model is configured; a metric depth model always takes
    /// precedence, and a relative one is fitted onto these estimates. Its
    /// centre offsets also apply to depth-map samples.
    pub mono: MonoDepthConfig,
    /// Colour naming settings.
    pub color: ColorConfig,
    /// Dense-instance settings.
    pub instances: InstanceConfig,
    /// Decode and resample the next frame on a second thread while the
    /// models run on the current one (same results, less wall time).
    pub prefetch: bool,
}

impl Default for FramesOptions {
    fn default() -> Self {
        FramesOptions {
            camera: None,
            fps: crate::model::DEFAULT_FPS,
            name: None,
            tracker: TrackerConfig::default(),
            ground: GroundConfig::default(),
            mono: MonoDepthConfig::default(),
            color: ColorConfig::default(),
            instances: InstanceConfig::default(),
            prefetch: true,
        }
    }
}

/// Progress of a long run, reported after every frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Frames done.
    pub done: u32,
    /// Frames in all.
    pub total: u32,
    /// Time in models and elsewhere so far.
    pub times: StageTimes,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ModelSetFile {
    detector: PathBuf,
    #[serde(default)]
    depth: Option<PathBuf>,
    #[serde(default)]
    flow: Option<PathBuf>,
}

/// The models a frames run uses.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelSet {
    /// The detector.
    pub detector: LoadedConfig,
    /// Optional depth model.
    pub depth: Option<LoadedConfig>,
    /// Optional two-frame flow model.
    pub flow: Option<LoadedConfig>,
}

impl ModelSet {
    /// Loads a models file: a set (`detector:` / `depth:` / `flow:`) or a single
    /// detector config.
    pub fn load(path: &Path) -> Result<ModelSet, RawError> {
        let text = std::fs::read_to_string(path).map_err(|e| RawError::io(path, e))?;
        let is_set = text.lines().any(|l| l.starts_with("detector:"));
        if !is_set {
            return Ok(ModelSet {
                detector: ModelConfig::parse(&text, path)?,
                depth: None,
                flow: None,
            });
        }
        let set: ModelSetFile =
            serde_saphyr::from_str(&text).map_err(|e| RawError::ConfigSyntax {
                path: path.to_path_buf(),
                message: crate::error::yaml_message(&e, &path.display().to_string()),
            })?;
        let base = path.parent().unwrap_or(Path::new("."));
        let load = |p: &PathBuf| ModelConfig::load(&base.join(p));
        let set = ModelSet {
            detector: load(&set.detector)?,
            depth: set.depth.as_ref().map(load).transpose()?,
            flow: set.flow.as_ref().map(load).transpose()?,
        };
        set.check_kinds()?;
        Ok(set)
    }

    /// Checks that the `depth:` model is a depth model and the `flow:` model a
    /// flow model: the pipeline only reads outputs of those kinds, so another
    /// kind there would be run (or opened) and then silently ignored.
    pub fn check_kinds(&self) -> Result<(), RawError> {
        let slots = [
            (&self.depth, "depth", "depth"),
            (&self.flow, "flow", "flow"),
        ];
        for (loaded, slot, want) in slots {
            let Some(l) = loaded else { continue };
            let kind = match l.config.output {
                OutputSpec::Detector { .. } => "detector",
                OutputSpec::Segmentation { .. } => "segmentation",
                OutputSpec::Depth { .. } => "depth",
                OutputSpec::Flow { .. } => "flow",
            };
            if kind != want {
                return Err(RawError::ConfigInvalid {
                    path: l.config_path.clone(),
                    field: "output.kind".to_string(),
                    message: format!(
                        "the model set's `{slot}:` needs a `{want}` model, this one is `{kind}`"
                    ),
                });
            }
        }
        Ok(())
    }
}

/// The image files of a frames directory (`.png`, `.jpg`, `.jpeg`), sorted by
/// name; frame `i` is the `i`-th file.
pub fn list_frames(dir: &Path) -> Result<Vec<PathBuf>, RawError> {
    let rd = std::fs::read_dir(dir).map_err(|e| RawError::io(dir, e))?;
    let mut out = Vec::new();
    for entry in rd {
        let path = entry.map_err(|e| RawError::io(dir, e))?.path();
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if matches!(ext.as_deref(), Some("png" | "jpg" | "jpeg")) {
            out.push(path);
        }
    }
    out.sort();
    // Before any model runs: a directory beyond the limit would otherwise
    // fail only after a full run, in `Sequence::validate`.
    checked_frame_count(dir, out.len())?;
    if out.is_empty() {
        return Err(RawError::Frames {
            path: dir.to_path_buf(),
            message: "no .png/.jpg frames in this directory".into(),
        });
    }
    Ok(out)
}

/// `n` frames of `dir` as a frame count, or an error naming the directory
/// and [`MAX_FRAMES`] when there are more.
fn checked_frame_count(dir: &Path, n: usize) -> Result<u32, RawError> {
    let message = match u32::try_from(n) {
        Ok(count) => match check_frame_count("frames", count) {
            Ok(()) => return Ok(count),
            Err(m) => m,
        },
        Err(_) => format!(
            "`frames` {n} exceeds the limit of {MAX_FRAMES} frames (perception::MAX_FRAMES)"
        ),
    };
    Err(RawError::Frames {
        path: dir.to_path_buf(),
        message,
    })
}

/// The camera assumed for uncalibrated frames (see [`FramesOptions::camera`]).
pub fn assumed_camera(width: u32, height: u32) -> CameraConfig {
    let f = f64::from(width);
    CameraConfig {
        intrinsics: CameraIntrinsics {
            fx: f,
            fy: f,
            cx: f64::from(width) / 2.0,
            cy: f64::from(height) / 2.0,
            image_width: width,
            image_height: height,
        },
        height_m: DEFAULT_CAMERA_HEIGHT_M,
    }
}

/// One object of one frame before tracking.
#[derive(Debug, Clone, PartialEq)]
struct Candidate {
    class: ObjectClass,
    type_name: Option<String>,
    bbox: BBox2D,
    score: f32,
    color: Option<&'static str>,
    /// Metric depth of the visible near surface from a metric depth map,
    /// metres.
    depth_m: Option<f64>,
    /// Raw sample of a relative depth map (near surface, unknown scale and
    /// shift) and how to read it.
    relative: Option<(f64, RelativeDepth)>,
}

/// How the `depth:` model's map is used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum DepthUse {
    /// Metres: each box's sample is its depth.
    Metric,
    /// Unknown scale (and shift): fitted per frame to the monocular
    /// estimates.
    Relative(RelativeDepth),
}

impl DepthUse {
    /// Relative for a `mode: relative` depth model (inverse depth unless its
    /// `relative:` says otherwise), metric for any other config: only a depth
    /// model yields a depth map, so the reading of other kinds never matters
    /// (and [`ModelSet::check_kinds`] refuses them in the `depth:` slot).
    fn of(output: &OutputSpec) -> DepthUse {
        match output {
            OutputSpec::Depth {
                mode: DepthMode::Relative,
                relative,
                ..
            } => DepthUse::Relative(relative.unwrap_or_default()),
            _ => DepthUse::Metric,
        }
    }
}

/// Turns per-frame candidates into tracked observations: tracker ids, 3D
/// position (metric depth when known; else relative depth through the
/// frame's [`super::relative::Alignment`]; else the configured monocular
/// estimate — the source recorded in `Observation::depth_source`), and a
/// per-track majority colour. A depth map sees the object's near surface,
/// so a map depth gets the same nearest-face → centre offset as the
/// monocular estimate ([`centre_offset_m`]); one beyond
/// [`GroundConfig::max_depth_m`] (an inverse-depth sample near zero, sky) is
/// no estimate and the box keeps its monocular one.
struct Assembler {
    tracker: Tracker,
    camera: CameraConfig,
    ground: GroundConfig,
    mono: MonoDepthConfig,
    observations: Vec<Observation>,
}

impl Assembler {
    fn new(camera: CameraConfig, options: &FramesOptions) -> Assembler {
        Assembler {
            tracker: Tracker::new(options.tracker),
            camera,
            ground: options.ground,
            mono: options.mono.clone(),
            observations: Vec::new(),
        }
    }

    fn frame(&mut self, frame: u32, candidates: Vec<Candidate>, flow: Option<&DenseMap<f32>>) {
        let inputs: Vec<TrackInput> = candidates
            .iter()
            .map(|c| TrackInput {
                class: c.class,
                bbox: c.bbox,
            })
            .collect();
        let ids = self.tracker.step(frame, &inputs, flow);
        let monos: Vec<Option<DepthEstimate>> = candidates
            .iter()
            .map(|c| {
                estimate(
                    &c.bbox,
                    c.type_name.as_deref(),
                    &self.camera,
                    &self.ground,
                    &self.mono,
                )
            })
            .collect();
        // The frame's fit of relative samples onto the near-face depths of
        // the anchor boxes (one depth model per run, so one reading).
        let kind = candidates.iter().find_map(|c| c.relative.map(|(_, k)| k));
        let alignment = kind.and_then(|kind| {
            align(
                kind,
                candidates.iter().zip(&monos).filter_map(|(c, m)| {
                    let m = m.as_ref().filter(|m| is_anchor(m))?;
                    let (sample, _) = c.relative.filter(|(_, k)| *k == kind)?;
                    Some((sample, m.near_z()))
                }),
            )
        });
        let k = self.camera.intrinsics;
        let max_depth = self.ground.max_depth_m;
        for ((c, mono), track_id) in candidates.into_iter().zip(monos).zip(ids) {
            let offset = centre_offset_m(&self.mono, c.type_name.as_deref());
            // A map's near-surface depth placed as the monocular estimate
            // places its own: the footprint centre `offset` behind the near
            // face, on the ground seen at the box's bottom row.
            let place = |near: f64| {
                let z = near + offset;
                if !(near > 0.0 && z.is_finite() && z <= max_depth) {
                    return None;
                }
                let (u, v) = (c.bbox.center_x(), c.bbox.bottom);
                let ground_y = k.back_project(u, v, near)[1];
                let [x, _, z] = k.back_project(u, v, z);
                Some([x, ground_y, z])
            };
            let from_map = c
                .depth_m
                .and_then(place)
                .map(|p| (p, DepthSource::DepthMap));
            let from_relative = || {
                let (sample, _) = c.relative?;
                let p = place(alignment?.depth(sample)?)?;
                Some((p, DepthSource::RelativeAligned))
            };
            let (position, depth_source) = from_map
                .or_else(from_relative)
                .or(mono.map(|e| (e.position, e.source)))
                .unzip();
            self.observations.push(Observation {
                frame,
                track_id,
                class: c.class,
                type_name: c.type_name,
                color: c.color.map(str::to_string),
                bbox: c.bbox,
                position,
                size: None,
                yaw: None,
                confidence: c.score.clamp(0.0, 1.0),
                truncation: None,
                occlusion: None,
                footprint: None,
                depth_source,
            });
        }
    }

    fn finish(
        mut self,
        name: String,
        source: &str,
        frame_count: u32,
        fps: f64,
    ) -> Result<Sequence, RawError> {
        // One colour per object: the most frequent per-frame name (ties to
        // the earlier value), so a shadowed frame does not recolour a car.
        let mut votes: std::collections::BTreeMap<u32, std::collections::BTreeMap<String, usize>> =
            Default::default();
        for o in &self.observations {
            if let Some(c) = &o.color {
                *votes
                    .entry(o.track_id)
                    .or_default()
                    .entry(c.clone())
                    .or_default() += 1;
            }
        }
        let winner = |id: u32| -> Option<String> {
            votes.get(&id).and_then(|v| {
                v.iter()
                    .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(a.0)))
                    .map(|(c, _)| c.clone())
            })
        };
        for o in &mut self.observations {
            o.color = winner(o.track_id);
        }
        let mut seq = Sequence {
            name,
            source: source.to_string(),
            camera: self.camera,
            frame_count,
            fps,
            observations: self.observations,
        };
        seq.sort();
        seq.validate()?;
        Ok(seq)
    }
}

/// Raw camera frames through the configured models.
pub struct FramesSource;

impl FramesSource {
    /// Runs the models file's detector (and optional depth / flow models) over
    /// every frame of `dir` and returns the tracked sequence (source
    /// `"frames"`). `progress` is called after every frame.
    pub fn open(
        dir: &Path,
        models: &Path,
        options: &FramesOptions,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Sequence, RawError> {
        let set = ModelSet::load(models)?;
        let runtime = Runtime::discover()?;
        FramesSource::run(&runtime, dir, set, options, progress)
    }

    /// [`FramesSource::open`] with an already loaded runtime and model set.
    pub fn run(
        runtime: &Runtime,
        dir: &Path,
        set: ModelSet,
        options: &FramesOptions,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Sequence, RawError> {
        FramesPipeline::open(runtime, set)?.run(dir, options, progress)
    }
}

/// The opened models of a frames run; reusable across directories so
/// sessions are created once.
#[derive(Debug)]
pub struct FramesPipeline {
    detector: Detector,
    /// The depth model and how its map is read (both or neither).
    depth: Option<(DenseModel, DepthUse)>,
    flow: Option<DenseModel>,
}

impl FramesPipeline {
    /// Opens every model of the set.
    pub fn open(runtime: &Runtime, set: ModelSet) -> Result<FramesPipeline, RawError> {
        set.check_kinds()?;
        let depth = set
            .depth
            .map(|d| {
                let depth_use = DepthUse::of(&d.config.output);
                DenseModel::open(runtime, d).map(|m| (m, depth_use))
            })
            .transpose()?;
        Ok(FramesPipeline {
            detector: Detector::open(runtime, set.detector)?,
            depth,
            flow: set.flow.map(|f| DenseModel::open(runtime, f)).transpose()?,
        })
    }

    /// Runs over every frame of `dir` (see [`FramesSource::open`]). With
    /// [`FramesOptions::prefetch`], a second thread decodes and resamples
    /// frame `i + 1` while the models run on frame `i`.
    pub fn run(
        &mut self,
        dir: &Path,
        options: &FramesOptions,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Sequence, RawError> {
        let files = list_frames(dir)?;
        let total = checked_frame_count(dir, files.len())?;
        let mut state = RunState {
            times: StageTimes::default(),
            assembler: None,
            size: None,
            previous: None,
        };
        if options.prefetch {
            let preparer = self.detector.preparer();
            std::thread::scope(|scope| -> Result<(), RawError> {
                // Bounded: the loader stays at most one frame ahead.
                let (frames_tx, frames_rx) =
                    std::sync::mpsc::sync_channel::<Result<Loaded, RawError>>(1);
                let (recycle_tx, recycle_rx) = std::sync::mpsc::channel::<Vec<Array4<f32>>>();
                let files = &files;
                scope.spawn(move || {
                    for path in files {
                        let recycled = recycle_rx.try_recv().unwrap_or_default();
                        let loaded = load_frame(path, Some((&preparer, recycled)));
                        let failed = loaded.is_err();
                        // A closed channel means the consumer stopped (an
                        // error of its own): nothing more to do.
                        if frames_tx.send(loaded).is_err() || failed {
                            break;
                        }
                    }
                });
                for (i, path) in files.iter().enumerate() {
                    let loaded = frames_rx.recv().map_err(|_| RawError::Frames {
                        path: path.clone(),
                        message: "frame loader stopped".into(),
                    })??;
                    let recycled = self.frame(&mut state, i as u32, path, loaded, options)?;
                    // The loader may have finished; then the tensors are dropped.
                    let _ = recycle_tx.send(recycled);
                    progress(Progress {
                        done: i as u32 + 1,
                        total,
                        times: state.times,
                    });
                }
                Ok(())
            })?;
        } else {
            for (i, path) in files.iter().enumerate() {
                let loaded = load_frame(path, None)?;
                let _ = self.frame(&mut state, i as u32, path, loaded, options)?;
                progress(Progress {
                    done: i as u32 + 1,
                    total,
                    times: state.times,
                });
            }
        }
        let assembler = state.assembler;
        let name = options.name.clone().unwrap_or_else(|| {
            dir.file_name()
                .and_then(|n| n.to_str())
                .unwrap_or("frames")
                .to_string()
        });
        let Some(asm) = assembler else {
            return Err(RawError::Frames {
                path: dir.to_path_buf(),
                message: "no frames".into(),
            });
        };
        asm.finish(name, "frames", total, options.fps)
    }

    /// One loaded frame through the models, 3D, colour and the tracker;
    /// returns the detector tensors for reuse.
    fn frame(
        &mut self,
        state: &mut RunState,
        frame: u32,
        path: &Path,
        loaded: Loaded,
        options: &FramesOptions,
    ) -> Result<Vec<Array4<f32>>, RawError> {
        let Loaded {
            image: img,
            prepared,
            time,
        } = loaded;
        match state.size {
            None => state.size = Some(img.dimensions()),
            Some(s) if s != img.dimensions() => {
                return Err(RawError::Frames {
                    path: path.to_path_buf(),
                    message: format!("frame is {:?}, earlier frames are {s:?}", img.dimensions()),
                });
            }
            Some(_) => {}
        }
        let times = &mut state.times;
        let (dets, recycled) = match prepared {
            Some(mut p) => {
                times.prefetch += time;
                let (dets, t) = self.detector.detect_prepared(&mut p)?;
                times.add(t);
                (dets, p.tensors)
            }
            None => {
                times.other += time;
                let (dets, t) = self.detector.detect(&img)?;
                times.add(t);
                (dets, Vec::new())
            }
        };
        let depth_map = match self.depth.as_mut() {
            Some((m, depth_use)) => match timed(times, || m.run(&img, None))? {
                DenseOutput::Depth(d) => Some((d, *depth_use)),
                _ => None,
            },
            None => None,
        };
        let flow = match (self.flow.as_mut(), state.previous.as_ref()) {
            (Some(m), Some(prev)) => match timed(times, || m.run(&img, Some(prev)))? {
                DenseOutput::Flow(f) => Some(f),
                _ => None,
            },
            _ => None,
        };
        let start = std::time::Instant::now();
        let asm = match &mut state.assembler {
            Some(asm) => asm,
            // The first frame fixes the image size the calibration must fit.
            slot @ None => {
                let camera = match &options.camera {
                    Some(c) => c.for_frames(img.width(), img.height(), path)?,
                    None => assumed_camera(img.width(), img.height()),
                };
                slot.insert(Assembler::new(camera, options))
            }
        };
        let candidates = dets
            .into_iter()
            .map(|d| {
                // The same sample for both kinds of map; only its reading differs.
                let sample = depth_map
                    .as_ref()
                    .and_then(|(m, u)| Some((box_depth(m, &d.bbox)?, *u)));
                let (depth_m, relative) = match sample {
                    Some((v, DepthUse::Metric)) => (Some(v), None),
                    Some((v, DepthUse::Relative(kind))) => (None, Some((v, kind))),
                    None => (None, None),
                };
                Candidate {
                    class: d.class,
                    type_name: d.type_name,
                    color: name_box(&img, &d.bbox, &options.color),
                    depth_m,
                    relative,
                    bbox: d.bbox,
                    score: d.score,
                }
            })
            .collect();
        asm.frame(frame, candidates, flow.as_ref());
        times.other += start.elapsed();
        state.previous = Some(img);
        Ok(recycled)
    }
}

/// What [`FramesPipeline::run`] carries from frame to frame.
struct RunState {
    times: StageTimes,
    assembler: Option<Assembler>,
    size: Option<(u32, u32)>,
    previous: Option<RgbImage>,
}

/// A decoded frame, resampled for the detector when prefetched.
struct Loaded {
    image: RgbImage,
    prepared: Option<PreparedFrame>,
    /// Time spent decoding (and resampling).
    time: std::time::Duration,
}

/// Decodes an image file into RGB (no copy when it already is 8-bit RGB)
/// and, given a preparer, resamples it into the detector's tensors.
fn load_frame(
    path: &Path,
    prepare: Option<(&Preparer, Vec<Array4<f32>>)>,
) -> Result<Loaded, RawError> {
    let start = std::time::Instant::now();
    let image = image::open(path)
        .map_err(|e| RawError::Image {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?
        .into_rgb8();
    let prepared = prepare.map(|(p, recycled)| p.prepare(&image, recycled));
    Ok(Loaded {
        image,
        prepared,
        time: start.elapsed(),
    })
}

fn timed<T>(
    times: &mut StageTimes,
    f: impl FnOnce() -> Result<T, RawError>,
) -> Result<T, RawError> {
    let start = std::time::Instant::now();
    let out = f();
    times.model += start.elapsed();
    out
}

/// Median known depth over the lower half of a box (the object rather than
/// what is behind its upper corners).
fn box_depth(m: &DenseMap<f32>, b: &BBox2D) -> Option<f64> {
    let x0 = b.left.max(0.0) as usize;
    let x1 = (b.right.max(0.0) as usize).min(m.width);
    let y0 = (0.5 * (b.top + b.bottom)).max(0.0) as usize;
    let y1 = (b.bottom.max(0.0) as usize).min(m.height);
    let mut v: Vec<f32> = Vec::new();
    for y in y0..y1 {
        for x in x0..x1 {
            if let Some(d) = m.get(x, y, 0).filter(|d| d.is_finite() && *d > 0.0) {
                v.push(d);
            }
        }
    }
    v.sort_by(f32::total_cmp);
    v.get(v.len() / 2).map(|d| f64::from(*d))
}

/// Dense maps (from files or a renderer) into a tracked sequence: instances
/// per frame → tracker (guided by each frame's flow) → 3D from the depth map
/// when present (nearest surface of the instance plus the type's centre
/// offset), else the monocular estimate ([`FramesOptions::mono`]). Static
/// classes (road, buildings, …) are scene structure, not tracked objects.
pub fn sequence_from_dense(
    name: &str,
    source: &str,
    camera: CameraConfig,
    frames: &[DenseFrame],
    classes: &ClassTable,
    options: &FramesOptions,
) -> Result<Sequence, RawError> {
    let count = checked_frame_count(Path::new(name), frames.len())?;
    let mut asm = Assembler::new(camera, options);
    let mut prev_flow: Option<&DenseMap<f32>> = None;
    for (frame, f) in (0u32..).zip(frames) {
        let found = instances(f, classes, &options.instances)?;
        let candidates = found
            .into_iter()
            .filter(|inst| !inst.class.is_static())
            .map(|inst| Candidate {
                class: inst.class,
                type_name: inst.type_name,
                bbox: inst.bbox,
                score: 1.0,
                color: None,
                depth_m: inst.nearest_depth_m,
                relative: None,
            })
            .collect();
        asm.frame(frame, candidates, prev_flow);
        prev_flow = f.flow.as_ref();
    }
    asm.finish(name.to_string(), source, count, options.fps)
}

/// Reads a directory of dense maps written by
/// [`DenseFrame::write_pngs`] (`<stem>_semantic.png`, optional `_instance`,
/// `_depth`, `_flow`), frames ordered by stem.
pub fn read_dense_dir(dir: &Path) -> Result<Vec<DenseFrame>, RawError> {
    let rd = std::fs::read_dir(dir).map_err(|e| RawError::io(dir, e))?;
    let mut stems: Vec<String> = Vec::new();
    for entry in rd {
        let name = entry.map_err(|e| RawError::io(dir, e))?.file_name();
        if let Some(stem) = name.to_str().and_then(|n| n.strip_suffix("_semantic.png")) {
            stems.push(stem.to_string());
        }
    }
    stems.sort();
    if stems.is_empty() {
        return Err(RawError::Frames {
            path: dir.to_path_buf(),
            message: "no *_semantic.png maps".into(),
        });
    }
    stems
        .iter()
        .map(|s| {
            let opt =
                |kind: &str| Some(dir.join(format!("{s}_{kind}.png"))).filter(|p| p.is_file());
            DenseFrame::from_pngs(
                opt("semantic").as_deref(),
                opt("instance").as_deref(),
                opt("depth").as_deref(),
                opt("flow").as_deref(),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::mono::test_support::car_box;
    use super::super::mono::{KITTI_CAR, MonoDepthMethod};
    use super::*;

    fn kitti() -> CameraConfig {
        crate::kitti::KITTI_2011_09_26_CAMERA
    }

    fn car(bbox: BBox2D, depth_m: Option<f64>) -> Candidate {
        Candidate {
            class: ObjectClass::Vehicle,
            type_name: Some("Car".into()),
            bbox,
            score: 0.9,
            color: None,
            depth_m,
            relative: None,
        }
    }

    fn with_relative(c: Candidate, sample: f64, kind: RelativeDepth) -> Candidate {
        Candidate {
            relative: Some((sample, kind)),
            ..c
        }
    }

    fn z_of(o: &Observation) -> f64 {
        o.position.map_or(f64::NAN, |p| p[2])
    }

    #[test]
    fn a_model_of_the_wrong_kind_in_a_set_slot_is_an_error() {
        let test_models = Path::new(env!("CARGO_MANIFEST_DIR")).join("models/test");
        let dir = std::env::temp_dir().join(format!("pframes_set_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let write = |name: &str, text: String| {
            let p = dir.join(name);
            std::fs::write(&p, text).unwrap();
            p
        };
        let m = |f: &str| test_models.join(f).display().to_string();
        let good = write(
            "good.yaml",
            format!(
                "detector: {}\ndepth: {}\nflow: {}\n",
                m("tiny_gfl.yaml"),
                m("tiny_depth.yaml"),
                m("tiny_flow.yaml")
            ),
        );
        let set = ModelSet::load(&good).unwrap();
        assert!(set.depth.is_some() && set.flow.is_some());
        for (slot, wrong) in [("flow", "tiny_seg.yaml"), ("depth", "tiny_flow.yaml")] {
            let bad = write(
                "bad.yaml",
                format!("detector: {}\n{slot}: {}\n", m("tiny_gfl.yaml"), m(wrong)),
            );
            let err = ModelSet::load(&bad).unwrap_err().to_string();
            assert!(
                err.contains(&format!("`{slot}:` needs a `{slot}` model")) && err.contains(wrong),
                "{err}"
            );
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_depth_map_overrides_the_monocular_estimate_and_each_position_names_its_method() {
        let bbox = BBox2D {
            left: 500.0,
            top: 180.0,
            right: 600.0,
            bottom: 260.0,
        };
        let mut asm = Assembler::new(kitti(), &FramesOptions::default());
        asm.frame(
            0,
            vec![
                car(bbox, Some(23.0)),
                car(
                    BBox2D {
                        left: 800.0,
                        right: 900.0,
                        ..bbox
                    },
                    None,
                ),
            ],
            None,
        );
        let [with_map, without] = [&asm.observations[0], &asm.observations[1]];
        assert_eq!(with_map.depth_source, Some(DepthSource::DepthMap));
        // The map sees the near face; the position is the footprint centre.
        let want = 23.0 + KITTI_CAR.half_depth_extent_m();
        assert!((z_of(with_map) - want).abs() < 1e-9, "{with_map:?}");
        assert_eq!(without.depth_source, Some(DepthSource::Fused));
        let z = without.position.map(|p| p[2]).unwrap_or(f64::NAN);
        assert!(z > 5.0 && z < 20.0, "{z}");
        // The configured method is the one used.
        let flat = FramesOptions {
            mono: MonoDepthConfig::default()
                .with_method(super::super::mono::MonoDepthMethod::FlatGround),
            ..FramesOptions::default()
        };
        let mut asm = Assembler::new(kitti(), &flat);
        asm.frame(0, vec![car(bbox, None)], None);
        assert_eq!(
            asm.observations[0].depth_source,
            Some(DepthSource::FlatGround)
        );
    }

    #[test]
    fn relative_depth_is_scaled_per_frame_onto_the_monocular_near_faces() {
        let camera = kitti();
        let options = FramesOptions::default();
        let boxes = [
            BBox2D {
                left: 500.0,
                top: 180.0,
                right: 600.0,
                bottom: 260.0,
            },
            BBox2D {
                left: 800.0,
                top: 170.0,
                right: 860.0,
                bottom: 215.0,
            },
            BBox2D {
                left: 200.0,
                top: 175.0,
                right: 280.0,
                bottom: 235.0,
            },
            // Bottom above the horizon (cy 172.9) and top cut by the image:
            // no monocular estimate, but the relative map still places it.
            BBox2D {
                left: 1000.0,
                top: 0.0,
                right: 1040.0,
                bottom: 150.0,
            },
        ];
        let mono: Vec<Option<f64>> = boxes
            .iter()
            .map(|b| {
                estimate(b, Some("Car"), &camera, &options.ground, &options.mono)
                    .map(|e| e.near_z())
            })
            .collect();
        assert!(
            mono[..3].iter().all(Option::is_some) && mono[3].is_none(),
            "{mono:?}"
        );
        // Relative values with other ratios than the monocular depths.
        let relative = [2.0, 5.0, 3.0, 9.0];
        let mut ratios: Vec<f64> = (0..3)
            .map(|i| mono[i].unwrap_or(f64::NAN) / relative[i])
            .collect();
        ratios.sort_by(f64::total_cmp);
        let scale = ratios[1];
        let mut asm = Assembler::new(camera, &options);
        let candidates = boxes
            .iter()
            .zip(relative)
            .map(|(b, r)| with_relative(car(*b, None), r, RelativeDepth::Depth))
            .collect();
        asm.frame(0, candidates, None);
        for (o, r) in asm.observations.iter().zip(relative) {
            assert_eq!(o.depth_source, Some(DepthSource::RelativeAligned), "{o:?}");
            let want = scale * r + KITTI_CAR.half_depth_extent_m();
            assert!((z_of(o) - want).abs() < 1e-9, "{} vs {want}", z_of(o));
        }
        // A metric depth still wins over an aligned relative one.
        let mut asm = Assembler::new(camera, &options);
        asm.frame(
            0,
            vec![
                with_relative(car(boxes[0], Some(23.0)), 2.0, RelativeDepth::Depth),
                with_relative(car(boxes[1], None), 5.0, RelativeDepth::Depth),
            ],
            None,
        );
        assert_eq!(
            asm.observations[0].depth_source,
            Some(DepthSource::DepthMap)
        );
        assert_eq!(
            asm.observations[1].depth_source,
            Some(DepthSource::RelativeAligned)
        );
    }

    #[test]
    fn a_frame_without_an_alignable_box_keeps_the_monocular_estimates() {
        let camera = kitti();
        let options = FramesOptions::default();
        // Cut by the image's bottom edge (375 rows): its flat-ground depth is
        // an overestimate and is not used to align.
        let cut = BBox2D {
            left: 500.0,
            top: 200.0,
            right: 700.0,
            bottom: 374.0,
        };
        let above = BBox2D {
            left: 1000.0,
            top: 0.0,
            right: 1040.0,
            bottom: 150.0,
        };
        let mut asm = Assembler::new(camera, &options);
        asm.frame(
            0,
            vec![
                with_relative(car(cut, None), 2.0, RelativeDepth::Depth),
                with_relative(car(above, None), 4.0, RelativeDepth::Depth),
            ],
            None,
        );
        let mono = estimate(&cut, Some("Car"), &camera, &options.ground, &options.mono);
        assert!(mono.is_some_and(|m| m.cut_by_image), "{mono:?}");
        assert_eq!(asm.observations[0].depth_source, mono.map(|m| m.source));
        assert_eq!(asm.observations[0].position, mono.map(|m| m.position));
        assert_eq!(asm.observations[1].depth_source, None);
        assert_eq!(asm.observations[1].position, None);
    }

    /// Road-aligned KITTI-sized cars with footprint centres at `zs` (x
    /// spread across the image), their boxes, and exact monocular estimates.
    fn cars_at(zs: &[f64]) -> Vec<(f64, BBox2D)> {
        let camera = kitti();
        zs.iter()
            .enumerate()
            .map(|(i, &z)| {
                let x = -4.0 + 3.0 * i as f64;
                (z, car_box(&camera, &KITTI_CAR, x, camera.height_m, z))
            })
            .collect()
    }

    #[test]
    fn a_map_of_the_near_face_gives_the_footprint_centre_back() {
        // Regression: alignment compared mono's footprint centres with the
        // map's near-surface samples, a distance-dependent bias (−15% at
        // 8 m to +6% at 40 m here), and a metric map's surface depth was
        // used as the centre.
        let camera = kitti();
        let options = FramesOptions::default();
        let cars = cars_at(&[8.0, 15.0, 25.0, 40.0]);
        let half = KITTI_CAR.half_depth_extent_m();
        for (z, b) in &cars {
            let e = estimate(b, Some("Car"), &camera, &options.ground, &options.mono);
            assert!(e.is_some_and(|e| (e.z() - z).abs() < 1e-6), "{e:?}");
        }
        // Each map's value for a near-face depth.
        let maps: [(&str, MapOf); 3] = [
            ("depth", |near| {
                with_relative(car(BBOX0, None), near / 7.0, RelativeDepth::Depth)
            }),
            ("inverse depth", |near| {
                with_relative(car(BBOX0, None), 7.0 / near, RelativeDepth::InverseDepth)
            }),
            ("metric", |near| car(BBOX0, Some(near))),
        ];
        for (name, make) in maps {
            let mut asm = Assembler::new(camera, &options);
            let candidates = cars
                .iter()
                .map(|(z, b)| Candidate {
                    bbox: *b,
                    ..make(z - half)
                })
                .collect();
            asm.frame(0, candidates, None);
            for ((z, _), o) in cars.iter().zip(&asm.observations) {
                assert_ne!(o.depth_source, Some(DepthSource::Fused), "{name}: {o:?}");
                assert!((z_of(o) - z).abs() < 1e-6, "{name}: {} vs {z}", z_of(o));
                // On the ground seen under the box, like the mono estimate.
                let y = o.position.map_or(f64::NAN, |p| p[1]);
                assert!((y - camera.height_m).abs() < 1e-6, "{name}: {o:?}");
            }
        }
    }

    /// A candidate carrying a map's value for a near-face depth.
    type MapOf = fn(f64) -> Candidate;

    /// A placeholder box, replaced by each test.
    const BBOX0: BBox2D = BBox2D {
        left: 0.0,
        top: 0.0,
        right: 1.0,
        bottom: 1.0,
    };

    #[test]
    fn a_shifted_inverse_depth_map_is_fitted_in_the_frame() {
        let camera = kitti();
        let options = FramesOptions::default();
        let cars = cars_at(&[7.0, 10.0, 12.0, 16.0, 20.0, 30.0, 45.0]);
        let half = KITTI_CAR.half_depth_extent_m();
        for shift in [0.05, 0.2] {
            let mut asm = Assembler::new(camera, &options);
            let candidates = cars
                .iter()
                .map(|(z, b)| {
                    with_relative(
                        car(*b, None),
                        7.0 / (z - half) + shift,
                        RelativeDepth::InverseDepth,
                    )
                })
                .collect();
            asm.frame(0, candidates, None);
            for ((z, _), o) in cars.iter().zip(&asm.observations) {
                assert_eq!(o.depth_source, Some(DepthSource::RelativeAligned));
                assert!(
                    (z_of(o) / z - 1.0).abs() < 0.01,
                    "{shift}: {} vs {z}",
                    z_of(o)
                );
            }
        }
    }

    #[test]
    fn only_ground_contacts_and_size_priors_anchor_the_alignment() {
        let camera = kitti();
        let options = FramesOptions::default();
        let cars = cars_at(&[10.0]);
        let (z, b) = cars[0];
        let half = KITTI_CAR.half_depth_extent_m();
        // A traffic sign: flat ground without a prior puts its box bottom
        // (well above the ground) far away; it must not pull the scale.
        let sign_box = BBox2D {
            left: 900.0,
            top: 190.0,
            right: 930.0,
            bottom: 200.0,
        };
        let sign = Candidate {
            class: ObjectClass::TrafficSign,
            type_name: None,
            ..car(sign_box, None)
        };
        let sign_mono = estimate(&sign_box, None, &camera, &options.ground, &options.mono);
        assert!(
            sign_mono.is_some_and(|m| m.source == DepthSource::FlatGround && m.z() > 40.0),
            "{sign_mono:?}"
        );
        let mut asm = Assembler::new(camera, &options);
        asm.frame(
            0,
            vec![
                with_relative(car(b, None), (z - half) / 7.0, RelativeDepth::Depth),
                // The sign is in truth 12 m away.
                with_relative(sign, 12.0 / 7.0, RelativeDepth::Depth),
            ],
            None,
        );
        let [c, s] = [&asm.observations[0], &asm.observations[1]];
        assert!((z_of(c) - z).abs() < 1e-6, "{c:?}");
        assert_eq!(s.depth_source, Some(DepthSource::RelativeAligned));
        assert!((z_of(s) - 12.0).abs() < 1e-6, "{s:?}");
    }

    #[test]
    fn a_map_depth_beyond_the_cap_falls_back_to_the_monocular_estimate() {
        let camera = kitti();
        let options = FramesOptions::default();
        let cars = cars_at(&[10.0, 20.0, 30.0, 40.0, 50.0]);
        let half = KITTI_CAR.half_depth_extent_m();
        let mut candidates: Vec<Candidate> = cars
            .iter()
            .map(|(z, b)| {
                with_relative(car(*b, None), 7.0 / (z - half), RelativeDepth::InverseDepth)
            })
            .collect();
        // Sky inside one box: an inverse depth near zero, 70 km. The robust
        // fit follows the other four.
        candidates[2].relative = Some((1e-4, RelativeDepth::InverseDepth));
        let mut asm = Assembler::new(camera, &options);
        asm.frame(0, candidates, None);
        let sky = &asm.observations[2];
        assert_eq!(sky.depth_source, Some(DepthSource::Fused), "{sky:?}");
        assert!((z_of(sky) - 30.0).abs() < 1e-6, "{sky:?}");
        // The other boxes still take their depth from the map.
        for (k, o) in asm.observations.iter().enumerate().filter(|(k, _)| *k != 2) {
            assert_eq!(o.depth_source, Some(DepthSource::RelativeAligned), "{o:?}");
            assert!((z_of(o) / cars[k].0 - 1.0).abs() < 0.01, "{o:?}");
        }
        // The same cap for a metric map.
        let mut asm = Assembler::new(camera, &options);
        asm.frame(0, vec![car(cars[0].1, Some(500.0))], None);
        assert_eq!(asm.observations[0].depth_source, Some(DepthSource::Fused));
        let flat = FramesOptions {
            mono: MonoDepthConfig::default().with_method(MonoDepthMethod::FlatGround),
            ..FramesOptions::default()
        };
        let mut asm = Assembler::new(camera, &flat);
        asm.frame(0, vec![car(cars[0].1, Some(f64::INFINITY))], None);
        assert_eq!(
            asm.observations[0].depth_source,
            Some(DepthSource::FlatGround)
        );
    }

    #[test]
    fn a_frame_count_beyond_max_frames_is_refused_naming_the_directory() {
        let dir = Path::new("/data/frames");
        assert_eq!(checked_frame_count(dir, 3).ok(), Some(3));
        let max = MAX_FRAMES as usize;
        assert_eq!(checked_frame_count(dir, max).ok(), Some(MAX_FRAMES));
        for n in [max + 1, usize::MAX] {
            let err = checked_frame_count(dir, n)
                .map_or_else(|e| e.to_string(), |c| format!("accepted {c}"));
            assert!(
                err.starts_with("/data/frames: ")
                    && err.contains(&format!("`frames` {n} exceeds the limit of 1000000")),
                "{err}"
            );
        }
    }
}
