//! The simulator's camera view: a frame's scene state ray-cast into an RGB
//! picture, so a multimodal model (or the frames pipeline) can look at a
//! simulated scene as it would at a real one.
//!
//! The rays are the dense renderer's ([`super::render`]): one through each
//! pixel centre of the pinhole camera, the nearest of ground, object boxes
//! and static solids wins. Colours come from [`palette`]: the sky where a ray
//! meets nothing, ground polygons by class, solids and agents by their
//! `ColorOf` value where they have one and by class otherwise. Box faces are
//! shaded by how squarely the ray meets them, so a box's front, side and top
//! differ and it reads as a solid; the shading is bounded by [`MIN_SHADE`]
//! so that the colour namer of [`super::color`] still names every shaded
//! face by its value. The output depends on the state and camera only.

use image::{Rgb, RgbImage};

use super::render::{Hit, RayHit, Scene, scaled_camera};
use crate::model::{CameraConfig, ObjectClass, SceneState};

/// The colours of the view, one named constant per thing drawn.
///
/// The `ColorOf` values are chosen inside their bands of
/// [`super::color::name_pixel`] (with its default thresholds) with room for
/// shading down to [`MIN_SHADE`].
pub mod palette {
    use image::Rgb;

    /// Where a ray meets nothing (above the horizon).
    pub const SKY: Rgb<u8> = Rgb([150, 190, 230]);
    /// Ground outside every ground polygon.
    pub const BARE_GROUND: Rgb<u8> = Rgb([125, 115, 95]);

    /// `Road`: dark asphalt.
    pub const ROAD: Rgb<u8> = Rgb([70, 70, 74]);
    /// `Sidewalk`: light paving.
    pub const SIDEWALK: Rgb<u8> = Rgb([172, 168, 160]);
    /// `LaneMarking`: white paint.
    pub const LANE_MARKING: Rgb<u8> = Rgb([240, 240, 236]);
    /// `Terrain`: grass.
    pub const TERRAIN: Rgb<u8> = Rgb([95, 140, 60]);
    /// `Building`: brick.
    pub const BUILDING: Rgb<u8> = Rgb([165, 120, 95]);
    /// `Pole`: galvanised steel.
    pub const POLE: Rgb<u8> = Rgb([120, 122, 128]);
    /// `TrafficSign`: sign blue.
    pub const TRAFFIC_SIGN: Rgb<u8> = Rgb([35, 85, 190]);
    /// `TrafficLight`: dark housing.
    pub const TRAFFIC_LIGHT: Rgb<u8> = Rgb([45, 45, 40]);
    /// `Vegetation`: foliage.
    pub const VEGETATION: Rgb<u8> = Rgb([50, 110, 45]);
    /// `Fence`: weathered wood.
    pub const FENCE: Rgb<u8> = Rgb([150, 130, 100]);
    /// `Wall`: concrete.
    pub const WALL: Rgb<u8> = Rgb([185, 178, 165]);
    /// `ConstructionObj`: safety orange.
    pub const CONSTRUCTION: Rgb<u8> = Rgb([240, 120, 20]);
    /// `Other` scenery.
    pub const OTHER: Rgb<u8> = Rgb([150, 100, 150]);

    /// A vehicle without a colour.
    pub const VEHICLE: Rgb<u8> = Rgb([95, 100, 110]);
    /// A pedestrian or sitting person: magenta clothing, unlike any
    /// vehicle's or scenery's colour, so people stand out.
    pub const PERSON: Rgb<u8> = Rgb([170, 40, 130]);
    /// A cyclist: a high-visibility jacket.
    pub const CYCLIST: Rgb<u8> = Rgb([230, 180, 40]);
    /// A `Misc` object (trailer, segway, …).
    pub const MISC: Rgb<u8> = Rgb([150, 105, 60]);

