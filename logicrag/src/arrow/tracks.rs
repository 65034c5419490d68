//! The *tracks schema*: object tracks from any dataset as an Arrow table
//! (one row per object and frame), read into a [`Sequence`] — what a
//! nuScenes, Waymo or Argoverse 2 user fills with a few lines of pandas or
//! polars (Python's `Engine.open_tracks`). docs/formats.md documents the
//! columns.
//!
//! Positions are in the **ego frame** of their frame (x forward, y left,
//! z up, metres: Argoverse 2's convention), the centre of the object's
//! box; `yaw` is counter-clockwise from `x`. They become observations
//! without a pixel box exactly as the `av2:` reader makes them: camera
//! convention `X = −y`, `Y = −(z − h/2)` (the bottom centre), `Z = x`,
//! `rotation_y` by [`perception::coords::vehicle_yaw_to_rotation_y`], so a
//! log converted by hand gives the `av2:` source's facts.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::sync::Arc;

use arrow_array::cast::AsArray;
use arrow_array::types::{Float32Type, Float64Type, Int32Type, Int64Type};
use arrow_array::{Array, RecordBatch};
use arrow_schema::DataType;
use perception::PerceptionError;
use perception::av2::categories;
use perception::model::{
    ObjectClass, Observation, SceneMap, Sequence, Skipped, WorldPose, check_frame_count,
    check_objects_per_frame,
};

/// The source kind of a sequence read from a tracks table: its label is
/// `tracks:<name>`.
pub const TRACKS_SOURCE: &str = "tracks";

/// How far (ns) a frame's timestamp may lie outside the pose table's and
/// still take its nearest pose (the `av2:` reader's default: 50 ms).
pub const POSE_TOLERANCE_NS: i64 = 50_000_000;

/// Errors of reading a tracks (or ego-pose) table.
#[derive(Debug, thiserror::Error)]
pub enum TracksError {
    /// Occurs when a table lacks a required column.
    #[error("{table} table: no column `{column}` ({what})")]
    MissingColumn {
        /// `tracks` or `poses`.
        table: &'static str,
        /// The column.
        column: String,
        /// What it holds.
        what: String,
    },
    /// Occurs when a column has a type the schema does not allow.
    #[error("{table} table: column `{column}` is {found}, expected {expected}")]
    ColumnType {
        /// `tracks` or `poses`.
        table: &'static str,
        /// The column.
        column: String,
        /// Its Arrow type.
        found: String,
        /// The types allowed.
        expected: String,
    },
    /// Occurs when a value is null, not finite, out of range or unknown;
    /// `row` counts from 0 over the whole table (all batches in order).
    #[error("{table} table row {row}: `{column}` {message}")]
    Value {
        /// `tracks` or `poses`.
        table: &'static str,
        /// The row.
        row: usize,
        /// The column.
        column: String,
        /// What is wrong.
        message: String,
    },
    /// Occurs when the table as a whole is unusable (no rows, the frames
    /// without their poses, too many frames or objects in one frame).
    #[error("{table} table: {message}")]
    Table {
        /// `tracks` or `poses`.
        table: &'static str,
        /// What is wrong.
        message: String,
    },
    /// Occurs when the assembled sequence breaks an invariant of
    /// [`Sequence::validate`] (a map without ego poses), or a map file
    /// cannot be read.
    #[error(transparent)]
    Perception(#[from] PerceptionError),
}

const TRACKS: &str = "tracks";
const POSES: &str = "poses";

/// One column of one batch, typed.
enum Column<'a> {
    Int(&'a dyn Array, bool),
    Float(&'a dyn Array, bool),
    Str(&'a dyn Array),
}

fn column<'a>(
    table: &'static str,
    batch: &'a RecordBatch,
    name: &str,
    what: &str,
    required: bool,
) -> Result<Option<&'a dyn Array>, TracksError> {
    match batch.column_by_name(name) {
        Some(c) => Ok(Some(c.as_ref())),
        None if required => Err(TracksError::MissingColumn {
            table,
            column: name.to_string(),
            what: what.to_string(),
        }),
        None => Ok(None),
    }
}

fn type_err(table: &'static str, name: &str, found: &DataType, expected: &str) -> TracksError {
    TracksError::ColumnType {
        table,
        column: name.to_string(),
        found: found.to_string(),
        expected: expected.to_string(),
    }
}

fn typed<'a>(
    table: &'static str,
    name: &str,
    array: &'a dyn Array,
    want: &str,
) -> Result<Column<'a>, TracksError> {
    let t = array.data_type();
    let int = matches!(t, DataType::Int64 | DataType::Int32);
    let float = matches!(t, DataType::Float64 | DataType::Float32);
    let text = matches!(t, DataType::Utf8 | DataType::LargeUtf8 | DataType::Utf8View);
    let c = match want {
        // Integer positions (a synthetic table) read as floats.
        "float64" if float => Column::Float(array, *t == DataType::Float64),
        "float64" | "int64" | "id" if int => Column::Int(array, *t == DataType::Int64),
        "utf8" | "id" if text => Column::Str(array),
        _ => {
            let expected = match want {
                "float64" => "float64 (or float32, int64)",
                "int64" => "int64 (or int32)",
                "utf8" => "utf8 (string, large_string or string_view)",
                _ => "int64 or utf8",
            };
            return Err(type_err(table, name, t, expected));
        }
    };
    Ok(c)
}

