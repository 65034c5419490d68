//! Source specifications, the strings users type to say where a
//! [`Sequence`] comes from:
//!
//! - `kitti:DIR` — a KITTI tracking root with `label_02/` and `calib/`;
//!   sequences are `0000`, `0001`, …
//! - `sim:NAME` or `sim:NAME@SEED` — a built-in scenario, or a scenario file
//!   (`.yaml`/`.yml`/`.json`) by path; the seed drives the noise model;
//! - `json:FILE` — a track file in the `logicrag-tracks/1` format;
//! - `av2:DIR` — an Argoverse 2 log directory (annotations Feather, ego
//!   pose Feather, `map/`), see [`crate::av2`].

use std::path::PathBuf;

use crate::error::PerceptionError;
use crate::model::Sequence;
use crate::sim::{self, Scenario, SimRun};

/// A parsed source specification.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Source {
    /// KITTI tracking labels under a root directory.
    Kitti {
        /// Root holding `label_02/` and `calib/`.
        root: PathBuf,
    },
    /// The simulator.
    Sim {
        /// Built-in scenario name or scenario file path.
        scenario: String,
        /// Noise seed.
        seed: u64,
    },
    /// A JSON track file.
    Json {
        /// The file.
        path: PathBuf,
    },
    /// An Argoverse 2 log directory.
    Av2 {
        /// The log directory (holding `annotations.feather` or
        /// `annotations_with_ego.feather`).
        dir: PathBuf,
    },
}

/// The spec a user would type: `kitti:DIR`, `sim:NAME@SEED`, `json:FILE`
/// (`Source::parse` reads it back to the same source).
impl std::fmt::Display for Source {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Source::Kitti { root } => write!(f, "kitti:{}", root.display()),
            Source::Sim { scenario, seed } => write!(f, "sim:{scenario}@{seed}"),
            Source::Json { path } => write!(f, "json:{}", path.display()),
            Source::Av2 { dir } => write!(f, "av2:{}", dir.display()),
        }
    }
}

impl Source {
    /// Parses `kitti:DIR`, `sim:NAME[@SEED]` or `json:FILE`.
    pub fn parse(spec: &str) -> Result<Source, PerceptionError> {
        let err = |message: &str| PerceptionError::Source {
            spec: spec.to_string(),
            message: message.to_string(),
        };
        let (kind, rest) = spec.split_once(':').ok_or_else(|| {
            err("expected `kitti:DIR`, `sim:NAME[@SEED]`, `json:FILE` or `av2:DIR`")
        })?;
        if rest.is_empty() {
            return Err(err("nothing after the colon"));
        }
        match kind {
            "kitti" => Ok(Source::Kitti {
                root: PathBuf::from(rest),
            }),
            "json" => Ok(Source::Json {
                path: PathBuf::from(rest),
            }),
            "av2" => Ok(Source::Av2 {
                dir: PathBuf::from(rest),
            }),
            "sim" => {
                let (scenario, seed) = match rest.rsplit_once('@') {
                    Some((name, seed)) => (
                        name,
                        seed.parse::<u64>().map_err(|_| {
                            err("the seed after `@` must be a non-negative integer")
                        })?,
                    ),
                    None => (rest, 0),
                };
                Ok(Source::Sim {
                    scenario: scenario.to_string(),
                    seed,
                })
            }
            _ => Err(err(
                "unknown source kind; expected `kitti`, `sim`, `json` or `av2`",
            )),
        }
    }

    /// The sequences this source offers (KITTI: every label file; others:
    /// their single sequence's name).
    pub fn sequences(&self) -> Result<Vec<String>, PerceptionError> {
        match self {
            Source::Kitti { root } => crate::kitti::list_sequences(root),
            Source::Sim { .. } => Ok(vec![self.scenario()?.name]),
            Source::Json { path } => Ok(vec![crate::json::load_tracks(path)?.name]),
            Source::Av2 { dir } => Ok(vec![crate::av2::log_name(dir)?]),
        }
    }

    fn scenario(&self) -> Result<Scenario, PerceptionError> {
        match self {
            Source::Sim { scenario, .. } => {
                if sim::builtin_text(scenario).is_some() {
                    Scenario::builtin(scenario)
                } else {
                    let path = std::path::Path::new(scenario);
                    if path.exists() {
                        Scenario::load(path)
                    } else {
                        Err(PerceptionError::Source {
                            spec: format!("sim:{scenario}"),
                            message: format!(
                                "neither a built-in scenario ({}) nor an existing file",
                                sim::BUILTIN_NAMES.join(", ")
                            ),
                        })
                    }
                }
            }
            _ => Err(PerceptionError::Source {
                spec: self.to_string(),
                message: "not a simulator source".into(),
            }),
        }
    }

