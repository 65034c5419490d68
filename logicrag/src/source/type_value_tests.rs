use super::unassigned_types;

#[test]
fn kitti_never_gives_a_body_style_of_the_taxonomy_nor_a_bus() {
    let unseen = unassigned_types(perception::kitti::KITTI_TYPES);
    // Every car body style of the built-in LogicPad's taxonomy (its
    // rules `TypeOf(x, Sedan) ==> TypeOf(x, Car)`): the two lists
    // cannot drift apart.
    let words = crate::context::Sentences::builtin();
    let taxonomy = words.supertypes("TypeOf").cloned().unwrap_or_default();
    let styles: Vec<&String> = taxonomy
        .iter()
        .filter(|(_, up)| up.contains("Car"))
        .map(|(sub, _)| sub)
        .collect();
    assert!(styles.len() >= 9, "{styles:?}");
    for s in styles {
        assert!(unseen.contains(&s.as_str()), "{s}: {unseen:?}");
    }
    for v in ["Bus", "Motorcycle", "Bicycle"] {
        assert!(unseen.contains(&v), "{v}: {unseen:?}");
    }
    for v in [
        "Car",
        "Van",
        "Truck",
        "Tram",
        "Pedestrian",
        "Cyclist",
        "Other",
    ] {
        assert!(!unseen.contains(&v), "{v}: {unseen:?}");
    }
}

#[test]
fn a_detector_sees_the_types_its_label_map_names() {
    let unseen = unassigned_types(["Pedestrian", "Car", "Bus", "truck"]);
    for v in ["Car", "Bus", "Truck", "Pedestrian"] {
        assert!(!unseen.contains(&v), "{v}: {unseen:?}");
    }
    for v in ["Van", "Tram", "Sedan", "Cyclist", "Bicycle"] {
        assert!(unseen.contains(&v), "{v}: {unseen:?}");
    }
}