impl Column<'_> {
    fn is_null(&self, i: usize) -> bool {
        match self {
            Column::Int(a, _) | Column::Float(a, _) | Column::Str(a) => a.is_null(i),
        }
    }

    fn int(&self, i: usize) -> Option<i64> {
        match self {
            Column::Int(a, true) => a.as_primitive_opt::<Int64Type>().map(|a| a.value(i)),
            Column::Int(a, false) => a
                .as_primitive_opt::<Int32Type>()
                .map(|a| i64::from(a.value(i))),
            _ => None,
        }
    }

    fn float(&self, i: usize) -> Option<f64> {
        match self {
            Column::Float(a, true) => a.as_primitive_opt::<Float64Type>().map(|a| a.value(i)),
            Column::Float(a, false) => a
                .as_primitive_opt::<Float32Type>()
                .map(|a| f64::from(a.value(i))),
            Column::Int(..) => self.int(i).map(|v| v as f64),
            Column::Str(_) => None,
        }
    }

    fn str(&self, i: usize) -> Option<&str> {
        match self {
            Column::Str(a) => match a.data_type() {
                DataType::Utf8 => a.as_string_opt::<i32>().map(|s| s.value(i)),
                DataType::LargeUtf8 => a.as_string_opt::<i64>().map(|s| s.value(i)),
                DataType::Utf8View => a.as_string_view_opt().map(|s| s.value(i)),
                _ => None,
            },
            _ => None,
        }
    }
}

/// A batch's columns by name, with the table's row offset for errors.
struct Cols<'a> {
    table: &'static str,
    base: usize,
    cols: BTreeMap<&'static str, Column<'a>>,
}

impl<'a> Cols<'a> {
    fn new(table: &'static str, base: usize) -> Cols<'a> {
        Cols {
            table,
            base,
            cols: BTreeMap::new(),
        }
    }

    fn add(
        &mut self,
        batch: &'a RecordBatch,
        name: &'static str,
        want: &str,
        what: &str,
        required: bool,
    ) -> Result<bool, TracksError> {
        match column(self.table, batch, name, what, required)? {
            Some(a) => {
                self.cols.insert(name, typed(self.table, name, a, want)?);
                Ok(true)
            }
            None => Ok(false),
        }
    }

    fn err(&self, i: usize, name: &str, message: impl Into<String>) -> TracksError {
        TracksError::Value {
            table: self.table,
            row: self.base + i,
            column: name.to_string(),
            message: message.into(),
        }
    }

    fn get(&self, name: &str) -> Option<&Column<'a>> {
        self.cols.get(name)
    }

