//! Model configuration files (YAML). Swapping a model is editing this file:
//! the model path, how frames become the input tensor, what the output means,
//! and how the model's classes map onto LogicPad classes and `TypeOf` values.
//!
//! ```yaml
//! name: nanodet-m-416-coco
//! model: ../../../shared/models/nanodet-m-416-coco.onnx   # relative to this file
//! input: { width: 416, height: 416, layout: nchw, colour: bgr,
//!          mean: [103.53, 116.28, 123.675], std: [57.375, 57.12, 58.395],
//!          resize: { mode: tiles, columns: 3 } }
//! output: { kind: detector, score_threshold: 0.45, nms_iou: 0.5, max_detections: 100,
//!           decoder: { name: nanodet_gfl, strides: [8, 16, 32], reg_max: 10, num_classes: 80 } }
//! labels:
//!   - { id: 2, name: car, class: Vehicles, type: Car }
//! ```

use std::path::{Path, PathBuf};

use serde::Deserialize;

use super::RawError;
use crate::model::ObjectClass;

/// Tensor layout of the model input.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Layout {
    /// Batch, channels, height, width.
    Nchw,
    /// Batch, height, width, channels.
    Nhwc,
}

/// Channel order the model expects.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ColourOrder {
    /// Red, green, blue.
    Rgb,
    /// Blue, green, red (OpenCV-trained models such as NanoDet).
    Bgr,
}

/// How a frame of any size becomes one or more model inputs.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(tag = "mode", rename_all = "snake_case", deny_unknown_fields)]
pub enum ResizeMode {
    /// Scale keeping the aspect ratio, pad the rest (one model run per frame).
    Letterbox,
    /// Scale each axis independently to the input size (distorts wide frames).
    Stretch,
    /// Cut the frame into `columns` overlapping crops with the input's aspect
    /// ratio, spanning the full frame height, one model run per crop: small
    /// objects in wide frames keep more pixels.
    Tiles {
        /// Number of crops across the frame (at least 1).
        columns: u32,
        /// Extra width of each crop beyond `frame width / columns`, as a
        /// fraction, so objects on a seam appear whole in one crop.
        #[serde(default = "default_overlap")]
        overlap: f32,
    },
}

/// Input tensor description.
///
/// Invariant (after [`ModelConfig::load`]): `width`, `height` > 0 and every
/// `std` entry is finite and non-zero.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InputSpec {
    /// Input width in pixels.
    pub width: u32,
    /// Input height in pixels.
    pub height: u32,
    /// Tensor layout.
    pub layout: Layout,
    /// Channel order.
    pub colour: ColourOrder,
    /// Per-channel mean subtracted from 0–255 pixel values, in `colour` order.
    pub mean: [f32; 3],
    /// Per-channel divisor applied after the mean, in `colour` order.
    pub std: [f32; 3],
    /// Frame-to-input mapping; letterbox when absent.
    #[serde(default = "default_resize")]
    pub resize: ResizeMode,
    /// Pixel value (0–255, before normalisation) of letterbox padding.
    #[serde(default)]
    pub pad_value: f32,
    /// Frames stacked on the channel axis, oldest first (2 for optical flow
    /// over the previous and the current frame); 1 when absent.
    #[serde(default = "one_frame")]
    pub frames: u32,
}

fn one_frame() -> u32 {
    1
}

fn default_overlap() -> f32 {
    0.1
}

fn default_resize() -> ResizeMode {
    ResizeMode::Letterbox
}

/// A named detector decoder.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "name", rename_all = "snake_case", deny_unknown_fields)]
pub enum DetectorDecoder {
    /// NanoDet / Generalized Focal Loss heads: per stride, one `N×C` score
    /// output (already sigmoid) and one `N×4(reg_max+1)` distribution output
    /// (sides left, top, right, bottom); a side's distance is the softmax
    /// expectation times the stride, measured from the cell centre
    /// `((x + 0.5)·stride, (y + 0.5)·stride)`, cells in row-major order.
    NanodetGfl {
        /// Feature-map strides in output order (8, 16, 32 for NanoDet-m).
        strides: Vec<u32>,
        /// Highest distribution bin; each side has `reg_max + 1` bins.
        reg_max: u32,
        /// Number of classes in the score outputs.
        num_classes: usize,
    },
}