    /// Runs the simulator for a `sim:` source (the sequence plus its event
    /// log and scene states).
    pub fn simulate(&self) -> Result<SimRun, PerceptionError> {
        self.simulate_with(None)
    }

    /// [`Source::simulate`] with the scenario's noise replaced by a noise
    /// level, a preset or a scaled one (`None`: the scenario's own `noise:`).
    pub fn simulate_with(&self, noise: Option<sim::NoiseLevel>) -> Result<SimRun, PerceptionError> {
        match self {
            Source::Sim { seed, .. } => {
                let mut scenario = self.scenario()?;
                if let Some(level) = noise {
                    scenario.noise = level.spec();
                }
                sim::simulate(&scenario, *seed)
            }
            _ => Err(PerceptionError::Source {
                spec: self.to_string(),
                message: "not a simulator source".into(),
            }),
        }
    }

    /// Loads a sequence. KITTI needs the sequence name (`"0000"`); the other
    /// sources have one sequence and accept `None` or its own name.
    pub fn load(&self, sequence: Option<&str>) -> Result<Sequence, PerceptionError> {
        let seq = match self {
            Source::Kitti { root } => {
                let name = sequence.ok_or_else(|| PerceptionError::Source {
                    spec: format!("kitti:{}", root.display()),
                    message: "a KITTI source needs a sequence name such as 0000".into(),
                })?;
                return Ok(crate::kitti::load(root, name)?.sequence);
            }
            Source::Sim { .. } => self.simulate()?.sequence,
            Source::Json { path } => crate::json::load_tracks(path)?,
            Source::Av2 { dir } => crate::av2::load(dir)?,
        };
        if let Some(name) = sequence
            && name != seq.name
        {
            return Err(PerceptionError::Source {
                spec: self.to_string(),
                message: format!(
                    "this source holds only the sequence `{}`, not `{name}`",
                    seq.name
                ),
            });
        }
        Ok(seq)
    }
}

/// Parses a frame range `A-B` (inclusive) or a single frame `A`.
pub fn parse_frame_range(text: &str) -> Result<(u32, u32), PerceptionError> {
    let bad = || PerceptionError::InvalidWindow(format!("`{text}` is not a frame range like 0-9"));
    let (a, b) = match text.split_once('-') {
        Some((a, b)) => (
            a.trim().parse::<u32>().map_err(|_| bad())?,
            b.trim().parse::<u32>().map_err(|_| bad())?,
        ),
        None => {
            let a = text.trim().parse::<u32>().map_err(|_| bad())?;
            (a, a)
        }
    };
    if a > b {
        return Err(bad());
    }
    Ok((a, b))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_specs() {
        assert_eq!(
            Source::parse("kitti:../x").unwrap(),
            Source::Kitti {
                root: "../x".into()
            }
        );
        assert_eq!(
            Source::parse("sim:braking@7").unwrap(),
            Source::Sim {
                scenario: "braking".into(),
                seed: 7
            }
        );
        assert_eq!(
            Source::parse("sim:braking").unwrap(),
            Source::Sim {
                scenario: "braking".into(),
                seed: 0
            }
        );
        assert!(Source::parse("video:x").is_err());
        assert!(Source::parse("sim:").is_err());
        assert!(Source::parse("sim:x@y").is_err());
        assert!(Source::parse("sim:nope").unwrap().load(None).is_err());
        assert_eq!(parse_frame_range("0-9").unwrap(), (0, 9));
        assert_eq!(parse_frame_range("5").unwrap(), (5, 5));
        assert!(parse_frame_range("9-0").is_err());
    }

    #[test]
    fn errors_name_the_spec_as_typed_not_the_debug_form() {
        for spec in ["kitti:../x", "sim:braking@7", "json:t.json"] {
            let source = Source::parse(spec).unwrap();
            assert_eq!(source.to_string(), spec);
            assert_eq!(Source::parse(&source.to_string()).unwrap(), source);
        }
        let e = Source::parse("sim:braking")
            .unwrap()
            .load(Some("other"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("sim:braking@0"), "{e}");
        assert!(!e.contains("Sim {"), "{e}");
    }
}