    /// A required value: an error names a null.
    fn present(&self, i: usize, name: &str) -> Result<&Column<'a>, TracksError> {
        match self.get(name) {
            Some(c) if c.is_null(i) => Err(self.err(i, name, "is null")),
            Some(c) => Ok(c),
            None => Err(self.err(i, name, "is missing")),
        }
    }

    fn int(&self, i: usize, name: &str) -> Result<i64, TracksError> {
        self.present(i, name)?
            .int(i)
            .ok_or_else(|| self.err(i, name, "is not an integer"))
    }

    fn finite(&self, i: usize, name: &str) -> Result<f64, TracksError> {
        let v = self
            .present(i, name)?
            .float(i)
            .ok_or_else(|| self.err(i, name, "is not a number"))?;
        if v.is_finite() {
            Ok(v)
        } else {
            Err(self.err(i, name, format!("is {v}, not a finite number")))
        }
    }

    fn positive(&self, i: usize, name: &str) -> Result<f64, TracksError> {
        let v = self.finite(i, name)?;
        if v > 0.0 {
            Ok(v)
        } else {
            Err(self.err(i, name, format!("is {v}: sizes must be positive (metres)")))
        }
    }

    fn optional_str(&self, i: usize, name: &str) -> Option<&str> {
        self.get(name)
            .filter(|c| !c.is_null(i))
            .and_then(|c| c.str(i))
    }
}

/// When a row was taken: its frame number or its timestamp.
#[derive(Clone, Copy, PartialEq, Eq)]
enum TimeKey {
    Frame,
    Timestamp,
}

/// A track's id as the table gives it.
#[derive(Clone, PartialEq, Eq, PartialOrd, Ord)]
enum TrackKey {
    Int(u32),
    Str(String),
}

/// One tracks row, read and checked.
struct Row {
    row: usize,
    time: i64,
    track: TrackKey,
    category: String,
    centre: [f64; 3],
    lwh: [f64; 3],
    yaw: f64,
    color: Option<String>,
    score: Option<f64>,
}

/// Which time column a batch uses: `frame` or `timestamp_ns`, never both.
fn time_key(table: &'static str, batch: &RecordBatch) -> Result<TimeKey, TracksError> {
    let has = |c: &str| batch.column_by_name(c).is_some();
    match (has("frame"), has("timestamp_ns")) {
        (true, false) => Ok(TimeKey::Frame),
        (false, true) => Ok(TimeKey::Timestamp),
        (true, true) => Err(TracksError::Table {
            table,
            message: "both `frame` and `timestamp_ns` columns: give one (frames are numbered from `frame`, or are the sorted distinct `timestamp_ns` values)".into(),
        }),
        (false, false) => Err(TracksError::MissingColumn {
            table,
            column: "frame".into(),
            what: "or `timestamp_ns`: when each row was seen".into(),
        }),
    }
}

