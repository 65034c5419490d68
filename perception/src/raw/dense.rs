//! The dense path: per-pixel maps (semantic, instance, depth, flow) from a
//! model or from PNG files, turned into object instances that go through the
//! same tracker as detections.
//!
//! PNG conventions (those of KITTI and Cityscapes-style exports):
//! - semantic: 8- or 16-bit grey, the value is the class id of the label map;
//! - instance: 16-bit grey, 0 = no instance, otherwise an instance id;
//! - depth: 16-bit grey, metres × 256, 0 = unknown (KITTI depth);
//! - flow: 16-bit RGB, `dx = (R − 2¹⁵) / 64`, `dy = (G − 2¹⁵) / 64`, `B` = 1
//!   where valid (KITTI flow).

use std::collections::BTreeMap;
use std::path::Path;

use image::{ImageBuffer, Luma, Rgb, RgbImage};

use super::RawError;
use super::config::{LoadedConfig, OutputSpec, ResizeMode};
use super::decode::{self, DenseMap};
use super::detect::open_model;
use super::preprocess;
use super::runtime::{ModelRunner, Runtime};
use crate::model::{BBox2D, ObjectClass};

/// The maps known for one frame, all of the frame's size.
///
/// Invariant: every present map is `width × height` (flow has 2 channels,
/// the others 1).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct DenseFrame {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Class id per pixel.
    pub semantic: Option<DenseMap<u16>>,
    /// Instance id per pixel (0 = none).
    pub instance: Option<DenseMap<u32>>,
    /// Depth in metres along the optical axis (0 or non-finite = unknown).
    pub depth: Option<DenseMap<f32>>,
    /// Forward flow `(dx, dy)` in pixels into the next frame.
    pub flow: Option<DenseMap<f32>>,
}

impl DenseFrame {
    /// Checks that every map has the frame's size; `origin` names the source in
    /// the error.
    pub fn validate(&self, origin: &Path) -> Result<(), RawError> {
        let check = |name: &str, w: usize, h: usize, c: usize, want_c: usize, len: usize| {
            if w != self.width || h != self.height || c != want_c || len != w * h * c {
                Err(RawError::Frames {
                    path: origin.to_path_buf(),
                    message: format!(
                        "{name} map is {w}x{h}x{c} ({len} values), the frame is {}x{}x{want_c}",
                        self.width, self.height
                    ),
                })
            } else {
                Ok(())
            }
        };
        if let Some(m) = &self.semantic {
            check("semantic", m.width, m.height, m.channels, 1, m.data.len())?;
        }
        if let Some(m) = &self.instance {
            check("instance", m.width, m.height, m.channels, 1, m.data.len())?;
        }
        if let Some(m) = &self.depth {
            check("depth", m.width, m.height, m.channels, 1, m.data.len())?;
        }
        if let Some(m) = &self.flow {
            check("flow", m.width, m.height, m.channels, 2, m.data.len())?;
        }
        Ok(())
    }
}

fn open_image(path: &Path) -> Result<image::DynamicImage, RawError> {
    crate::raw::frames::open_image(path)
}

/// A grey PNG as a one-channel map, each 16-bit value passed through `f`.
fn grey_map<T>(img: image::DynamicImage, f: impl Fn(u16) -> T) -> DenseMap<T> {
    let img = img.to_luma16();
    let (w, h) = img.dimensions();
    DenseMap {
        width: w as usize,
        height: h as usize,
        channels: 1,
        data: img.into_raw().into_iter().map(f).collect(),
    }
}

/// Reads a semantic PNG (8- or 16-bit grey class ids).
pub fn read_semantic_png(path: &Path) -> Result<DenseMap<u16>, RawError> {
    let img = open_image(path)?;
    // to_luma16 scales 8-bit values by 257; undo it for 8-bit sources.
    let eight_bit = img.color() == image::ColorType::L8;
    Ok(grey_map(img, |v| if eight_bit { v / 257 } else { v }))
}

