//! Argoverse 2 sensor logs (`av2:DIR`): 360° cuboid annotations, the ego's
//! city pose and the vector map, read into one [`Sequence`].
//!
//! A log directory holds
//! - `annotations_with_ego.feather` (preferred) or `annotations.feather`:
//!   one row per cuboid and sweep (10 Hz) — `timestamp_ns`, `track_uuid`,
//!   `category`, `length_m`, `width_m`, `height_m`, `qw qx qy qz` and
//!   `tx_m ty_m tz_m` in the ego frame (x forward, y left, z up; `t` the
//!   cuboid's centre);
//! - `city_SE3_egovehicle.feather` (optional): the ego's city pose at about
//!   200 Hz (`timestamp_ns`, `qw qx qy qz`, `tx_m ty_m tz_m`);
//! - `map/log_map_archive_*.json` (optional): lanes, pedestrian crossings
//!   and drivable areas in the city frame.
//!
//! Frame `i` is the `i`-th distinct annotation timestamp. Each cuboid
//! becomes an observation without a pixel box, placed by its bottom centre
//! in the camera convention (X right = −y, Y down = −(z − h/2), Z forward
//! = x), size `[h, w, l]` and KITTI `rotation_y` from its yaw about z.
//! Track ids are given in sorted uuid order; `track_keys` keeps the uuids.
//! `EGO_VEHICLE` rows are the ego (constant `ego`), not objects: they are
//! counted in `skipped`, as are unreadable rows and duplicate (timestamp,
//! track) rows. The camera is nominal (AV2's `ring_front_center`): no
//! pixel box is used. `docs/formats.md` documents the format.

pub mod categories;
pub mod feather;
pub mod map;
pub mod pose;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::coords::vehicle_yaw_to_rotation_y;
use crate::error::PerceptionError;
use crate::model::{
    CameraConfig, CameraIntrinsics, Observation, SceneMap, Sequence, Skipped, WorldPose,
    check_frame_count, check_objects_per_frame,
};

pub use feather::{
    AnnotationRow, Annotations, FeatherTable, PoseRow, parse_annotations, parse_feather,
    parse_poses, read_annotations, read_feather, read_poses,
};
pub use map::{parse_map_json, read_map_json};

/// The annotation tables a log may have, in order of preference.
pub const ANNOTATION_FILES: [&str; 2] = ["annotations_with_ego.feather", "annotations.feather"];
/// The ego pose table.
pub const POSE_FILE: &str = "city_SE3_egovehicle.feather";

/// A nominal camera for AV2 logs: the `ring_front_center` camera's
/// typical intrinsics (portrait 1550 × 2048) and mounting height. Nominal
/// because no pixel box is read: the sequence's objects are placed by
/// their 3D cuboids, and a log's own calibration is not consulted.
pub const AV2_NOMINAL_CAMERA: CameraConfig = CameraConfig {
    intrinsics: CameraIntrinsics {
        fx: 1686.0,
        fy: 1686.0,
        cx: 775.0,
        cy: 1022.0,
        image_width: 1550,
        image_height: 2048,
    },
    height_m: 1.6,
};

/// How a log is read.
#[derive(Debug, Clone, PartialEq)]
pub struct Av2Options {
    /// How far (ns) an annotation timestamp may lie outside the ego poses
    /// and still take the nearest pose; farther is an error. Default 50 ms
    /// (ten pose rows at 200 Hz).
    pub pose_tolerance_ns: i64,
    /// Cuboids whose centre is farther than this from the ego on the
    /// ground plane are skipped and counted; `None` (default) keeps all.
    pub max_range_m: Option<f64>,
    /// Whether to read `map/` (default true).
    pub read_map: bool,
}

impl Default for Av2Options {
    fn default() -> Self {
        Av2Options {
            pose_tolerance_ns: 50_000_000,
            max_range_m: None,
            read_map: true,
        }
    }
}

/// The log's name (its directory name).
pub fn log_name(dir: &Path) -> Result<String, PerceptionError> {
    let named = |p: &Path| p.file_name().and_then(|n| n.to_str()).map(str::to_string);
    named(dir)
        .or_else(|| dir.canonicalize().ok().as_deref().and_then(named))
        .ok_or_else(|| PerceptionError::Source {
            spec: format!("av2:{}", dir.display()),
            message: "expected a log directory with a name".into(),
        })
}

/// Loads a log with the default [`Av2Options`].
pub fn load(dir: &Path) -> Result<Sequence, PerceptionError> {
    load_with(dir, &Av2Options::default())
}