fn read_rows(batches: &[RecordBatch]) -> Result<(TimeKey, Vec<Row>), TracksError> {
    let mut rows = Vec::new();
    let mut key: Option<TimeKey> = None;
    let mut base = 0;
    for batch in batches {
        let k = time_key(TRACKS, batch)?;
        if key.is_some_and(|prev| prev != k) {
            return Err(TracksError::Table {
                table: TRACKS,
                message: "batches differ in their time column (`frame` or `timestamp_ns`)".into(),
            });
        }
        key = Some(k);
        let time_col = match k {
            TimeKey::Frame => "frame",
            TimeKey::Timestamp => "timestamp_ns",
        };
        let mut c = Cols::new(TRACKS, base);
        c.add(batch, time_col, "int64", "when the row was seen", true)?;
        c.add(batch, "track_id", "id", "the object's track id", true)?;
        c.add(
            batch,
            "category",
            "utf8",
            "the object's class or type",
            true,
        )?;
        for (name, what) in [
            ("x", "centre, metres forward of the ego"),
            ("y", "centre, metres left of the ego"),
            ("z", "centre, metres above the ego's origin"),
            ("length", "metres"),
            ("width", "metres"),
            ("height", "metres"),
            ("yaw", "radians, counter-clockwise from the ego's x axis"),
        ] {
            c.add(batch, name, "float64", what, true)?;
        }
        c.add(batch, "color", "utf8", "", false)?;
        c.add(batch, "score", "float64", "", false)?;
        for i in 0..batch.num_rows() {
            let time = c.int(i, time_col)?;
            if k == TimeKey::Frame && !(0..i64::from(perception::model::MAX_FRAMES)).contains(&time)
            {
                return Err(c.err(
                    i,
                    "frame",
                    format!(
                        "is {time}: frames are numbered 0 to {} (below perception::MAX_FRAMES)",
                        perception::model::MAX_FRAMES - 1
                    ),
                ));
            }
            let id = c.present(i, "track_id")?;
            let track = match id.str(i) {
                Some("") => return Err(c.err(i, "track_id", "is empty")),
                Some(s) => TrackKey::Str(s.to_string()),
                None => {
                    let v = c.int(i, "track_id")?;
                    TrackKey::Int(u32::try_from(v).map_err(|_| {
                        c.err(
                            i,
                            "track_id",
                            format!("is {v}: integer ids are 0 to {}", u32::MAX),
                        )
                    })?)
                }
            };
            let category = c
                .present(i, "category")?
                .str(i)
                .unwrap_or_default()
                .to_string();
            let centre = [c.finite(i, "x")?, c.finite(i, "y")?, c.finite(i, "z")?];
            let lwh = [
                c.positive(i, "length")?,
                c.positive(i, "width")?,
                c.positive(i, "height")?,
            ];
            let yaw = c.finite(i, "yaw")?;
            let color = match c.optional_str(i, "color") {
                None => None,
                Some(v) => Some(
                    perception::facts::COLOR_VALUES
                        .iter()
                        .find(|k| k.eq_ignore_ascii_case(v))
                        .map(|k| (*k).to_string())
                        .ok_or_else(|| {
                            c.err(
                                i,
                                "color",
                                format!(
                                    "`{v}` is not a colour of the vocabulary ({})",
                                    perception::facts::COLOR_VALUES.join(", ")
                                ),
                            )
                        })?,
                ),
            };
            let score = match c.get("score").filter(|s| !s.is_null(i)) {
                None => None,
                Some(_) => {
                    let s = c.finite(i, "score")?;
                    if !(0.0..=1.0).contains(&s) {
                        return Err(c.err(i, "score", format!("is {s}, not in [0, 1]")));
                    }
                    Some(s)
                }
            };
            rows.push(Row {
                row: base + i,
                time,
                track,
                category,
                centre,
                lwh,
                yaw,
                color,
                score,
            });
        }
        base += batch.num_rows();
    }
    let key = key.ok_or_else(|| TracksError::Table {
        table: TRACKS,
        message: "no batches".into(),
    })?;
    Ok((key, rows))
}

/// `TypeOf` values of this project's own sources (KITTI, the simulator)
/// that name a motor vehicle.
const VEHICLE_TYPES: [&str; 15] = [
    "Car",
    "Van",
    "Truck",
    "Tram",
    "Bus",
    "Motorcycle",
    "SUV",
    "Sedan",
    "Coupe",
    "Hatchback",
    "Wagon",
    "Minivan",
    "Cab",
    "Convertible",
    "PoliceCar",
];

