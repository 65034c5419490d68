//! The models file of a frames run: one detector config, or a set naming a
//! detector and optional depth and flow models.

use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::raw::RawError;
use crate::raw::config::{LoadedConfig, ModelConfig, OutputSpec};

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
        let text = crate::textfile::read_text_file(path).map_err(|e| RawError::io(path, e))?;
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