fn source_err(dir: &Path, message: String) -> PerceptionError {
    PerceptionError::Source {
        spec: format!("av2:{}", dir.display()),
        message,
    }
}

fn file_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || path.display().to_string(),
        |f| f.to_string_lossy().into_owned(),
    )
}

/// Loads a log: annotations into frames and observations, the ego poses
/// at the frames' timestamps when the pose file is there, the map when
/// `map/` holds an archive and the poses are known. What is not read is
/// said in `Sequence::skipped` (a `count` of 0 for a missing file).
pub fn load_with(dir: &Path, options: &Av2Options) -> Result<Sequence, PerceptionError> {
    if !dir.is_dir() {
        return Err(source_err(
            dir,
            format!(
                "no such directory; expected an Argoverse 2 log directory holding {} or {} (and optionally {POSE_FILE} and map/)",
                ANNOTATION_FILES[0], ANNOTATION_FILES[1]
            ),
        ));
    }
    let name = log_name(dir)?;
    let Some(ann_path) = ANNOTATION_FILES
        .iter()
        .map(|f| dir.join(f))
        .find(|p| p.is_file())
    else {
        return Err(source_err(
            dir,
            format!(
                "no annotations: expected {} or {} in the directory",
                ANNOTATION_FILES[0], ANNOTATION_FILES[1]
            ),
        ));
    };
    let ann_file = file_name(&ann_path);
    let Annotations { rows, mut skipped } = read_annotations(&ann_path)?;
    let file_err = |message: String| PerceptionError::File {
        path: ann_path.clone(),
        message,
    };
    if rows.is_empty() {
        return Err(file_err("no readable annotation rows".into()));
    }

    // Frames: every distinct timestamp, the ego's own rows included.
    let timestamps: Vec<i64> = rows
        .iter()
        .map(|r| r.timestamp_ns)
        .collect::<BTreeSet<_>>()
        .into_iter()
        .collect();
    let frame_count = u32::try_from(timestamps.len())
        .map_err(|_| file_err(format!("{} timestamps", timestamps.len())))?;
    check_frame_count("frame_count", frame_count).map_err(file_err)?;

    let mut kept: Vec<&AnnotationRow> = Vec::with_capacity(rows.len());
    for r in &rows {
        let example = || format!("{ann_file} row {}", r.row);
        if r.category == categories::EGO_CATEGORY {
            feather::count_skip(
                &mut skipped,
                "EGO_VEHICLE rows: the ego vehicle is the constant `ego`, not an object".into(),
                example,
            );
            continue;
        }
        if let Some(max) = options.max_range_m {
            let [x, y, _] = r.centre();
            if x.hypot(y) > max {
                feather::count_skip(
                    &mut skipped,
                    format!("beyond max_range_m ({max} m) from the ego"),
                    example,
                );
                continue;
            }
        }
        kept.push(r);
    }

    // Track ids in sorted uuid order: the same log always numbers alike.
    let uuids: BTreeSet<&str> = kept.iter().map(|r| r.track_uuid.as_str()).collect();
    let mut track_of: BTreeMap<&str, u32> = BTreeMap::new();
    let mut track_keys = BTreeMap::new();
    for (i, u) in uuids.into_iter().enumerate() {
        let id = u32::try_from(i).map_err(|_| file_err("more than 2^32 tracks".into()))?;
        track_of.insert(u, id);
        track_keys.insert(id, u.to_string());
    }

    let mut observations = Vec::with_capacity(kept.len());
    let mut rows_of = Vec::with_capacity(kept.len());
    for r in &kept {
        // Both lookups succeed: the maps were built from these rows.
        let (Ok(frame), Some(&track_id)) = (
            timestamps.binary_search(&r.timestamp_ns),
            track_of.get(r.track_uuid.as_str()),
        ) else {
            continue;
        };
        observations.push(observation(r, frame as u32, track_id));
        rows_of.push(r.row);
    }
    // Sort by (frame, track), file order within: the first row of a
    // duplicated (timestamp, track) pair is kept, the others counted.
    let mut order: Vec<usize> = (0..observations.len()).collect();
    order.sort_by_key(|&i| (observations[i].frame, observations[i].track_id, rows_of[i]));
    let mut sorted: Vec<Observation> = Vec::with_capacity(observations.len());
    let mut slots: Vec<Option<Observation>> = observations.into_iter().map(Some).collect();
    for i in order {
        let Some(o) = slots[i].take() else { continue };
        if sorted
            .last()
            .is_some_and(|p| (p.frame, p.track_id) == (o.frame, o.track_id))
        {
            feather::count_skip(
                &mut skipped,
                "duplicate (timestamp_ns, track_uuid) row: the first is kept".into(),
                || format!("{ann_file} row {}", rows_of[i]),
            );
            continue;
        }
        sorted.push(o);
    }
    for run in sorted.chunk_by(|a, b| a.frame == b.frame) {
        if let Some(o) = run.first() {
            check_objects_per_frame(o.frame, run.len()).map_err(|m| {
                file_err(format!(
                    "timestamp_ns {}: {m}",
                    timestamps[o.frame as usize]
                ))
            })?;
        }
    }

    let fps = crate::model::fps_from_timestamps(&timestamps);
    let ego_poses = read_ego_poses(dir, &timestamps, options, &mut skipped)?;
    let map = if ego_poses.is_some() {
        read_log_map(dir, options, &mut skipped)?
    } else {
        if dir.join("map").is_dir() {
            skipped.push(Skipped {
                reason: format!("map/ not read: placing the map needs the ego poses ({POSE_FILE})"),
                count: 0,
                example: dir.join("map").display().to_string(),
            });
        }
        None
    };
    let sequence = Sequence {
        name,
        source: "av2".into(),
        camera: AV2_NOMINAL_CAMERA,
        frame_count,
        fps,
        observations: sorted,
        timestamps_ns: Some(timestamps),
        ego_poses,
        map: map.map(Arc::new),
        track_keys,
        skipped,
    };
    sequence.validate()?;
    Ok(sequence)
}