/// Depth output interpretation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DepthMode {
    /// Output is metres (times `scale`).
    Metric,
    /// Output is monotonic in depth with an unknown scale (what
    /// [`RelativeDepth`] says: inverse depth by default, MiDaS style). Each
    /// frame's map is aligned to that frame's monocular estimates
    /// ([`super::relative`]) by one scale factor.
    Relative,
}

/// What a relative depth map's values are proportional to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RelativeDepth {
    /// Inverse depth / disparity: larger is nearer (MiDaS, DPT, Depth
    /// Anything in their relative form). The default.
    #[default]
    InverseDepth,
    /// Depth itself up to scale: larger is farther.
    Depth,
}

/// What the model's output means.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum OutputSpec {
    /// Object detector.
    Detector {
        /// The decoder that turns raw outputs into boxes.
        decoder: DetectorDecoder,
        /// Minimum class score kept.
        score_threshold: f32,
        /// IoU above which a lower-scored box of the same class is suppressed.
        nms_iou: f32,
        /// Most detections kept per frame after NMS.
        max_detections: usize,
        /// A box also counts as a duplicate when a kept box of its class
        /// covers more than this fraction of its area (the partial boxes tiles
        /// produce at seams); 1 disables the rule.
        #[serde(default = "one")]
        containment: f32,
    },
    /// Semantic segmentation: one output `1×C×H×W` of logits or scores; the
    /// class of a pixel is the argmax over `C`.
    Segmentation {
        /// Number of classes `C`.
        num_classes: usize,
    },
    /// Depth map: one output `1×1×H×W` or `1×H×W`.
    Depth {
        /// Metric or relative.
        mode: DepthMode,
        /// Multiplier applied to raw values (metres per unit for metric; for
        /// relative maps it cancels in the alignment).
        #[serde(default = "one")]
        scale: f32,
        /// For `mode: relative`, what the values are proportional to
        /// (`inverse_depth` when absent); an error with `mode: metric`.
        #[serde(default)]
        relative: Option<RelativeDepth>,
    },
    /// Optical flow: one output `1×2×H×W` (dx, dy in input pixels).
    Flow {
        /// Multiplier applied to raw values.
        #[serde(default = "one")]
        scale: f32,
    },
}

fn one() -> f32 {
    1.0
}

/// A label's LogicPad class. It can only hold a class, so the detector and
/// the dense path map labels without a lookup that could fail; it is read
/// from the exact class predicate (`Vehicles`, not the variant alias
/// `Vehicle` that [`ObjectClass::from_predicate`] also accepts), and any
/// other text is a parse error naming the file, line and the expected names.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct LabelClass(ObjectClass);

impl LabelClass {
    /// The label class of `class`.
    pub fn new(class: ObjectClass) -> LabelClass {
        LabelClass(class)
    }

    /// The class.
    pub fn class(self) -> ObjectClass {
        self.0
    }

    /// The class predicate (`Vehicles`, `Pedestrian`, …).
    pub fn as_str(self) -> &'static str {
        self.0.predicate()
    }
}

impl From<ObjectClass> for LabelClass {
    fn from(class: ObjectClass) -> LabelClass {
        LabelClass(class)
    }
}

impl<'de> Deserialize<'de> for LabelClass {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<LabelClass, D::Error> {
        let name = String::deserialize(d)?;
        ObjectClass::ALL
            .iter()
            .copied()
            .find(|c| c.predicate() == name)
            .map(LabelClass)
            .ok_or_else(|| {
                serde::de::Error::custom(format!(
                    "`{name}` is not a LogicPad class; expected one of {}",
                    CLASS_PREDICATES.join(", ")
                ))
            })
    }
}

