//! AV2 annotation categories → object class and `TypeOf` value.

use crate::model::ObjectClass;

/// The ego vehicle's category: its rows are the ego (constant `ego`), not
/// an object.
pub const EGO_CATEGORY: &str = "EGO_VEHICLE";

/// Every AV2 category this reader knows, with its class and `TypeOf` value
/// (the category in CamelCase; each is in [`crate::facts::TYPE_VALUES`]).
pub const CATEGORIES: [(&str, ObjectClass, &str); 30] = [
    ("REGULAR_VEHICLE", ObjectClass::Vehicle, "RegularVehicle"),
    ("LARGE_VEHICLE", ObjectClass::Vehicle, "LargeVehicle"),
    ("BUS", ObjectClass::Vehicle, "Bus"),
    ("SCHOOL_BUS", ObjectClass::Vehicle, "SchoolBus"),
    ("ARTICULATED_BUS", ObjectClass::Vehicle, "ArticulatedBus"),
    ("BOX_TRUCK", ObjectClass::Vehicle, "BoxTruck"),
    ("TRUCK", ObjectClass::Vehicle, "Truck"),
    ("TRUCK_CAB", ObjectClass::Vehicle, "TruckCab"),
    (
        "VEHICULAR_TRAILER",
        ObjectClass::Vehicle,
        "VehicularTrailer",
    ),
    ("RAILED_VEHICLE", ObjectClass::Vehicle, "RailedVehicle"),
    ("MOTORCYCLE", ObjectClass::Vehicle, "Motorcycle"),
    ("PEDESTRIAN", ObjectClass::Pedestrian, "Pedestrian"),
    (
        "OFFICIAL_SIGNALER",
        ObjectClass::Pedestrian,
        "OfficialSignaler",
    ),
    ("BICYCLIST", ObjectClass::Cyclist, "Bicyclist"),
    ("MOTORCYCLIST", ObjectClass::Cyclist, "Motorcyclist"),
    ("WHEELED_RIDER", ObjectClass::Cyclist, "WheeledRider"),
    ("BICYCLE", ObjectClass::Misc, "Bicycle"),
    ("WHEELED_DEVICE", ObjectClass::Misc, "WheeledDevice"),
    ("WHEELCHAIR", ObjectClass::Misc, "Wheelchair"),
    ("STROLLER", ObjectClass::Misc, "Stroller"),
    ("DOG", ObjectClass::Misc, "Dog"),
    ("ANIMAL", ObjectClass::Misc, "Animal"),
    (
        "MESSAGE_BOARD_TRAILER",
        ObjectClass::Misc,
        "MessageBoardTrailer",
    ),
    (
        "TRAFFIC_LIGHT_TRAILER",
        ObjectClass::Misc,
        "TrafficLightTrailer",
    ),
    ("BOLLARD", ObjectClass::Pole, "Bollard"),
    (
        "CONSTRUCTION_CONE",
        ObjectClass::ConstructionObj,
        "ConstructionCone",
    ),
    (
        "CONSTRUCTION_BARREL",
        ObjectClass::ConstructionObj,
        "ConstructionBarrel",
    ),
    ("SIGN", ObjectClass::TrafficSign, "Sign"),
    ("STOP_SIGN", ObjectClass::TrafficSign, "StopSign"),
    (
        "MOBILE_PEDESTRIAN_CROSSING_SIGN",
        ObjectClass::TrafficSign,
        "MobilePedestrianCrossingSign",
    ),
];

/// The class and `TypeOf` value of a category: the table's, or for an
/// unknown category class `Other` and the category in CamelCase (kept, so
/// the object is not lost; its `TypeOf` value then reads `Other`).
pub fn classify(category: &str) -> (ObjectClass, String) {
    match CATEGORIES.iter().find(|(c, _, _)| *c == category) {
        Some((_, class, t)) => (*class, (*t).to_string()),
        None => (ObjectClass::Other, camel_case(category)),
    }
}

/// `SCHOOL_BUS` → `SchoolBus`; a category without letters or digits
/// becomes `Unknown`.
pub fn camel_case(category: &str) -> String {
    let mut out = String::with_capacity(category.len());
    for word in category.split(|c: char| !c.is_ascii_alphanumeric()) {
        let mut chars = word.chars();
        if let Some(first) = chars.next() {
            out.push(first.to_ascii_uppercase());
            out.extend(chars.map(|c| c.to_ascii_lowercase()));
        }
    }
    if out.is_empty() {
        "Unknown".to_string()
    } else {
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_type_value_is_the_camel_case_category_and_a_known_type() {
        for (cat, _, t) in CATEGORIES {
            assert_eq!(camel_case(cat), t);
            assert!(
                crate::facts::TYPE_VALUES.contains(&t),
                "{t} missing from TYPE_VALUES"
            );
        }
        assert_eq!(
            classify("HOVERCRAFT"),
            (ObjectClass::Other, "Hovercraft".into())
        );
        assert_eq!(camel_case("__"), "Unknown");
    }
}