/// A row's class and `TypeOf` value: an Argoverse 2 category
/// (`REGULAR_VEHICLE`, any case) or its CamelCase value (`RegularVehicle`)
/// as the `av2:` reader maps it; one of this project's types (`Car`,
/// `Pedestrian`, `Cyclist`, `Bicycle`, KITTI's `Misc` and
/// `Person_sitting`); a class predicate (`Vehicles`, `Pole`) as a class
/// without a type. Anything else is kept as class `Other` with the
/// category in CamelCase, as the `av2:` reader keeps an unknown category.
pub fn category_class(category: &str) -> (ObjectClass, Option<String>) {
    let upper = category.to_ascii_uppercase();
    if let Some((_, class, t)) = categories::CATEGORIES
        .iter()
        .find(|(c, _, t)| *c == upper || t.eq_ignore_ascii_case(category))
    {
        return (*class, Some((*t).to_string()));
    }
    let own = |list: &[&str]| {
        list.iter()
            .find(|t| t.eq_ignore_ascii_case(category))
            .map(|t| (*t).to_string())
    };
    if let Some(t) = own(&VEHICLE_TYPES) {
        return (ObjectClass::Vehicle, Some(t));
    }
    for (t, class) in [
        ("Pedestrian", ObjectClass::Pedestrian),
        ("Cyclist", ObjectClass::Cyclist),
        ("Bicycle", ObjectClass::Misc),
        ("Misc", ObjectClass::Misc),
        ("Person_sitting", ObjectClass::Person),
    ] {
        if t.eq_ignore_ascii_case(category) {
            return (class, Some(t.to_string()));
        }
    }
    if let Some(class) = ObjectClass::ALL
        .iter()
        .find(|c| c.predicate().eq_ignore_ascii_case(category))
    {
        return (*class, None);
    }
    let (class, t) = categories::classify(category);
    (class, Some(t))
}

