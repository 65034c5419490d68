//! Dense maps (from PNG files or the renderer) into a tracked sequence,
//! without any model.

use std::path::Path;

use super::assemble::{Assembler, Candidate};
use super::input::checked_frame_count;
use super::options::FramesOptions;
use crate::model::{CameraConfig, Sequence};
use crate::raw::RawError;
use crate::raw::decode::DenseMap;
use crate::raw::dense::{ClassTable, DenseFrame, instances};

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