    /// `ColorOf` value `Black`.
    pub const BLACK: Rgb<u8> = Rgb([28, 28, 30]);
    /// `ColorOf` value `Blue`.
    pub const BLUE: Rgb<u8> = Rgb([30, 60, 200]);
    /// `ColorOf` value `Brown`.
    pub const BROWN: Rgb<u8> = Rgb([120, 70, 30]);
    /// `ColorOf` value `Cyan`.
    pub const CYAN: Rgb<u8> = Rgb([30, 190, 200]);
    /// `ColorOf` value `Green`.
    pub const GREEN: Rgb<u8> = Rgb([40, 150, 50]);
    /// `ColorOf` value `Grey`.
    pub const GREY: Rgb<u8> = Rgb([105, 105, 108]);
    /// `ColorOf` value `Orange`.
    pub const ORANGE: Rgb<u8> = Rgb([235, 130, 20]);
    /// `ColorOf` value `Red`.
    pub const RED: Rgb<u8> = Rgb([200, 25, 30]);
    /// `ColorOf` value `Violet`.
    pub const VIOLET: Rgb<u8> = Rgb([140, 50, 190]);
    /// `ColorOf` value `White`.
    pub const WHITE: Rgb<u8> = Rgb([250, 250, 247]);
    /// `ColorOf` value `Yellow`.
    pub const YELLOW: Rgb<u8> = Rgb([230, 210, 30]);
    /// `ColorOf` value `Silver`.
    pub const SILVER: Rgb<u8> = Rgb([185, 188, 192]);
}

/// The darkest shade of a box face (met at a grazing angle); a face met
/// head on keeps its full colour. Above 0.82 so a shaded `White` is still
/// named white (see [`palette`]).
pub const MIN_SHADE: f64 = 0.85;

/// The colour of a `ColorOf` value (`White`, `Red`, …); `None` for `Other`
/// and for names that are not values, which are drawn by class.
pub fn value_color(name: &str) -> Option<Rgb<u8>> {
    Some(match name {
        "Black" => palette::BLACK,
        "Blue" => palette::BLUE,
        "Brown" => palette::BROWN,
        "Cyan" => palette::CYAN,
        "Green" => palette::GREEN,
        "Grey" | "Gray" => palette::GREY,
        "Orange" => palette::ORANGE,
        "Red" => palette::RED,
        "Violet" => palette::VIOLET,
        "White" => palette::WHITE,
        "Yellow" => palette::YELLOW,
        "Silver" => palette::SILVER,
        _ => return None,
    })
}

/// The colour a class is drawn in when its element has no `ColorOf` value.
pub fn class_color(class: ObjectClass) -> Rgb<u8> {
    match class {
        ObjectClass::Vehicle => palette::VEHICLE,
        ObjectClass::Pedestrian | ObjectClass::Person => palette::PERSON,
        ObjectClass::Cyclist => palette::CYCLIST,
        ObjectClass::Misc => palette::MISC,
        ObjectClass::Road => palette::ROAD,
        ObjectClass::Sidewalk => palette::SIDEWALK,
        ObjectClass::LaneMarking => palette::LANE_MARKING,
        ObjectClass::Pole => palette::POLE,
        ObjectClass::TrafficSign => palette::TRAFFIC_SIGN,
        ObjectClass::TrafficLight => palette::TRAFFIC_LIGHT,
        ObjectClass::Building => palette::BUILDING,
        ObjectClass::Vegetation => palette::VEGETATION,
        ObjectClass::Fence => palette::FENCE,
        ObjectClass::Wall => palette::WALL,
        ObjectClass::Terrain => palette::TERRAIN,
        ObjectClass::ConstructionObj => palette::CONSTRUCTION,
        ObjectClass::Other => palette::OTHER,
    }
}

/// An element's colour: its `ColorOf` value where it has one, else its
/// class's.
fn element_color(class: ObjectClass, color: Option<&str>) -> Rgb<u8> {
    color
        .and_then(value_color)
        .unwrap_or_else(|| class_color(class))
}

/// `c` darkened for a face met at `facing` (cosine between ray and face
/// normal): full colour head on, [`MIN_SHADE`] of it at a grazing angle.
fn shade(c: Rgb<u8>, facing: f64) -> Rgb<u8> {
    let s = MIN_SHADE + (1.0 - MIN_SHADE) * facing.clamp(0.0, 1.0);
    Rgb(c
        .0
        .map(|v| (f64::from(v) * s).round().clamp(0.0, 255.0) as u8))
}