/// Reads a tracks table (and optionally an ego-pose table and a map) into
/// a sequence named `name` (label `tracks:<name>`).
///
/// Frames: the `frame` column, or the sorted distinct `timestamp_ns`
/// values. Tracks: integer `track_id`s are the ids; string ids (a uuid,
/// a nuScenes instance token) are numbered in sorted order and kept as
/// track keys (objects are then named `car_0f3c9a1e`). `EGO_VEHICLE`
/// rows are the ego, counted in `skipped`; a repeated (frame, track) row
/// is counted there too, the first kept. `poses`: one row per frame
/// (`frame`), or rows at any timestamps (`timestamp_ns`, interpolated at
/// the frames'); a `map` needs them.
pub fn tracks_from_batches(
    name: &str,
    batches: &[RecordBatch],
    poses: Option<&[RecordBatch]>,
    map: Option<SceneMap>,
) -> Result<Sequence, TracksError> {
    let table_err = |message: String| TracksError::Table {
        table: TRACKS,
        message,
    };
    let (key, rows) = read_rows(batches)?;
    if rows.is_empty() {
        return Err(table_err("no rows".into()));
    }
    // Frames: as given, or every distinct timestamp (the ego's own rows
    // included, as the `av2:` reader counts them).
    let timestamps: Option<Vec<i64>> = (key == TimeKey::Timestamp).then(|| {
        rows.iter()
            .map(|r| r.time)
            .collect::<BTreeSet<_>>()
            .into_iter()
            .collect()
    });
    let frame_of = |t: i64| -> u32 {
        match &timestamps {
            Some(ts) => ts.binary_search(&t).map_or(0, |f| f as u32),
            // Checked below MAX_FRAMES when read.
            None => t as u32,
        }
    };
    let frame_count = match &timestamps {
        Some(ts) => u32::try_from(ts.len()).unwrap_or(u32::MAX),
        None => rows
            .iter()
            .map(|r| frame_of(r.time).saturating_add(1))
            .max()
            .unwrap_or(0),
    };
    check_frame_count("frame_count", frame_count).map_err(table_err)?;

    let mut skipped: Vec<Skipped> = Vec::new();
    let mut skip = |reason: &str, row: usize| {
        if let Some(s) = skipped.iter_mut().find(|s| s.reason == reason) {
            s.count += 1;
        } else {
            skipped.push(Skipped {
                reason: reason.to_string(),
                count: 1,
                example: format!("tracks table row {row}"),
            });
        }
    };
    let kept: Vec<&Row> = rows
        .iter()
        .filter(|r| {
            let ego = r.category.eq_ignore_ascii_case(categories::EGO_CATEGORY);
            if ego {
                skip(
                    "EGO_VEHICLE rows: the ego vehicle is the constant `ego`, not an object",
                    r.row,
                );
            }
            !ego
        })
        .collect();

    // String ids in sorted order: the same table always numbers alike.
    let mut track_keys = BTreeMap::new();
    let mut id_of: BTreeMap<&TrackKey, u32> = BTreeMap::new();
    let keys: BTreeSet<&TrackKey> = kept.iter().map(|r| &r.track).collect();
    let mut strings = 0u32;
    for k in keys {
        match k {
            TrackKey::Int(id) => {
                id_of.insert(k, *id);
            }
            TrackKey::Str(s) => {
                id_of.insert(k, strings);
                track_keys.insert(strings, s.clone());
                strings = strings
                    .checked_add(1)
                    .ok_or_else(|| table_err("more than 2^32 tracks".into()))?;
            }
        }
    }
    if !track_keys.is_empty() && track_keys.len() != id_of.len() {
        return Err(table_err(
            "batches mix integer and string `track_id`s: use one type".into(),
        ));
    }

    let mut obs: Vec<(Observation, usize)> = kept
        .iter()
        .map(|r| {
            let (class, type_name) = category_class(&r.category);
            let [x, y, z] = r.centre;
            let [l, w, h] = r.lwh;
            let o = Observation {
                frame: frame_of(r.time),
                track_id: id_of.get(&r.track).copied().unwrap_or_default(),
                class,
                type_name,
                color: r.color.clone(),
                bbox: None,
                position: Some([-y, -(z - h / 2.0), x]),
                size: Some([h, w, l]),
                yaw: Some(perception::coords::vehicle_yaw_to_rotation_y(r.yaw)),
                confidence: r.score.unwrap_or(1.0) as f32,
                truncation: None,
                occlusion: None,
                footprint: None,
                depth_source: None,
            };
            (o, r.row)
        })
        .collect();
    obs.sort_by_key(|(o, row)| (o.frame, o.track_id, *row));
    let mut observations: Vec<Observation> = Vec::with_capacity(obs.len());
    for (o, row) in obs {
        if observations
            .last()
            .is_some_and(|p| (p.frame, p.track_id) == (o.frame, o.track_id))
        {
            skip("a repeated (frame, track_id) row: the first is kept", row);
            continue;
        }
        observations.push(o);
    }
    for run in observations.chunk_by(|a, b| a.frame == b.frame) {
        if let Some(o) = run.first() {
            check_objects_per_frame(o.frame, run.len()).map_err(table_err)?;
        }
    }

    let ego_poses = match poses {
        None => None,
        Some(p) => Some(read_poses(p, frame_count, timestamps.as_deref())?),
    };
    let fps = timestamps.as_deref().map_or(
        perception::model::DEFAULT_FPS,
        perception::model::fps_from_timestamps,
    );
    let seq = Sequence {
        name: name.to_string(),
        source: TRACKS_SOURCE.into(),
        camera: perception::json::DEFAULT_CAMERA,
        frame_count,
        fps,
        observations,
        timestamps_ns: timestamps,
        ego_poses,
        map: map.map(Arc::new),
        track_keys,
        skipped,
    };
    seq.validate()?;
    Ok(seq)
}