/// One entry of the label map: a model class id onto a LogicPad class
/// predicate and an optional `TypeOf` value. Model classes absent from the map
/// are not perceived (a COCO detector's `cup` is not traffic).
#[derive(Debug, Clone, PartialEq, Eq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LabelSpec {
    /// The model's class index.
    pub id: usize,
    /// The model's class name (documentation and object naming).
    pub name: String,
    /// LogicPad class (`Vehicles`, `Pedestrian`, `TrafficLight`, …).
    pub class: LabelClass,
    /// `TypeOf` value (`Car`, `Bus`, …), when the class has one.
    #[serde(default, rename = "type")]
    pub type_name: Option<String>,
}

/// A model configuration file, as written.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelConfig {
    /// Human-readable model name.
    pub name: String,
    /// Model file, relative to the config file's directory.
    pub model: PathBuf,
    /// Input description.
    pub input: InputSpec,
    /// Output description.
    pub output: OutputSpec,
    /// Label map (detectors and segmentation).
    #[serde(default)]
    pub labels: Vec<LabelSpec>,
    /// Intra-op threads for ONNX Runtime; 0 lets it choose.
    #[serde(default)]
    pub threads: usize,
}

/// The class predicates a label may map onto (the canonical vocabulary):
/// [`ObjectClass::predicate`] of every [`ObjectClass::ALL`], in that order.
pub const CLASS_PREDICATES: &[&str] = &{
    let mut out = [""; ObjectClass::ALL.len()];
    let mut i = 0;
    while i < out.len() {
        out[i] = ObjectClass::ALL[i].predicate();
        i += 1;
    }
    out
};

/// The `TypeOf` values a label may carry (the vocabulary's one list).
pub use crate::facts::TYPE_VALUES;

/// A validated config with its model path resolved.
///
/// Invariant: every check of [`ModelConfig::validate`] holds, and
/// `model_path` is the config's `model` joined to the config's directory (or
/// the override given to [`LoadedConfig::with_model`]).
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedConfig {
    /// The parsed config.
    pub config: ModelConfig,
    /// The config file it came from.
    pub config_path: PathBuf,
    /// The model file to open.
    pub model_path: PathBuf,
}

impl LoadedConfig {
    /// Replaces the model file (the `--model` override), keeping the rest.
    pub fn with_model(mut self, model: impl Into<PathBuf>) -> Self {
        self.model_path = model.into();
        self
    }

    /// The label for model class `id`, if mapped.
    pub fn label(&self, id: usize) -> Option<&LabelSpec> {
        self.config.labels.iter().find(|l| l.id == id)
    }
}

impl ModelConfig {
    /// Reads, parses and validates a config file; the model path is resolved
    /// relative to the file's directory.
    pub fn load(path: &Path) -> Result<LoadedConfig, RawError> {
        let text = crate::textfile::read_text_file(path).map_err(|e| RawError::io(path, e))?;
        ModelConfig::parse(&text, path)
    }

    /// Parses and validates config text; `path` names it in errors and anchors
    /// the relative model path.
    pub fn parse(text: &str, path: &Path) -> Result<LoadedConfig, RawError> {
        let config: ModelConfig =
            serde_saphyr::from_str(text).map_err(|e| RawError::ConfigSyntax {
                path: path.to_path_buf(),
                message: crate::error::yaml_message(&e, &path.display().to_string()),
            })?;
        config.validate(path)?;
        let base = path.parent().unwrap_or(Path::new("."));
        let model_path = if config.model.is_absolute() {
            config.model.clone()
        } else {
            base.join(&config.model)
        };
        Ok(LoadedConfig {
            config,
            config_path: path.to_path_buf(),
            model_path,
        })
    }