/// The camera scaled down so that the longer image side is at most
/// `max_side` pixels (never up), for a picture that need not be larger.
pub fn camera_within(camera: &CameraConfig, max_side: u32) -> CameraConfig {
    let k = &camera.intrinsics;
    let longest = k.image_width.max(k.image_height);
    if longest <= max_side {
        return *camera;
    }
    scaled_camera(camera, f64::from(max_side.max(1)) / f64::from(longest))
}

/// Renders what `camera` (the state's own, or [`scaled_camera`] /
/// [`camera_within`] of it) sees of `state`: an image of the camera's size.
pub fn render_view(state: &SceneState, camera: &CameraConfig) -> RgbImage {
    let k = camera.intrinsics;
    let scene = Scene::new(state, camera);
    let mut img = RgbImage::new(k.image_width, k.image_height);
    for (u, v, px) in img.enumerate_pixels_mut() {
        let (u, v) = (u as usize, v as usize);
        *px = match scene.cast(u, v) {
            None => palette::SKY,
            Some(RayHit {
                hit: Hit::Ground,
                point,
                ..
            }) => scene
                .ground_under(point)
                .and_then(|i| state.statics.get(i))
                .map_or(palette::BARE_GROUND, |e| {
                    element_color(e.class, e.color.as_deref())
                }),
            Some(RayHit {
                hit: Hit::Object(i),
                facing,
                ..
            }) => state.objects.get(i).map_or(palette::OTHER, |o| {
                shade(element_color(o.class, o.color.as_deref()), facing)
            }),
            Some(RayHit {
                hit: Hit::Solid(i),
                facing,
                ..
            }) => state.statics.get(i).map_or(palette::OTHER, |e| {
                shade(element_color(e.class, e.color.as_deref()), facing)
            }),
        };
    }
    img
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::model::{Box3D, CameraPose, SceneObject};
    use crate::raw::color::{COLOR_VALUES, ColorConfig, name_pixel};
    use crate::sim::{Scenario, simulate};

    fn urban_crossing() -> crate::sim::SimRun {
        let scenario = Scenario::builtin("urban_crossing").expect("built-in scenario");
        simulate(&scenario, 0).expect("simulates")
    }

    /// A state with nothing but one object straight ahead of the camera.
    fn one_object(color: Option<&str>, yaw: f64) -> SceneState {
        let camera = crate::sim::default_camera();
        let pose = CameraPose {
            position: [0.0, -camera.height_m, 0.0],
            yaw: 0.0,
        };
        let world = Box3D {
            center: [0.0, 0.0, 12.0],
            size: [1.5, 1.8, 4.2],
            yaw,
        };
        let cam = Box3D {
            center: pose
                .world_to_camera(crate::coords::WorldPoint::from_array(world.center))
                .to_array(),
            size: world.size,
            yaw: world.yaw - pose.yaw,
        };
        SceneState {
            frame: 0,
            camera_pose: pose,
            camera,
            objects: vec![SceneObject {
                track_id: 1,
                name: "car_1".into(),
                class: ObjectClass::Vehicle,
                type_name: Some("Car".into()),
                color: color.map(str::to_string),
                world,
                camera: cam,
                bbox: None,
                visible: true,
            }],
            statics: Arc::new(Vec::new()),
        }
    }

    #[test]
    fn every_value_colour_is_named_back_at_every_shade() {
        let config = ColorConfig::default();
        for name in COLOR_VALUES.iter().filter(|c| **c != "Other") {
            let c = value_color(name).expect("a value has a colour");
            for facing in [0.0, 0.5, 1.0] {
                assert_eq!(
                    name_pixel(shade(c, facing).0, &config),
                    *name,
                    "{name} at {facing}"
                );
            }
        }
        assert_eq!(value_color("Other"), None);
        assert_eq!(value_color("Mauve"), None);
    }

    #[test]
    fn sky_above_road_below_in_a_road_scenario() {
        let run = urban_crossing();
        let state = &run.states[0];
        let img = render_view(state, &state.camera);
        let k = state.camera.intrinsics;
        assert_eq!(img.dimensions(), (k.image_width, k.image_height));
        let centre = k.image_width / 2;
        assert_eq!(*img.get_pixel(centre, 0), palette::SKY);
        assert_eq!(*img.get_pixel(centre, k.image_height - 1), palette::ROAD);
        // The sidewalks are in view too.
        assert!(img.pixels().any(|p| *p == palette::SIDEWALK));
    }

    #[test]
    fn agents_show_in_their_own_colour_where_their_boxes_project() {
        let run = urban_crossing();
        let config = ColorConfig::default();
        let mut named = std::collections::BTreeSet::new();
        for state in run.states.iter().step_by(10) {
            let img = render_view(state, &state.camera);
            let scene = Scene::new(state, &state.camera);
            for (i, o) in state.objects.iter().enumerate() {
                let (Some(b), Some(color)) = (o.bbox, o.color.as_deref()) else {
                    continue;
                };
                let (u, v) = (b.center_x().round(), (0.5 * (b.top + b.bottom)).round());
                let (u, v) = (u as u32, v as u32);
                // Only where the box's centre is not hidden behind another.
                if scene.cast(u as usize, v as usize).map(|h| h.hit) != Some(Hit::Object(i)) {
                    continue;
                }
                assert_eq!(
                    name_pixel(img.get_pixel(u, v).0, &config),
                    color,
                    "frame {} {}",
                    state.frame,
                    o.name
                );
                named.insert(o.name.clone());
            }
        }
        assert!(named.len() >= 3, "too few agents checked: {named:?}");
    }

    #[test]
    fn a_box_is_drawn_in_its_colour_with_faces_shaded_apart() {
        let state = one_object(Some("Red"), 0.6);
        let img = render_view(&state, &state.camera);
        let k = state.camera.intrinsics;
        let uv = k
            .project(crate::coords::CameraPoint::new(0.0, 0.8, 12.0), 0.1)
            .expect("in front");
        let px = *img.get_pixel(uv.x.round() as u32, uv.y.round() as u32);
        assert_eq!(name_pixel(px.0, &ColorConfig::default()), "Red");
        // Turned 0.6 rad, the car shows two faces: two shades of red.
        let reds: std::collections::BTreeSet<[u8; 3]> = img
            .pixels()
            .filter(|p| name_pixel(p.0, &ColorConfig::default()) == "Red")
            .map(|p| p.0)
            .collect();
        assert!(reds.len() >= 2, "{reds:?}");
        // Without a colour, the class colour, shaded.
        let plain = render_view(&one_object(None, 0.0), &state.camera);
        let px = *plain.get_pixel(uv.x.round() as u32, uv.y.round() as u32);
        let head_on = shade(palette::VEHICLE, 1.0);
        assert!(
            px.0.iter().zip(head_on.0).all(|(a, b)| a.abs_diff(b) <= 2),
            "{px:?}"
        );
        // Nothing else in view: sky above the horizon, bare ground below.
        assert_eq!(*img.get_pixel(0, 0), palette::SKY);
        assert_eq!(*img.get_pixel(0, k.image_height - 1), palette::BARE_GROUND);
    }

    #[test]
    fn a_smaller_camera_renders_a_smaller_picture_of_the_same_scene() {
        let run = urban_crossing();
        let state = &run.states[20];
        let small = camera_within(&state.camera, 400);
        let k = small.intrinsics;
        assert_eq!(k.image_width.max(k.image_height), 400);
        let img = render_view(state, &small);
        assert_eq!(img.dimensions(), (k.image_width, k.image_height));
        assert_eq!(
            *img.get_pixel(k.image_width / 2, k.image_height - 1),
            palette::ROAD
        );
        assert_eq!(camera_within(&state.camera, 5000), state.camera);
        // Deterministic: the same state renders to the same pixels.
        assert_eq!(render_view(state, &small), img);
    }
}
