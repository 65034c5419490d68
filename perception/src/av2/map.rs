//! The vector map of an AV2 log (`map/log_map_archive_*.json`): lane
//! segments, pedestrian crossings and drivable areas in the city frame.
//!
//! The file is three objects keyed by element id:
//! `lane_segments` (`id`, `lane_type` `VEHICLE|BUS|BIKE`, `is_intersection`,
//! `left_lane_boundary`/`right_lane_boundary` as lists of `{x, y, z}`,
//! `successors`, `predecessors`, `left_neighbor_id`, `right_neighbor_id`),
//! `pedestrian_crossings` (`id`, `edge1`, `edge2`: two polylines along the
//! crossing's long sides) and `drivable_areas` (`id`, `area_boundary`).
//! Other fields (lane mark types) are ignored. Elements come out sorted by
//! id, whatever the file's key order.

use std::collections::BTreeMap;
use std::path::Path;

use serde::Deserialize;

use crate::error::PerceptionError;
use crate::model::{LaneKind, MapArea, MapLane, SceneMap};

#[derive(Deserialize)]
struct MapFile {
    lane_segments: BTreeMap<String, LaneSegment>,
    pedestrian_crossings: BTreeMap<String, Crossing>,
    drivable_areas: BTreeMap<String, DrivableArea>,
}

#[derive(Deserialize)]
struct Point {
    x: f64,
    y: f64,
}

#[derive(Deserialize)]
enum LaneType {
    #[serde(rename = "VEHICLE")]
    Vehicle,
    #[serde(rename = "BUS")]
    Bus,
    #[serde(rename = "BIKE")]
    Bike,
}

#[derive(Deserialize)]
struct LaneSegment {
    id: i64,
    lane_type: LaneType,
    #[serde(default)]
    is_intersection: bool,
    left_lane_boundary: Vec<Point>,
    right_lane_boundary: Vec<Point>,
    #[serde(default)]
    successors: Vec<i64>,
    #[serde(default)]
    predecessors: Vec<i64>,
    #[serde(default)]
    left_neighbor_id: Option<i64>,
    #[serde(default)]
    right_neighbor_id: Option<i64>,
}

#[derive(Deserialize)]
struct Crossing {
    id: i64,
    edge1: Vec<Point>,
    edge2: Vec<Point>,
}

#[derive(Deserialize)]
struct DrivableArea {
    id: i64,
    area_boundary: Vec<Point>,
}

fn xy(points: &[Point]) -> Vec<[f64; 2]> {
    points.iter().map(|p| [p.x, p.y]).collect()
}

/// Reads an AV2 map archive; the map's `origin` is the path.
pub fn read_map_json(path: &Path) -> Result<SceneMap, PerceptionError> {
    let text = std::fs::read_to_string(path).map_err(|e| PerceptionError::io(path, e))?;
    parse_map_json(&text, &path.display().to_string())
}

