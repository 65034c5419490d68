//! Semantic classes and their LogicPad class predicates.

use serde::{Deserialize, Serialize};

/// Semantic class of an object; maps one-to-one onto a LogicPad class
/// predicate (see [`ObjectClass::predicate`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum ObjectClass {
    /// Any motor vehicle or tram (predicate `Vehicles`).
    #[serde(rename = "Vehicles", alias = "Vehicle")]
    Vehicle,
    /// A person on foot.
    Pedestrian,
    /// A sitting person (KITTI `Person_sitting`).
    Person,
    /// A person riding a bicycle.
    Cyclist,
    /// KITTI `Misc` (trailers, segways, …).
    Misc,
    /// Drivable road surface.
    Road,
    /// Sidewalk surface.
    Sidewalk,
    /// Painted lane marking.
    LaneMarking,
    /// Pole.
    Pole,
    /// Traffic sign.
    TrafficSign,
    /// Traffic light.
    TrafficLight,
    /// Building.
    Building,
    /// Trees, bushes.
    Vegetation,
    /// Fence.
    Fence,
    /// Wall.
    Wall,
    /// Terrain (grass, soil).
    Terrain,
    /// Construction object (barrier, cone).
    ConstructionObj,
    /// Anything else.
    Other,
}

impl ObjectClass {
    /// Every class, in declaration order.
    pub const ALL: [ObjectClass; 18] = [
        ObjectClass::Vehicle,
        ObjectClass::Pedestrian,
        ObjectClass::Person,
        ObjectClass::Cyclist,
        ObjectClass::Misc,
        ObjectClass::Road,
        ObjectClass::Sidewalk,
        ObjectClass::LaneMarking,
        ObjectClass::Pole,
        ObjectClass::TrafficSign,
        ObjectClass::TrafficLight,
        ObjectClass::Building,
        ObjectClass::Vegetation,
        ObjectClass::Fence,
        ObjectClass::Wall,
        ObjectClass::Terrain,
        ObjectClass::ConstructionObj,
        ObjectClass::Other,
    ];

    /// The LogicPad class predicate, e.g. `"Vehicles"`.
    pub const fn predicate(&self) -> &'static str {
        match self {
            ObjectClass::Vehicle => "Vehicles",
            ObjectClass::Pedestrian => "Pedestrian",
            ObjectClass::Person => "Person",
            ObjectClass::Cyclist => "Cyclist",
            ObjectClass::Misc => "Misc",
            ObjectClass::Road => "Road",
            ObjectClass::Sidewalk => "Sidewalk",
            ObjectClass::LaneMarking => "LaneMarking",
            ObjectClass::Pole => "Pole",
            ObjectClass::TrafficSign => "TrafficSign",
            ObjectClass::TrafficLight => "TrafficLight",
            ObjectClass::Building => "Building",
            ObjectClass::Vegetation => "Vegetation",
            ObjectClass::Fence => "Fence",
            ObjectClass::Wall => "Wall",
            ObjectClass::Terrain => "Terrain",
            ObjectClass::ConstructionObj => "ConstructionObj",
            ObjectClass::Other => "Other",
        }
    }

    /// Parses a class predicate (or the variant name) back into a class.
    pub fn from_predicate(name: &str) -> Option<ObjectClass> {
        if name == "Vehicle" {
            return Some(ObjectClass::Vehicle);
        }
        ObjectClass::ALL
            .iter()
            .copied()
            .find(|c| c.predicate() == name)
    }

    /// Whether objects of this class never move (scene structure); static
    /// objects are ego-motion anchors and are never `Moving`.
    pub fn is_static(&self) -> bool {
        !matches!(
            self,
            ObjectClass::Vehicle
                | ObjectClass::Pedestrian
                | ObjectClass::Person
                | ObjectClass::Cyclist
                | ObjectClass::Misc
                | ObjectClass::Other
        )
    }

    /// Whether the class is a region of the ground (road, sidewalk, lane
    /// marking, terrain) rather than an object with one position: its box
    /// centre or ground point says nothing about where the region lies, so
    /// relations between positions (`LeftOf`, `InFrontOf`, …) skip it even
    /// when a source gives it no footprint.
    pub fn is_ground_surface(&self) -> bool {
        matches!(
            self,
            ObjectClass::Road
                | ObjectClass::Sidewalk
                | ObjectClass::LaneMarking
                | ObjectClass::Terrain
        )
    }

    /// Whether the class is a road user that can walk (pedestrian-like).
    pub fn is_person_like(&self) -> bool {
        matches!(self, ObjectClass::Pedestrian | ObjectClass::Person)
    }

    /// Lower snake case kind used in object names when no type is known.
    pub fn kind(&self) -> &'static str {
        match self {
            ObjectClass::Vehicle => "vehicle",
            ObjectClass::Pedestrian => "pedestrian",
            ObjectClass::Person => "person",
            ObjectClass::Cyclist => "cyclist",
            ObjectClass::Misc => "misc",
            ObjectClass::Road => "road",
            ObjectClass::Sidewalk => "sidewalk",
            ObjectClass::LaneMarking => "lane_marking",
            ObjectClass::Pole => "pole",
            ObjectClass::TrafficSign => "traffic_sign",
            ObjectClass::TrafficLight => "traffic_light",
            ObjectClass::Building => "building",
            ObjectClass::Vegetation => "vegetation",
            ObjectClass::Fence => "fence",
            ObjectClass::Wall => "wall",
            ObjectClass::Terrain => "terrain",
            ObjectClass::ConstructionObj => "construction_obj",
            ObjectClass::Other => "other",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn class_predicates_round_trip() {
        for c in ObjectClass::ALL {
            assert_eq!(ObjectClass::from_predicate(c.predicate()), Some(c));
        }
        assert!(ObjectClass::Road.is_static());
        assert!(!ObjectClass::Vehicle.is_static());
    }
}