/// Reads an instance PNG (16-bit grey ids, 0 = none).
pub fn read_instance_png(path: &Path) -> Result<DenseMap<u32>, RawError> {
    Ok(grey_map(open_image(path)?, u32::from))
}

/// Reads a depth PNG (16-bit, metres × 256, 0 = unknown).
pub fn read_depth_png(path: &Path) -> Result<DenseMap<f32>, RawError> {
    Ok(grey_map(open_image(path)?, |v| f32::from(v) / 256.0))
}

/// Reads a KITTI flow PNG (16-bit RGB); invalid pixels get zero flow.
pub fn read_flow_png(path: &Path) -> Result<DenseMap<f32>, RawError> {
    let img = open_image(path)?.to_rgb16();
    let (w, h) = img.dimensions();
    let mut data = Vec::with_capacity(w as usize * h as usize * 2);
    for p in img.pixels() {
        let valid = p.0[2] > 0;
        let d = |v: u16| {
            if valid {
                (f32::from(v) - 32768.0) / 64.0
            } else {
                0.0
            }
        };
        data.push(d(p.0[0]));
        data.push(d(p.0[1]));
    }
    Ok(DenseMap {
        width: w as usize,
        height: h as usize,
        channels: 2,
        data,
    })
}

fn save<P: image::Pixel<Subpixel = u16> + image::PixelWithColorType>(
    img: &ImageBuffer<P, Vec<u16>>,
    path: &Path,
) -> Result<(), RawError>
where
    [P::Subpixel]: image::EncodableLayout,
{
    img.save(path).map_err(|e| RawError::Image {
        path: path.to_path_buf(),
        message: e.to_string(),
    })
}

fn dims(width: usize, height: usize, path: &Path) -> Result<(u32, u32), RawError> {
    match (u32::try_from(width), u32::try_from(height)) {
        (Ok(w), Ok(h)) => Ok((w, h)),
        _ => Err(RawError::Frames {
            path: path.to_path_buf(),
            message: "map too large for PNG".into(),
        }),
    }
}

impl DenseFrame {
    /// Reads whichever maps are given; all must have the same size.
    pub fn from_pngs(
        semantic: Option<&Path>,
        instance: Option<&Path>,
        depth: Option<&Path>,
        flow: Option<&Path>,
    ) -> Result<DenseFrame, RawError> {
        let mut f = DenseFrame {
            semantic: semantic.map(read_semantic_png).transpose()?,
            instance: instance.map(read_instance_png).transpose()?,
            depth: depth.map(read_depth_png).transpose()?,
            flow: flow.map(read_flow_png).transpose()?,
            ..DenseFrame::default()
        };
        let size = [
            f.semantic.as_ref().map(|m| (m.width, m.height)),
            f.instance.as_ref().map(|m| (m.width, m.height)),
            f.depth.as_ref().map(|m| (m.width, m.height)),
            f.flow.as_ref().map(|m| (m.width, m.height)),
        ]
        .into_iter()
        .flatten()
        .next();
        let origin = semantic
            .or(instance)
            .or(depth)
            .or(flow)
            .unwrap_or(Path::new("<no maps>"));
        let Some((w, h)) = size else {
            return Err(RawError::Frames {
                path: origin.to_path_buf(),
                message: "no dense map given".into(),
            });
        };
        f.width = w;
        f.height = h;
        f.validate(origin)?;
        Ok(f)
    }