/// Parses an AV2 map archive held in memory; `origin` names it in errors
/// and becomes the map's `origin`. A document of another shape is a
/// [`PerceptionError::Json`] with the line and column and what was
/// expected; a map breaking [`SceneMap::validate`] (a lane boundary of one
/// point, a crossing edge missing) names the element.
pub fn parse_map_json(text: &str, origin: &str) -> Result<SceneMap, PerceptionError> {
    let json_err = |message: String| PerceptionError::Json {
        origin: origin.to_string(),
        message,
    };
    let file: MapFile = serde_json::from_str(text).map_err(|e| {
        json_err(format!(
            "{e} (expected an Argoverse 2 map archive: an object with `lane_segments`, `pedestrian_crossings` and `drivable_areas`, each keyed by element id)"
        ))
    })?;
    let mut lanes: Vec<MapLane> = file
        .lane_segments
        .into_values()
        .map(|l| MapLane {
            id: l.id,
            kind: match l.lane_type {
                LaneType::Vehicle => LaneKind::Vehicle,
                LaneType::Bus => LaneKind::Bus,
                LaneType::Bike => LaneKind::Bike,
            },
            is_intersection: l.is_intersection,
            left_boundary: xy(&l.left_lane_boundary),
            right_boundary: xy(&l.right_lane_boundary),
            successors: l.successors,
            predecessors: l.predecessors,
            left_neighbor: l.left_neighbor_id,
            right_neighbor: l.right_neighbor_id,
        })
        .collect();
    lanes.sort_by_key(|l| l.id);
    let mut crosswalks: Vec<MapArea> = file
        .pedestrian_crossings
        .into_values()
        .map(|c| {
            // Both edges run the same way along the crossing: one edge and
            // the other reversed walk its outline.
            let mut polygon = xy(&c.edge1);
            polygon.extend(xy(&c.edge2).into_iter().rev());
            MapArea { id: c.id, polygon }
        })
        .collect();
    crosswalks.sort_by_key(|a| a.id);
    let mut drivable_areas: Vec<MapArea> = file
        .drivable_areas
        .into_values()
        .map(|a| MapArea {
            id: a.id,
            polygon: xy(&a.area_boundary),
        })
        .collect();
    drivable_areas.sort_by_key(|a| a.id);
    let map = SceneMap {
        origin: origin.to_string(),
        lanes,
        crosswalks,
        drivable_areas,
    };
    map.validate().map_err(json_err)?;
    Ok(map)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = r#"{
      "lane_segments": {"7": {"id": 7, "is_intersection": true, "lane_type": "BUS",
          "left_lane_boundary": [{"x": 0, "y": 2, "z": 0}, {"x": 10, "y": 2, "z": 0}],
          "right_lane_boundary": [{"x": 0, "y": -2, "z": 0}, {"x": 10, "y": -2, "z": 0}],
          "left_lane_mark_type": "SOLID_WHITE", "successors": [8], "predecessors": [],
          "left_neighbor_id": null, "right_neighbor_id": 9}},
      "pedestrian_crossings": {"3": {"id": 3,
          "edge1": [{"x": 0, "y": 0, "z": 0}, {"x": 0, "y": 5, "z": 0}],
          "edge2": [{"x": 2, "y": 0, "z": 0}, {"x": 2, "y": 5, "z": 0}]}},
      "drivable_areas": {"1": {"id": 1, "area_boundary": [{"x": 0, "y": 0, "z": 0},
          {"x": 1, "y": 0, "z": 0}, {"x": 1, "y": 1, "z": 0}]}}
    }"#;

    #[test]
    fn reads_the_three_layers() {
        let m = parse_map_json(SMALL, "m.json").unwrap();
        assert_eq!(m.origin, "m.json");
        let l = &m.lanes[0];
        assert_eq!((l.id, l.kind, l.is_intersection), (7, LaneKind::Bus, true));
        assert_eq!(
            (l.successors.clone(), l.left_neighbor, l.right_neighbor),
            (vec![8], None, Some(9))
        );
        // edge1, then edge2 reversed: a simple quadrilateral.
        assert_eq!(
            m.crosswalks[0].polygon,
            vec![[0.0, 0.0], [0.0, 5.0], [2.0, 5.0], [2.0, 0.0]]
        );
        assert_eq!(m.drivable_areas[0].polygon.len(), 3);
    }

    #[test]
    fn wrong_shape_names_the_file_the_place_and_the_expectation() {
        let e = parse_map_json(r#"{"lane_segments": []}"#, "bad.json")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("bad.json: ")
                && e.contains("line 1")
                && e.contains("keyed by element id"),
            "{e}"
        );
        let e = parse_map_json(&SMALL.replace("\"BUS\"", "\"TRAM\""), "m.json")
            .unwrap_err()
            .to_string();
        assert!(e.contains("TRAM") && e.contains("line"), "{e}");
    }

    #[test]
    fn an_invalid_element_is_named() {
        let text = SMALL.replace(r#"{"x": 2, "y": 0, "z": 0}, {"x": 2, "y": 5, "z": 0}"#, "");
        let e = parse_map_json(&text, "m.json").unwrap_err().to_string();
        assert!(e.contains("pedestrian crossing 3"), "{e}");
    }
}
