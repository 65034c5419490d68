//! `logicrag simulate`: one simulator scenario's tracks, ground-truth
//! events and window facts, printed or written to a directory, and its
//! camera view of every frame written as PNG files.

use anyhow::{Context, Result};
use clap::Args;
use perception::{FactConfig, SceneState, WindowSpec};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Args)]
pub struct SimulateArgs {
    /// Built-in scenario name or scenario file.
    pub scenario: String,
    /// Noise seed.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Write tracks.json, events.json and facts/ into this directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Write the camera's view of every frame as DIR/NNNNNN.png (the frame
    /// number, six digits), a directory `frames:DIR` reads back.
    #[arg(long, value_name = "DIR")]
    pub frames_out: Option<PathBuf>,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: SimulateArgs) -> Result<ExitCode> {
    let spec = format!("sim:{}@{}", a.scenario, a.seed);
    let source = perception::Source::parse(&spec)?;
    let run = source.simulate()?;
    let windows =
        perception::window_facts(&run.sequence, WindowSpec::PAPER, &FactConfig::default())?;
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir.join("facts"))
            .with_context(|| format!("creating {}", dir.display()))?;
        std::fs::write(
            dir.join("tracks.json"),
            perception::json::to_tracks_json(&run.sequence)?,
        )?;
        std::fs::write(
            dir.join("events.json"),
            serde_json::to_string_pretty(&run.events)?,
        )?;
        for w in &windows {
            let id = logicrag::source::window_id(&run.sequence.name, w.first_frame);
            std::fs::write(dir.join("facts").join(format!("{id}.facts")), w.to_kb())?;
        }
        eprintln!(
            "wrote {}/tracks.json, events.json and {} window KBs under facts/",
            dir.display(),
            windows.len()
        );
    }
    if let Some(dir) = &a.frames_out {
        let written = write_frames(dir, &run.states)?;
        let k = run.states.first().map(|s| s.camera.intrinsics);
        eprintln!(
            "wrote {written} frames{} to {}/NNNNNN.png",
            k.map(|k| format!(" ({}×{})", k.image_width, k.image_height))
                .unwrap_or_default(),
            dir.display()
        );
    }
    if a.json {
        outln!(
            "{}",
            serde_json::json!({
                "scenario": run.sequence.name, "frames": run.sequence.frame_count,
                "observations": run.sequence.observations.len(), "events": run.events,
                "windows": windows.len(),
            })
        );
    } else {
        outln!(
            "scenario {}: {} frames, {} observations, {} tracks, {} windows",
            run.sequence.name,
            run.sequence.frame_count,
            run.sequence.observations.len(),
            run.sequence.tracks().len(),
            windows.len()
        );
        outln!("ground-truth events:");
        for e in &run.events {
            let other = e
                .other
                .as_ref()
                .map(|o| format!(" → {o}"))
                .unwrap_or_default();
            outln!(
                "  frames {:>3}-{:<3} {:<14} {}{}",
                e.first_frame,
                e.last_frame,
                format!("{:?}", e.kind),
                e.object,
                other
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Renders each state with its own camera into `dir/NNNNNN.png`, frames in
/// parallel (each is independent and named by its frame number, so the
/// files do not depend on the order); returns how many were written.
fn write_frames(dir: &Path, states: &[SceneState]) -> Result<usize> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    states
        .par_iter()
        .map(|state| {
            let path = dir.join(format!("{:06}.png", state.frame));
            perception::raw::view::render_view(state, &state.camera)
                .save_with_format(&path, image::ImageFormat::Png)
                .with_context(|| format!("writing {}", path.display()))
        })
        .collect::<Result<Vec<()>>>()
        .map(|v| v.len())
}