    /// Writes the present maps as PNGs named `<stem>_semantic.png`,
    /// `_instance.png`, `_depth.png`, `_flow.png` in `dir` (the conventions of
    /// the module docs; depth beyond 255.99 m saturates).
    pub fn write_pngs(&self, dir: &Path, stem: &str) -> Result<(), RawError> {
        std::fs::create_dir_all(dir).map_err(|e| RawError::io(dir, e))?;
        let (w, h) = dims(self.width, self.height, dir)?;
        if let Some(m) = &self.semantic {
            let path = dir.join(format!("{stem}_semantic.png"));
            let img: ImageBuffer<Luma<u16>, Vec<u16>> =
                ImageBuffer::from_raw(w, h, m.data.clone()).ok_or_else(|| size_err(&path))?;
            save(&img, &path)?;
        }
        if let Some(m) = &self.instance {
            let path = dir.join(format!("{stem}_instance.png"));
            let data = m
                .data
                .iter()
                .map(|&v| u16::try_from(v).unwrap_or(u16::MAX))
                .collect();
            let img: ImageBuffer<Luma<u16>, Vec<u16>> =
                ImageBuffer::from_raw(w, h, data).ok_or_else(|| size_err(&path))?;
            save(&img, &path)?;
        }
        if let Some(m) = &self.depth {
            let path = dir.join(format!("{stem}_depth.png"));
            let data = m
                .data
                .iter()
                .map(|&v| {
                    if v.is_finite() && v > 0.0 {
                        (v * 256.0).round().clamp(1.0, 65535.0) as u16
                    } else {
                        0
                    }
                })
                .collect();
            let img: ImageBuffer<Luma<u16>, Vec<u16>> =
                ImageBuffer::from_raw(w, h, data).ok_or_else(|| size_err(&path))?;
            save(&img, &path)?;
        }
        if let Some(m) = &self.flow {
            let path = dir.join(format!("{stem}_flow.png"));
            let enc = |v: f32| (v * 64.0 + 32768.0).round().clamp(0.0, 65535.0) as u16;
            let data = m
                .data
                .chunks_exact(2)
                .flat_map(|p| [enc(p[0]), enc(p[1]), 1])
                .collect();
            let img: ImageBuffer<Rgb<u16>, Vec<u16>> =
                ImageBuffer::from_raw(w, h, data).ok_or_else(|| size_err(&path))?;
            save(&img, &path)?;
        }
        Ok(())
    }
}

fn size_err(path: &Path) -> RawError {
    RawError::Frames {
        path: path.to_path_buf(),
        message: "map data does not match its size".into(),
    }
}

/// Class ids of a dense map onto LogicPad classes (from a config's labels).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClassTable {
    entries: BTreeMap<u16, (ObjectClass, Option<String>)>,
}

impl ClassTable {
    /// Builds the table from a config's label map. The classes need no
    /// check (a [`super::config::LabelClass`] is valid by construction); the
    /// ids can still be too large for a 16-bit class map (a segmentation
    /// model may declare more than 65,536 classes), which is an error naming
    /// the label.
    pub fn from_config(loaded: &LoadedConfig) -> Result<ClassTable, RawError> {
        let mut entries = BTreeMap::new();
        for (i, l) in loaded.config.labels.iter().enumerate() {
            let id = u16::try_from(l.id).map_err(|_| RawError::ConfigInvalid {
                path: loaded.config_path.clone(),
                field: format!("labels[{i}]"),
                message: format!("id {} does not fit a 16-bit class map", l.id),
            })?;
            entries.insert(id, (l.class.class(), l.type_name.clone()));
        }
        Ok(ClassTable { entries })
    }

    /// Adds or replaces one entry.
    pub fn insert(&mut self, id: u16, class: ObjectClass, type_name: Option<String>) {
        self.entries.insert(id, (class, type_name));
    }

    /// The entry for class id `id`.
    pub fn get(&self, id: u16) -> Option<&(ObjectClass, Option<String>)> {
        self.entries.get(&id)
    }
}