    /// Checks ranges and cross-field consistency.
    pub fn validate(&self, path: &Path) -> Result<(), RawError> {
        let bad = |field: &str, message: String| RawError::ConfigInvalid {
            path: path.to_path_buf(),
            field: field.to_string(),
            message,
        };
        let input = &self.input;
        if input.width == 0 || input.height == 0 {
            return Err(bad(
                "input",
                format!("size {}x{} must be positive", input.width, input.height),
            ));
        }
        if let Some(s) = input.std.iter().find(|s| !s.is_finite() || **s == 0.0) {
            return Err(bad("input.std", format!("{s} must be finite and non-zero")));
        }
        if !(1..=2).contains(&input.frames) {
            return Err(bad(
                "input.frames",
                format!("{} must be 1 or 2", input.frames),
            ));
        }
        if input.frames == 2 && !matches!(self.output, OutputSpec::Flow { .. }) {
            return Err(bad(
                "input.frames",
                "two stacked frames are only meaningful for a flow model".to_string(),
            ));
        }
        if input.mean.iter().any(|m| !m.is_finite()) {
            return Err(bad("input.mean", "values must be finite".to_string()));
        }
        if let ResizeMode::Tiles { columns, overlap } = input.resize {
            if columns == 0 {
                return Err(bad(
                    "input.resize.columns",
                    "must be at least 1".to_string(),
                ));
            }
            if !(0.0..=1.0).contains(&overlap) {
                return Err(bad(
                    "input.resize.overlap",
                    format!("{overlap} is not in [0, 1]"),
                ));
            }
        }
        let num_classes = match &self.output {
            OutputSpec::Detector {
                decoder,
                score_threshold,
                nms_iou,
                max_detections,
                containment,
            } => {
                if !(0.0..=1.0).contains(containment) {
                    return Err(bad(
                        "output.containment",
                        format!("{containment} is not in [0, 1]"),
                    ));
                }
                if !(0.0..=1.0).contains(score_threshold) {
                    return Err(bad(
                        "output.score_threshold",
                        format!("{score_threshold} is not in [0, 1]"),
                    ));
                }
                if !(0.0..=1.0).contains(nms_iou) {
                    return Err(bad("output.nms_iou", format!("{nms_iou} is not in [0, 1]")));
                }
                if *max_detections == 0 {
                    return Err(bad("output.max_detections", "must be positive".to_string()));
                }
                match decoder {
                    DetectorDecoder::NanodetGfl {
                        strides,
                        reg_max,
                        num_classes,
                    } => {
                        if strides.is_empty() || strides.contains(&0) {
                            return Err(bad(
                                "output.decoder.strides",
                                format!("{strides:?} must be non-empty and positive"),
                            ));
                        }
                        if let Some(s) = strides.iter().find(|&&s| {
                            !input.width.is_multiple_of(s) || !input.height.is_multiple_of(s)
                        }) {
                            return Err(bad(
                                "output.decoder.strides",
                                format!(
                                    "stride {s} does not divide the input size {}x{}",
                                    input.width, input.height
                                ),
                            ));
                        }
                        if *reg_max == 0 {
                            return Err(bad(
                                "output.decoder.reg_max",
                                "must be positive".to_string(),
                            ));
                        }
                        if *num_classes == 0 {
                            return Err(bad(
                                "output.decoder.num_classes",
                                "must be positive".to_string(),
                            ));
                        }
                        Some(*num_classes)
                    }
                }
            }
            OutputSpec::Segmentation { num_classes } => {
                if *num_classes == 0 {
                    return Err(bad("output.num_classes", "must be positive".to_string()));
                }
                Some(*num_classes)
            }
            OutputSpec::Depth {
                mode: DepthMode::Metric,
                relative: Some(_),
                ..
            } => {
                return Err(bad(
                    "output.relative",
                    "only meaningful with `mode: relative` (a metric map is metres)".to_string(),
                ));
            }
            OutputSpec::Depth { scale, .. } | OutputSpec::Flow { scale } => {
                if !scale.is_finite() || *scale <= 0.0 {
                    return Err(bad("output.scale", format!("{scale} must be positive")));
                }
                None
            }
        };
        let mut seen = std::collections::BTreeSet::new();
        for (i, label) in self.labels.iter().enumerate() {
            let field = format!("labels[{i}]");
            if let Some(n) = num_classes
                && label.id >= n
            {
                return Err(bad(
                    &field,
                    format!("id {} is not below the model's {n} classes", label.id),
                ));
            }
            if !seen.insert(label.id) {
                return Err(bad(&field, format!("id {} is mapped twice", label.id)));
            }
            if let Some(t) = &label.type_name
                && !TYPE_VALUES.contains(&t.as_str())
            {
                return Err(bad(
                    &format!("{field}.type"),
                    format!(
                        "`{t}` is not a TypeOf value; expected one of {}",
                        TYPE_VALUES.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn class_predicates_are_every_class_once() {
        assert_eq!(CLASS_PREDICATES.len(), ObjectClass::ALL.len());
        for (name, class) in CLASS_PREDICATES.iter().zip(ObjectClass::ALL) {
            assert_eq!(ObjectClass::from_predicate(name), Some(class));
        }
        assert_eq!(CLASS_PREDICATES[0], "Vehicles");
        assert_eq!(CLASS_PREDICATES.last(), Some(&"Other"));
    }

    const GOOD: &str = "
name: tiny
model: tiny.onnx
input:
  width: 32
  height: 32
  layout: nchw
  colour: bgr
  mean: [0, 0, 0]
  std: [1, 1, 1]
  resize: { mode: tiles, columns: 2 }
output:
  kind: detector
  score_threshold: 0.3
  nms_iou: 0.5
  max_detections: 10
  decoder: { name: nanodet_gfl, strides: [8, 16], reg_max: 3, num_classes: 4 }
labels:
  - { id: 2, name: car, class: Vehicles, type: Car }
  - { id: 0, name: person, class: Pedestrian }
";

    #[test]
    fn parses_and_resolves_model_relative_to_config() {
        let loaded = ModelConfig::parse(GOOD, Path::new("/cfg/dir/tiny.yaml")).unwrap();
        assert_eq!(loaded.model_path, PathBuf::from("/cfg/dir/tiny.onnx"));
        assert_eq!(
            loaded.config.input.resize,
            ResizeMode::Tiles {
                columns: 2,
                overlap: 0.1
            }
        );
        assert_eq!(
            loaded.label(2).and_then(|l| l.type_name.as_deref()),
            Some("Car")
        );
        assert!(loaded.label(1).is_none());
        let over = loaded.with_model("/elsewhere/m.onnx");
        assert_eq!(over.model_path, PathBuf::from("/elsewhere/m.onnx"));
    }

    #[test]
    fn syntax_errors_name_file_and_line() {
        let text = GOOD.replace("layout: nchw", "layout: nchwx");
        let err = ModelConfig::parse(&text, Path::new("m.yaml"))
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("m.yaml:"), "{err}");
        assert!(err.contains("line") || err.contains(':'), "{err}");
        let unknown = GOOD.replace("name: tiny", "name: tiny\ncolor_space: bgr");
        assert!(ModelConfig::parse(&unknown, Path::new("m.yaml")).is_err());
    }

    #[test]
    fn invalid_fields_are_named() {
        let cases = [
            ("std: [1, 1, 1]", "std: [1, 0, 1]", "input.std"),
            (
                "strides: [8, 16]",
                "strides: [8, 12]",
                "output.decoder.strides",
            ),
            ("type: Car", "type: Automobile", "labels[0].type"),
            ("id: 2,", "id: 7,", "labels[0]"),
            ("id: 0,", "id: 2,", "labels[1]"),
            ("nms_iou: 0.5", "nms_iou: 1.5", "output.nms_iou"),
            ("columns: 2", "columns: 0", "input.resize.columns"),
        ];
        for (from, to, field) in cases {
            let text = GOOD.replace(from, to);
            let err = ModelConfig::parse(&text, Path::new("m.yaml"))
                .unwrap_err()
                .to_string();
            assert!(
                err.contains(&format!("field `{field}`")),
                "{from} -> {to}: {err}"
            );
        }
    }

    #[test]
    fn a_label_class_outside_the_vocabulary_is_a_parse_error_with_its_position() {
        // Label classes are `LabelClass`es: checked while parsing, so the
        // detector and the dense path never meet an unknown class. The
        // variant alias `Vehicle` is not a predicate and is refused too.
        let text = GOOD.replace("class: Vehicles", "class: Vehicle");
        let err = ModelConfig::parse(&text, Path::new("m.yaml"))
            .unwrap_err()
            .to_string();
        assert!(err.starts_with("m.yaml:"), "{err}");
        assert!(err.contains("line 19"), "{err}");
        assert!(
            err.contains("`Vehicle` is not a LogicPad class; expected one of Vehicles, Pedestrian"),
            "{err}"
        );
        let loaded = ModelConfig::parse(GOOD, Path::new("m.yaml")).unwrap();
        let classes: Vec<ObjectClass> = loaded
            .config
            .labels
            .iter()
            .map(|l| l.class.class())
            .collect();
        assert_eq!(classes, [ObjectClass::Vehicle, ObjectClass::Pedestrian]);
        assert_eq!(loaded.config.labels[0].class.as_str(), "Vehicles");
    }

    #[test]
    fn dense_kinds_parse() {
        let seg = "name: s\nmodel: s.onnx\ninput: {width: 8, height: 4, layout: nhwc, colour: rgb, mean: [0,0,0], std: [255,255,255]}\noutput: {kind: segmentation, num_classes: 3}\nlabels: [{id: 1, name: road, class: Road}]\n";
        let loaded = ModelConfig::parse(seg, Path::new("s.yaml")).unwrap();
        assert_eq!(
            loaded.config.output,
            OutputSpec::Segmentation { num_classes: 3 }
        );
        assert_eq!(loaded.config.input.resize, ResizeMode::Letterbox);
        let depth = seg.replace(
            "{kind: segmentation, num_classes: 3}",
            "{kind: depth, mode: metric, scale: 80}",
        );
        let loaded = ModelConfig::parse(&depth, Path::new("d.yaml")).unwrap();
        assert_eq!(
            loaded.config.output,
            OutputSpec::Depth {
                mode: DepthMode::Metric,
                scale: 80.0,
                relative: None,
            }
        );
        let relative = seg.replace(
            "{kind: segmentation, num_classes: 3}",
            "{kind: depth, mode: relative, relative: depth}",
        );
        let loaded = ModelConfig::parse(&relative, Path::new("r.yaml")).unwrap();
        assert_eq!(
            loaded.config.output,
            OutputSpec::Depth {
                mode: DepthMode::Relative,
                scale: 1.0,
                relative: Some(RelativeDepth::Depth),
            }
        );
        let metric_relative = seg.replace(
            "{kind: segmentation, num_classes: 3}",
            "{kind: depth, mode: metric, relative: inverse_depth}",
        );
        let err = ModelConfig::parse(&metric_relative, Path::new("m.yaml"))
            .unwrap_err()
            .to_string();
        assert!(err.contains("field `output.relative`"), "{err}");
        let flow = seg.replace("{kind: segmentation, num_classes: 3}", "{kind: flow}");
        let loaded = ModelConfig::parse(&flow, Path::new("f.yaml")).unwrap();
        assert_eq!(loaded.config.output, OutputSpec::Flow { scale: 1.0 });
    }
}