/// A cuboid as an observation in the camera convention.
fn observation(r: &AnnotationRow, frame: u32, track_id: u32) -> Observation {
    let (class, type_name) = categories::classify(&r.category);
    let [x, y, z] = r.centre();
    let h = r.height_m();
    Observation {
        frame,
        track_id,
        class,
        type_name: Some(type_name),
        color: None,
        bbox: None,
        position: Some([-y, -(z - h / 2.0), x]),
        size: Some([h, r.width_m(), r.length_m()]),
        yaw: Some(vehicle_yaw_to_rotation_y(pose::yaw_of_quaternion(
            r.quaternion(),
        ))),
        confidence: 1.0,
        truncation: None,
        occlusion: None,
        footprint: None,
        depth_source: None,
    }
}

/// The ego's pose at each frame, or `None` (noted in `skipped`) without
/// the pose file.
fn read_ego_poses(
    dir: &Path,
    timestamps: &[i64],
    options: &Av2Options,
    skipped: &mut Vec<Skipped>,
) -> Result<Option<Vec<WorldPose>>, PerceptionError> {
    let path = dir.join(POSE_FILE);
    if !path.is_file() {
        skipped.push(Skipped {
            reason: format!("no {POSE_FILE}: ego motion estimated from the objects"),
            count: 0,
            example: dir.display().to_string(),
        });
        return Ok(None);
    }
    let rows = pose::sorted_poses(read_poses(&path)?, &path)?;
    timestamps
        .iter()
        .map(|&t| pose::pose_at(&rows, t, options.pose_tolerance_ns, &path))
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// The log's map archive, or `None` (noted in `skipped`) without one.
fn read_log_map(
    dir: &Path,
    options: &Av2Options,
    skipped: &mut Vec<Skipped>,
) -> Result<Option<SceneMap>, PerceptionError> {
    if !options.read_map {
        return Ok(None);
    }
    let map_dir = dir.join("map");
    let mut archives: Vec<PathBuf> = match std::fs::read_dir(&map_dir) {
        Ok(entries) => entries
            .filter_map(Result::ok)
            .map(|e| e.path())
            .filter(|p| {
                p.file_name()
                    .and_then(|n| n.to_str())
                    .is_some_and(|n| n.starts_with("log_map_archive_") && n.ends_with(".json"))
            })
            .collect(),
        Err(_) => Vec::new(),
    };
    archives.sort();
    match archives.as_slice() {
        [] => {
            skipped.push(Skipped {
                reason: "no map/log_map_archive_*.json: map facts are unobservable".into(),
                count: 0,
                example: map_dir.display().to_string(),
            });
            Ok(None)
        }
        [one] => read_map_json(one).map(Some),
        many => Err(source_err(
            dir,
            format!(
                "{} map archives in {} ({}); expected one log_map_archive_*.json",
                many.len(),
                map_dir.display(),
                many.iter()
                    .map(|p| file_name(p))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
    }
}

#[cfg(test)]
mod tests;