/// One object instance found in dense maps.
#[derive(Debug, Clone, PartialEq)]
pub struct DenseInstance {
    /// Class id in the semantic map.
    pub class_id: u16,
    /// LogicPad class.
    pub class: ObjectClass,
    /// `TypeOf` value.
    pub type_name: Option<String>,
    /// Instance id from the instance map, when one was given.
    pub instance_id: Option<u32>,
    /// Tight box around the pixels (pixel edges: `right = max x + 1`).
    pub bbox: BBox2D,
    /// Number of pixels.
    pub pixels: usize,
    /// Median depth of the pixels with known depth, metres.
    pub depth_m: Option<f64>,
    /// Lowest known depth of the pixels (the nearest surface), metres.
    pub nearest_depth_m: Option<f64>,
}

/// Instance extraction settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InstanceConfig {
    /// Components smaller than this are noise and dropped.
    pub min_pixels: usize,
}

impl Default for InstanceConfig {
    fn default() -> Self {
        InstanceConfig { min_pixels: 20 }
    }
}

/// Instances of a frame's maps: with an instance map, one instance per
/// instance id (class by majority vote of its semantic pixels); without, the
/// 4-connected components of every mapped class. Sorted by (class id, first
/// pixel in row-major order), so the order is deterministic.
pub fn instances(
    frame: &DenseFrame,
    classes: &ClassTable,
    config: &InstanceConfig,
) -> Result<Vec<DenseInstance>, RawError> {
    frame.validate(Path::new("<dense frame>"))?;
    let Some(semantic) = &frame.semantic else {
        return Err(RawError::Frames {
            path: "<dense frame>".into(),
            message: "instances need a semantic map (classes)".into(),
        });
    };
    let (w, h) = (frame.width, frame.height);
    let n = w * h;
    // Group pixels into components: label per pixel, usize::MAX = none.
    let mut comp = vec![usize::MAX; n];
    let mut groups: Vec<Vec<usize>> = Vec::new();
    if let Some(inst) = &frame.instance {
        let mut by_id: BTreeMap<u32, usize> = BTreeMap::new();
        for (i, &id) in inst.data.iter().enumerate() {
            if id == 0 {
                continue;
            }
            let g = *by_id.entry(id).or_insert_with(|| {
                groups.push(Vec::new());
                groups.len() - 1
            });
            comp[i] = g;
            if let Some(list) = groups.get_mut(g) {
                list.push(i);
            }
        }
    } else {
        let mut stack = Vec::new();
        for start in 0..n {
            let Some(&label) = semantic.data.get(start) else {
                continue;
            };
            if comp[start] != usize::MAX || classes.get(label).is_none() {
                continue;
            }
            let g = groups.len();
            let mut members = Vec::new();
            comp[start] = g;
            stack.push(start);
            while let Some(p) = stack.pop() {
                members.push(p);
                let (x, y) = (p % w, p / w);
                let neighbours = [
                    (x > 0).then(|| p - 1),
                    (x + 1 < w).then(|| p + 1),
                    (y > 0).then(|| p - w),
                    (y + 1 < h).then(|| p + w),
                ];
                for q in neighbours.into_iter().flatten() {
                    if comp.get(q) == Some(&usize::MAX) && semantic.data.get(q) == Some(&label) {
                        comp[q] = g;
                        stack.push(q);
                    }
                }
            }
            groups.push(members);
        }
    }
    let inst_ids: Option<&DenseMap<u32>> = frame.instance.as_ref();
    let mut out = Vec::new();
    for members in groups {
        if members.len() < config.min_pixels {
            continue;
        }
        let mut votes: BTreeMap<u16, usize> = BTreeMap::new();
        for &p in &members {
            if let Some(&l) = semantic.data.get(p) {
                *votes.entry(l).or_default() += 1;
            }
        }
        let Some((&class_id, _)) = votes
            .iter()
            .filter(|(l, _)| classes.get(**l).is_some())
            .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(a.0)))
        else {
            continue;
        };
        let Some((class, type_name)) = classes.get(class_id).cloned() else {
            continue;
        };
        let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
        let mut depths = Vec::new();
        for &p in &members {
            let (x, y) = (p % w, p / w);
            x0 = x0.min(x);
            y0 = y0.min(y);
            x1 = x1.max(x);
            y1 = y1.max(y);
            if let Some(d) = frame
                .depth
                .as_ref()
                .and_then(|d| d.data.get(p))
                .filter(|d| d.is_finite() && **d > 0.0)
            {
                depths.push(f64::from(*d));
            }
        }
        depths.sort_by(f64::total_cmp);
        let first = members.iter().copied().min().unwrap_or(0);
        out.push((
            (class_id, first),
            DenseInstance {
                class_id,
                class,
                type_name,
                instance_id: inst_ids.and_then(|m| m.data.get(first).copied()),
                bbox: BBox2D {
                    left: x0 as f64,
                    top: y0 as f64,
                    right: (x1 + 1) as f64,
                    bottom: (y1 + 1) as f64,
                },
                pixels: members.len(),
                depth_m: depths.get(depths.len() / 2).copied(),
                nearest_depth_m: depths.first().copied(),
            },
        ));
    }
    out.sort_by_key(|(k, _)| *k);
    Ok(out.into_iter().map(|(_, i)| i).collect())
}

