//! Raw frames through the models: a loader thread decodes and resamples
//! the next frame while the detector, depth and flow models run on the
//! current one; the results go to the [`super::assemble`] stage.

use std::path::Path;

use image::RgbImage;
use ndarray::Array4;

use super::assemble::{Assembler, Candidate, DepthUse};
use super::input::{checked_frame_count, list_frames};
use super::modelset::ModelSet;
use super::options::{FramesOptions, Progress, assumed_camera};
use crate::model::{BBox2D, Sequence};
use crate::raw::RawError;
use crate::raw::color::name_box;
use crate::raw::decode::DenseMap;
use crate::raw::dense::{DenseModel, DenseOutput};
use crate::raw::detect::{Detector, PreparedFrame, Preparer, StageTimes};
use crate::raw::runtime::Runtime;

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
                    message: format!(
                        "frame is {}×{} pixels, earlier frames are {}×{}",
                        img.width(),
                        img.height(),
                        s.0,
                        s.1
                    ),
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
    let image = super::input::open_image(path)?.into_rgb8();
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
