//! What a source can observe: the predicates each kind of source cannot
//! support (no map, no colours, a detector's label map, unassigned types),
//! so that asking about them is unknown, never no.

use crate::kb::Observability;
use perception::Sequence;

/// The `TypeOf` values perception knows (`TYPE_VALUES`) that a source
/// whose type names are `assigned` never gives, `Other` aside (the vague
/// value is no claim about a kind): what it cannot see, so that "is there
/// a sedan?" on labels that say only `Car` is unknown, not no.
pub(crate) fn unassigned_types<'a>(
    assigned: impl IntoIterator<Item = &'a str>,
) -> Vec<&'static str> {
    let given: std::collections::BTreeSet<String> = assigned
        .into_iter()
        .map(perception::facts::type_value)
        .collect();
    perception::facts::TYPE_VALUES
        .iter()
        .copied()
        .filter(|v| *v != "Other" && !given.contains(*v))
        .collect()
}

/// Predicates KITTI tracking labels cannot support: they carry no colour,
/// no static scene classes and no support surfaces.
pub const KITTI_UNOBSERVABLE: &[&str] = &[
    "ColorOf",
    "On",
    "Road",
    "Sidewalk",
    "LaneMarking",
    "Pole",
    "TrafficSign",
    "TrafficLight",
    "Building",
    "Vegetation",
    "Fence",
    "Wall",
    "Terrain",
    "ConstructionObj",
    "Other",
];

/// Predicates a frames run with `set` cannot support: `On` (a detector sees
/// no support surfaces) and every class predicate its detector's label map
/// never produces — with the shipped NanoDet config, surfaces and scenery
/// but also `Cyclist`, `Person` and `Misc` (COCO has one `person` class,
/// mapped to `Pedestrian`). Asking about them must be "unknown", not "no".
pub(crate) fn frames_unobservable(set: &perception::raw::frames::ModelSet) -> Vec<&'static str> {
    let seen: std::collections::BTreeSet<&str> = set
        .detector
        .config
        .labels
        .iter()
        .map(|l| l.class.as_str())
        .collect();
    std::iter::once("On")
        .chain(
            perception::raw::config::CLASS_PREDICATES
                .iter()
                .copied()
                .filter(|c| !seen.contains(c)),
        )
        .collect()
}

/// The predicates only a map can support (`Sequence::map`): on a source
/// without one, "is the car on a crosswalk?" is unknown, never no.
pub(crate) const MAP_PREDICATES: &[&str] = &[
    "OnCrosswalk",
    "NearCrosswalk",
    "InDrivableArea",
    "Lane",
    "LaneType",
    "OnLane",
    "InIntersection",
    "NearIntersection",
    "SameLane",
    "Following",
];

/// `obs`, with the map's predicates unobservable when `seq` has no map.
pub(super) fn map_observability(seq: &Sequence, obs: Observability) -> Observability {
    if seq.map.is_some() {
        obs
    } else {
        obs.without(
            MAP_PREDICATES,
            "the source has no map (lanes, crosswalks, drivable areas)",
        )
    }
}

/// `obs` for a sequence that may be a forward camera's or a 360° log's:
/// only a camera (every observation with a pixel box) is blind behind the
/// ego.
pub(super) fn camera_observability(seq: &Sequence, obs: Observability) -> Observability {
    if seq.is_surround() {
        obs
    } else {
        obs.forward_camera()
    }
}

/// What an Argoverse 2 log's annotations cannot tell: colours, scene
/// surfaces and classes it does not annotate, and the `TypeOf` values
/// (body styles, vans) none of its categories names, directly or through
/// the built-in taxonomy (`RegularVehicle` is a `Car`).
pub(super) fn av2_observability() -> Observability {
    let taxonomy = crate::context::Sentences::builtin()
        .supertypes("TypeOf")
        .cloned()
        .unwrap_or_default();
    // Each category's type value and every value above it.
    let mut given: std::collections::BTreeSet<String> = std::collections::BTreeSet::new();
    let mut todo: Vec<String> = perception::av2::categories::CATEGORIES
        .iter()
        .map(|(_, _, t)| perception::facts::type_value(t))
        .collect();
    while let Some(t) = todo.pop() {
        if let Some(ups) = taxonomy.get(&t) {
            todo.extend(ups.iter().filter(|u| !given.contains(*u)).cloned());
        }
        given.insert(t);
    }
    Observability::everything()
        .without(
            &av2_unobservable(),
            "Argoverse 2 annotations carry no colours, scene surfaces or such classes",
        )
        .without_type_values(
            &unassigned_types(given.iter().map(String::as_str)),
            "no Argoverse 2 category is of this type (AV2 tells no car body styles)",
        )
}

/// What Argoverse 2 annotations support that KITTI labels do not: static
/// classes — bollards (`Pole`), signs (`TrafficSign`), cones and barrels
/// (`ConstructionObj`) — and `Other` (an unknown category keeps its own
/// type). The rest of [`KITTI_UNOBSERVABLE`] holds for both: no colours,
/// no support surfaces, no other static classes; the road's layout is the
/// map's (`MAP_PREDICATES`).
const AV2_OBSERVES: &[&str] = &["Pole", "TrafficSign", "ConstructionObj", "Other"];

/// Predicates Argoverse 2 annotations cannot support, in
/// [`KITTI_UNOBSERVABLE`]'s order.
pub(crate) fn av2_unobservable() -> Vec<&'static str> {
    KITTI_UNOBSERVABLE
        .iter()
        .copied()
        .filter(|p| !AV2_OBSERVES.contains(p))
        .collect()
}