/// What a dense model produced, resampled to the frame's size.
#[derive(Debug, Clone, PartialEq)]
pub enum DenseOutput {
    /// Class id per pixel.
    Semantic(DenseMap<u16>),
    /// Depth in metres (metric) or relative units (relative).
    Depth(DenseMap<f32>),
    /// Forward flow in frame pixels.
    Flow(DenseMap<f32>),
}

/// A segmentation, depth or flow model built from a config.
#[derive(Debug)]
pub struct DenseModel {
    loaded: LoadedConfig,
    runner: ModelRunner,
    tensor: ndarray::Array4<f32>,
}

impl DenseModel {
    /// Opens a dense model; tiles are not supported for dense outputs.
    pub fn open(runtime: &Runtime, loaded: LoadedConfig) -> Result<DenseModel, RawError> {
        let invalid = |field: &str, message: &str| RawError::ConfigInvalid {
            path: loaded.config_path.clone(),
            field: field.into(),
            message: message.into(),
        };
        if matches!(loaded.config.output, OutputSpec::Detector { .. }) {
            return Err(invalid(
                "output.kind",
                "a segmentation, depth or flow config is needed here",
            ));
        }
        if matches!(loaded.config.input.resize, ResizeMode::Tiles { .. }) {
            return Err(invalid(
                "input.resize",
                "dense models take the whole frame (letterbox or stretch)",
            ));
        }
        let runner = open_model(runtime, &loaded)?;
        let tensor = preprocess::new_tensor(&loaded.config.input);
        Ok(DenseModel {
            loaded,
            runner,
            tensor,
        })
    }