/// The ego pose of every frame from the pose table: keyed by `frame` (one
/// row per frame) or by `timestamp_ns` (interpolated at the frames').
fn read_poses(
    batches: &[RecordBatch],
    frame_count: u32,
    frame_times: Option<&[i64]>,
) -> Result<Vec<WorldPose>, TracksError> {
    let mut rows: Vec<(i64, usize, WorldPose)> = Vec::new();
    let mut key = None;
    let mut base = 0;
    for batch in batches {
        let k = time_key(POSES, batch)?;
        key = Some(k);
        let time_col = match k {
            TimeKey::Frame => "frame",
            TimeKey::Timestamp => "timestamp_ns",
        };
        let mut c = Cols::new(POSES, base);
        c.add(batch, time_col, "int64", "when the pose was taken", true)?;
        for name in ["x", "y", "yaw"] {
            c.add(batch, name, "float64", "the ego's world pose", true)?;
        }
        let has_z = c.add(batch, "z", "float64", "", false)?;
        for i in 0..batch.num_rows() {
            let pose = WorldPose {
                x: c.finite(i, "x")?,
                y: c.finite(i, "y")?,
                // No `z` (or a null one): on the ground plane.
                z: match c.get("z") {
                    Some(z) if has_z && !z.is_null(i) => c.finite(i, "z")?,
                    _ => 0.0,
                },
                yaw: c.finite(i, "yaw")?,
            };
            rows.push((c.int(i, time_col)?, base + i, pose));
        }
        base += batch.num_rows();
    }
    let err = |message: String| TracksError::Table {
        table: POSES,
        message,
    };
    rows.sort_by_key(|(t, row, _)| (*t, *row));
    if let Some(w) = rows.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(TracksError::Value {
            table: POSES,
            row: w[1].1,
            column: time_col_name(key).into(),
            message: format!("{} appears twice (also row {})", w[0].0, w[0].1),
        });
    }
    match (key, frame_times) {
        (None, _) => Err(err("no batches".into())),
        (Some(TimeKey::Frame), _) => (0..frame_count)
            .map(|f| {
                rows.binary_search_by_key(&i64::from(f), |r| r.0)
                    .map(|i| rows[i].2)
                    .map_err(|_| err(format!("no pose for frame {f} (one row per frame 0..{frame_count} is needed)")))
            })
            .collect(),
        (Some(TimeKey::Timestamp), None) => Err(err(
            "poses keyed by `timestamp_ns` need tracks keyed by `timestamp_ns` (or give the poses a `frame` column)".into(),
        )),
        (Some(TimeKey::Timestamp), Some(times)) => {
            times.iter().map(|&t| pose_at(&rows, t).map_err(err)).collect()
        }
    }
}

fn time_col_name(key: Option<TimeKey>) -> &'static str {
    match key {
        Some(TimeKey::Frame) => "frame",
        _ => "timestamp_ns",
    }
}

/// The pose at `t` by the `av2:` reader's rule ([`WorldPose::interpolate`],
/// up to [`POSE_TOLERANCE_NS`] outside the rows the nearest end row).
fn pose_at(rows: &[(i64, usize, WorldPose)], t: i64) -> Result<WorldPose, String> {
    let poses: Vec<(i64, WorldPose)> = rows.iter().map(|r| (r.0, r.2)).collect();
    WorldPose::interpolate(&poses, t, POSE_TOLERANCE_NS).map_err(|m| format!("the frame at {m}"))
}

/// Reads a map file: an Argoverse 2 map archive (`log_map_archive_*.json`,
/// an object with `lane_segments`) or a [`SceneMap`] in this project's
/// JSON (`lanes`, `crosswalks`, `drivable_areas`, as in a
/// `logicrag-tracks/2` file). The map's origin is the path.
pub fn read_map(path: &Path) -> Result<SceneMap, PerceptionError> {
    let text =
        perception::textfile::read_text_file(path).map_err(|e| PerceptionError::io(path, e))?;
    let origin = path.display().to_string();
    if text.contains("\"lane_segments\"") {
        return perception::av2::parse_map_json(&text, &origin);
    }
    let json_err = |message: String| PerceptionError::Json {
        origin: origin.clone(),
        message,
    };
    let mut map: SceneMap = serde_json::from_str(&text).map_err(|e| {
        json_err(format!(
            "{e} (expected an Argoverse 2 map archive with `lane_segments`, or a map with `lanes`, `crosswalks` and `drivable_areas`)"
        ))
    })?;
    map.validate().map_err(json_err)?;
    if map.origin.is_empty() {
        map.origin = origin;
    }
    Ok(map)
}

#[cfg(test)]
mod tests;