    /// Runs on `frame` (and `previous`, for two-frame flow models) and
    /// resamples the output to the frame's size (nearest neighbour; flow
    /// vectors rescaled to frame pixels).
    pub fn run(
        &mut self,
        frame: &RgbImage,
        previous: Option<&RgbImage>,
    ) -> Result<DenseOutput, RawError> {
        let input = self.loaded.config.input.clone();
        let (fw, fh) = frame.dimensions();
        let Some(patch) = preprocess::plan(&input, fw, fh).into_iter().next() else {
            return Err(RawError::Frames {
                path: self.runner.path().to_path_buf(),
                message: "empty frame".into(),
            });
        };
        if input.frames == 2 {
            let prev = previous.unwrap_or(frame);
            if prev.dimensions() != frame.dimensions() {
                return Err(RawError::Frames {
                    path: self.runner.path().to_path_buf(),
                    message: "previous and current frame differ in size".into(),
                });
            }
            preprocess::fill_slot(&input, prev, &patch, &mut self.tensor, 0);
            preprocess::fill_slot(&input, frame, &patch, &mut self.tensor, 1);
        } else {
            preprocess::fill(&input, frame, &patch, &mut self.tensor);
        }
        let outputs = self.runner.run(self.tensor.view().into_dyn())?;
        let model = self.runner.path().to_path_buf();
        Ok(match &self.loaded.config.output {
            OutputSpec::Segmentation { num_classes } => DenseOutput::Semantic(resample(
                &decode::segmentation_argmax(&model, &outputs, *num_classes)?,
                &patch,
                fw,
                fh,
                |_, v| v,
            )),
            OutputSpec::Depth { scale, .. } => DenseOutput::Depth(resample(
                &decode::depth_map(&model, &outputs, *scale)?,
                &patch,
                fw,
                fh,
                |_, v| v,
            )),
            OutputSpec::Flow { scale } => {
                let m = decode::flow_map(&model, &outputs, *scale)?;
                let k = [(1.0 / patch.scale_x) as f32, (1.0 / patch.scale_y) as f32];
                DenseOutput::Flow(resample(&m, &patch, fw, fh, |c, v| {
                    v * k.get(c).copied().unwrap_or(1.0)
                }))
            }
            OutputSpec::Detector { .. } => {
                return Err(RawError::OutputShape {
                    model,
                    message: "detector output in a dense model".into(),
                });
            }
        })
    }
}

/// Nearest-neighbour resampling of a model-resolution map back to the frame;
/// `gain(channel, value)` rescales values (flow vectors into frame pixels).
fn resample<T: Copy + Default>(
    m: &DenseMap<T>,
    patch: &preprocess::Patch,
    fw: u32,
    fh: u32,
    gain: impl Fn(usize, T) -> T,
) -> DenseMap<T> {
    let (w, h) = (fw as usize, fh as usize);
    let mut data = Vec::with_capacity(w * h * m.channels);
    for y in 0..h {
        let my = ((y as f64 + 0.5) * patch.scale_y) as usize;
        for x in 0..w {
            let mx = ((x as f64 + 0.5) * patch.scale_x) as usize;
            for c in 0..m.channels {
                let v = m
                    .get(
                        mx.min(m.width.saturating_sub(1)),
                        my.min(m.height.saturating_sub(1)),
                        c,
                    )
                    .unwrap_or_default();
                data.push(gain(c, v));
            }
        }
    }
    DenseMap {
        width: w,
        height: h,
        channels: m.channels,
        data,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame_with(w: usize, h: usize, labels: Vec<u16>) -> DenseFrame {
        DenseFrame {
            width: w,
            height: h,
            semantic: Some(DenseMap {
                width: w,
                height: h,
                channels: 1,
                data: labels,
            }),
            ..DenseFrame::default()
        }
    }

    #[test]
    fn connected_components_split_same_class_blobs() {
        // Two separate blobs of class 1, one of class 2, background 0 unmapped.
        #[rustfmt::skip]
        let labels = vec![
            1, 1, 0, 1,
            1, 0, 0, 1,
            0, 0, 2, 2,
        ];
        let mut table = ClassTable::default();
        table.insert(1, ObjectClass::Vehicle, Some("Car".into()));
        table.insert(2, ObjectClass::Pedestrian, None);
        let inst = instances(
            &frame_with(4, 3, labels),
            &table,
            &InstanceConfig { min_pixels: 1 },
        )
        .unwrap();
        assert_eq!(inst.len(), 3);
        assert_eq!(
            inst[0].bbox,
            BBox2D {
                left: 0.0,
                top: 0.0,
                right: 2.0,
                bottom: 2.0
            }
        );
        assert_eq!(inst[0].pixels, 3);
        assert_eq!(
            inst[1].bbox,
            BBox2D {
                left: 3.0,
                top: 0.0,
                right: 4.0,
                bottom: 2.0
            }
        );
        assert_eq!(inst[2].class, ObjectClass::Pedestrian);
        let big = instances(
            &frame_with(4, 3, vec![1, 1, 0, 1, 1, 0, 0, 1, 0, 0, 2, 2]),
            &table,
            &InstanceConfig { min_pixels: 3 },
        )
        .unwrap();
        assert_eq!(big.len(), 1);
    }

    #[test]
    fn instance_maps_separate_touching_objects_and_carry_depth() {
        let mut f = frame_with(4, 1, vec![1, 1, 1, 1]);
        f.instance = Some(DenseMap {
            width: 4,
            height: 1,
            channels: 1,
            data: vec![5, 5, 9, 9],
        });
        f.depth = Some(DenseMap {
            width: 4,
            height: 1,
            channels: 1,
            data: vec![10.0, 12.0, 0.0, 30.0],
        });
        let mut table = ClassTable::default();
        table.insert(1, ObjectClass::Vehicle, None);
        let inst = instances(&f, &table, &InstanceConfig { min_pixels: 1 }).unwrap();
        assert_eq!(inst.len(), 2);
        assert_eq!(inst[0].instance_id, Some(5));
        assert_eq!(inst[0].nearest_depth_m, Some(10.0));
        assert_eq!(inst[1].depth_m, Some(30.0), "unknown depth (0) is skipped");
    }

    #[test]
    fn mismatched_maps_are_rejected() {
        let mut f = frame_with(4, 1, vec![1, 1, 1, 1]);
        f.depth = Some(DenseMap {
            width: 2,
            height: 2,
            channels: 1,
            data: vec![1.0; 4],
        });
        let err = instances(&f, &ClassTable::default(), &InstanceConfig::default())
            .unwrap_err()
            .to_string();
        assert!(err.contains("depth map is 2x2"), "{err}");
    }

    #[test]
    fn png_round_trip() {
        let dir = std::env::temp_dir().join(format!("pframes-dense-{}", std::process::id()));
        let mut f = frame_with(3, 2, vec![0, 1, 2, 3, 4, 300]);
        f.instance = Some(DenseMap {
            width: 3,
            height: 2,
            channels: 1,
            data: vec![0, 1, 1, 2, 2, 70000],
        });
        f.depth = Some(DenseMap {
            width: 3,
            height: 2,
            channels: 1,
            data: vec![0.0, 1.5, 10.25, 80.0, 200.0, f32::NAN],
        });
        f.flow = Some(DenseMap {
            width: 3,
            height: 2,
            channels: 2,
            data: vec![
                0.5, -1.0, 2.0, 0.0, -3.25, 4.0, 0.0, 0.0, 1.0, 1.0, 7.5, -7.5,
            ],
        });
        f.write_pngs(&dir, "f").unwrap();
        let back = DenseFrame::from_pngs(
            Some(&dir.join("f_semantic.png")),
            Some(&dir.join("f_instance.png")),
            Some(&dir.join("f_depth.png")),
            Some(&dir.join("f_flow.png")),
        )
        .unwrap();
        assert_eq!(back.semantic, f.semantic);
        assert_eq!(
            back.instance.as_ref().map(|m| m.data[5]),
            Some(65535),
            "ids saturate at 16 bits"
        );
        assert_eq!(
            back.depth.as_ref().map(|m| m.data[..5].to_vec()),
            Some(vec![0.0, 1.5, 10.25, 80.0, 200.0])
        );
        assert_eq!(
            back.depth.as_ref().map(|m| m.data[5]),
            Some(0.0),
            "unknown depth stays unknown"
        );
        assert_eq!(back.flow, f.flow);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn eight_bit_semantic_png_keeps_class_ids() {
        let dir = std::env::temp_dir().join(format!("pframes_sem8_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("sem8.png");
        image::GrayImage::from_raw(3, 1, vec![0, 7, 255])
            .unwrap()
            .save(&path)
            .unwrap();
        let m = read_semantic_png(&path).unwrap();
        assert_eq!((m.width, m.height, m.channels), (3, 1, 1));
        assert_eq!(m.data, vec![0, 7, 255]);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
