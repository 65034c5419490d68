//! Dense maps rendered from the simulator's per-frame scene state, so the
//! dense path (maps → instances → tracker → 3D → facts) is tested end to end
//! against known truth.
//!
//! A ray is cast through every pixel of the pinhole camera and meets the
//! flat ground (`Y = 0` in the world, the camera `height_m` above it) and the
//! oriented boxes of the objects and static solids; the nearest hit wins (a
//! z-buffer). Ground hits take the class of the ground polygon they fall in
//! (road, sidewalk, …; later polygons drawn over earlier ones), or no class.
//! Flow follows each hit point to the next frame: a point on an object moves
//! rigidly with the object's box, a point of the static world stays put while
//! the camera moves.

use std::collections::{BTreeMap, BTreeSet};

use super::decode::DenseMap;
use super::dense::{ClassTable, DenseFrame};
use crate::coords::{CameraPoint, WorldBev, WorldPoint};
use crate::model::{Box3D, CameraConfig, CameraIntrinsics, ObjectClass, SceneState, StaticShape};

/// Semantic ids for rendered maps: one per `(class, type)` met in the scene
/// states, numbered from 1 in sorted order (0 = nothing).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RenderLabels {
    ids: BTreeMap<(ObjectClass, Option<String>), u16>,
}

impl RenderLabels {
    /// Collects every `(class, type)` of the states.
    pub fn from_states(states: &[SceneState]) -> RenderLabels {
        let mut keys = BTreeSet::new();
        for s in states {
            for o in &s.objects {
                keys.insert((o.class, o.type_name.clone()));
            }
            for e in s.statics.iter() {
                keys.insert((e.class, None));
            }
        }
        let ids = keys
            .into_iter()
            .enumerate()
            .map(|(i, k)| (k, u16::try_from(i + 1).unwrap_or(u16::MAX)))
            .collect();
        RenderLabels { ids }
    }

    /// The id of `(class, type)`, 0 when unknown.
    pub fn id(&self, class: ObjectClass, type_name: Option<&str>) -> u16 {
        self.ids
            .get(&(class, type_name.map(str::to_string)))
            .copied()
            .unwrap_or(0)
    }

    /// The table that maps the ids back to classes and types.
    pub fn class_table(&self) -> ClassTable {
        let mut t = ClassTable::default();
        for ((class, type_name), id) in &self.ids {
            t.insert(*id, *class, type_name.clone());
        }
        t
    }
}

/// The camera scaled to render at `scale` times the image size (pixel
/// centres kept aligned).
pub fn scaled_camera(camera: &CameraConfig, scale: f64) -> CameraConfig {
    let k = &camera.intrinsics;
    CameraConfig {
        intrinsics: CameraIntrinsics {
            fx: k.fx * scale,
            fy: k.fy * scale,
            cx: (k.cx + 0.5) * scale - 0.5,
            cy: (k.cy + 0.5) * scale - 0.5,
            image_width: ((f64::from(k.image_width) * scale).round() as u32).max(1),
            image_height: ((f64::from(k.image_height) * scale).round() as u32).max(1),
        },
        height_m: camera.height_m,
    }
}

/// What a pixel's ray hits first.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Hit {
    /// Object `index` of the state's objects.
    Object(usize),
    /// A static solid, by index into the statics.
    Solid(usize),
    /// The ground.
    Ground,
}

/// Hits nearer than this depth (m) are ignored (the camera inside a box
/// does not see it); a box with a corner nearer may cover any pixel.
const MIN_HIT_DEPTH_M: f64 = 1e-6;

/// Entry distance `t` of the ray `t · d` (from the camera centre) into an
/// oriented box given in camera coordinates, if it hits in front, with the
/// axis (unit, camera coordinates) of the face it enters through — the
/// view renderer shades by it.
fn ray_box_face(d: [f64; 3], b: &Box3D) -> Option<(f64, [f64; 3])> {
    let (s, c) = b.yaw.sin_cos();
    let heading = [c, 0.0, -s];
    let lateral = [s, 0.0, c];
    let vertical = [0.0, 1.0, 0.0];
    let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let o = [-b.center[0], -b.center[1], -b.center[2]];
    let [h, w, l] = b.size;
    // (axis, origin, direction, min, max) per slab; height spans Y in
    // [-h, 0] relative to the bottom centre (Y points down).
    let slabs = [
        (heading, dot(o, heading), dot(d, heading), -l / 2.0, l / 2.0),
        (lateral, dot(o, lateral), dot(d, lateral), -w / 2.0, w / 2.0),
        (vertical, o[1], d[1], -h, 0.0),
    ];
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    let mut face = vertical;
    for (axis, oo, dd, lo, hi) in slabs {
        if dd.abs() < 1e-12 {
            if oo < lo || oo > hi {
                return None;
            }
            continue;
        }
        let (a, b2) = ((lo - oo) / dd, (hi - oo) / dd);
        if a.min(b2) > t0 {
            t0 = a.min(b2);
            face = axis;
        }
        t1 = t1.min(a.max(b2));
    }
    (t0 <= t1 && t1 > 0.0).then_some((t0.max(0.0), face))
}

/// The pixels `u0..=u1`, `v0..=v1` a box can cover (possibly beyond the
/// image).
#[derive(Debug, Clone, Copy)]
struct PixelRect {
    u0: f64,
    u1: f64,
    v0: f64,
    v1: f64,
}

impl PixelRect {
    fn contains(&self, u: f64, v: f64) -> bool {
        u >= self.u0 && u <= self.u1 && v >= self.v0 && v <= self.v1
    }
}

/// The pixels a camera-frame box can cover: the bounds of its projected
/// corners (the projection of a box in front of the camera lies within
/// them), everything when it reaches behind the camera, `None` when it lies
/// wholly behind. Lets a ray skip the boxes it cannot hit, which is most of
/// them at every pixel.
fn box_pixels(b: &Box3D, k: &CameraIntrinsics) -> Option<PixelRect> {
    let (s, c) = b.yaw.sin_cos();
    let [h, w, l] = b.size;
    let mut corners = Vec::with_capacity(8);
    for a in [-l / 2.0, l / 2.0] {
        for e in [-w / 2.0, w / 2.0] {
            for y in [-h, 0.0] {
                corners.push(CameraPoint::new(
                    b.center[0] + a * c + e * s,
                    b.center[1] + y,
                    b.center[2] - a * s + e * c,
                ));
            }
        }
    }
    let in_front = corners.iter().filter(|p| p.0.z > MIN_HIT_DEPTH_M).count();
    if in_front == 0 {
        return None;
    }
    let everything = PixelRect {
        u0: f64::NEG_INFINITY,
        u1: f64::INFINITY,
        v0: f64::NEG_INFINITY,
        v1: f64::INFINITY,
    };
    if in_front < corners.len() {
        return Some(everything);
    }
    let mut r = PixelRect {
        u0: f64::INFINITY,
        u1: f64::NEG_INFINITY,
        v0: f64::INFINITY,
        v1: f64::NEG_INFINITY,
    };
    for p in corners {
        let Some(uv) = k.project(p, 0.0) else {
            return Some(everything);
        };
        r.u0 = r.u0.min(uv.x);
        r.u1 = r.u1.max(uv.x);
        r.v0 = r.v0.min(uv.y);
        r.v1 = r.v1.max(uv.y);
    }
    // A pixel of margin against rounding at the box's silhouette.
    Some(PixelRect {
        u0: r.u0 - 1.0,
        u1: r.u1 + 1.0,
        v0: r.v0 - 1.0,
        v1: r.v1 + 1.0,
    })
}

/// A box a ray may hit: its index, camera-frame box and pixel bounds.
#[derive(Debug, Clone)]
struct Target {
    index: usize,
    camera: Box3D,
    pixels: PixelRect,
}

/// Where a pixel's ray first meets the scene.
#[derive(Debug, Clone, Copy)]
pub(super) struct RayHit {
    /// What it hits.
    pub hit: Hit,
    /// Depth along the optical axis (the ray is `t · d` with `d.z = 1`).
    pub t: f64,
    /// The hit point, camera coordinates.
    pub point: CameraPoint,
    /// Cosine between the ray and the normal of the face it meets (1 head
    /// on, near 0 grazing).
    pub facing: f64,
}

/// One frame's geometry prepared for casting rays: boxes in camera
/// coordinates with their pixel bounds, ground polygons as typed points.
/// Shared by the dense-map and the colour renderer so both see the same
/// scene.
pub(super) struct Scene<'a> {
    state: &'a SceneState,
    k: CameraIntrinsics,
    /// Camera height above the ground (m).
    height: f64,
    objects: Vec<Target>,
    solids: Vec<Target>,
    /// Ground polygons by static index, in draw order.
    grounds: Vec<(usize, Vec<WorldBev>)>,
}

impl<'a> Scene<'a> {
    /// Prepares `state` for rays through the pixels of `camera`.
    pub(super) fn new(state: &'a SceneState, camera: &CameraConfig) -> Scene<'a> {
        let k = camera.intrinsics;
        let target = |index: usize, camera: Box3D| {
            box_pixels(&camera, &k).map(|pixels| Target {
                index,
                camera,
                pixels,
            })
        };
        let objects = state
            .objects
            .iter()
            .enumerate()
            .filter_map(|(i, o)| target(i, o.camera))
            .collect();
        let solids = state
            .statics
            .iter()
            .enumerate()
            .filter_map(|(i, e)| match &e.shape {
                StaticShape::Solid(b) => target(i, world_box_to_camera(state, b)),
                StaticShape::Ground { .. } => None,
            })
            .collect();
        let grounds = state
            .statics
            .iter()
            .enumerate()
            .filter_map(|(i, e)| match &e.shape {
                StaticShape::Ground { polygon } => {
                    Some((i, polygon.iter().copied().map(WorldBev::from_xz).collect()))
                }
                StaticShape::Solid(_) => None,
            })
            .collect();
        Scene {
            state,
            k,
            height: -state.camera_pose.position[1],
            objects,
            solids,
            grounds,
        }
    }

    /// The first thing the ray through pixel `(u, v)` hits; on a tie in
    /// depth the ground wins over objects, objects over solids.
    pub(super) fn cast(&self, u: usize, v: usize) -> Option<RayHit> {
        let k = &self.k;
        let (uf, vf) = (u as f64, v as f64);
        let d = [(uf - k.cx) / k.fx, (vf - k.cy) / k.fy, 1.0];
        let norm = (d[0] * d[0] + d[1] * d[1] + 1.0).sqrt();
        // (t, hit, face axis)
        let mut best: Option<(f64, Hit, [f64; 3])> = None;
        let mut consider = |t: f64, hit: Hit, axis: [f64; 3]| {
            if t > MIN_HIT_DEPTH_M && best.is_none_or(|(bt, _, _)| t < bt) {
                best = Some((t, hit, axis));
            }
        };
        if d[1] > 0.0 && self.height > 0.0 {
            consider(self.height / d[1], Hit::Ground, [0.0, 1.0, 0.0]);
        }
        for o in &self.objects {
            if o.pixels.contains(uf, vf)
                && let Some((t, axis)) = ray_box_face(d, &o.camera)
            {
                consider(t, Hit::Object(o.index), axis);
            }
        }
        for s in &self.solids {
            if s.pixels.contains(uf, vf)
                && let Some((t, axis)) = ray_box_face(d, &s.camera)
            {
                consider(t, Hit::Solid(s.index), axis);
            }
        }
        let (t, hit, axis) = best?;
        let facing = (axis[0] * d[0] + axis[1] * d[1] + axis[2] * d[2]).abs() / norm;
        Some(RayHit {
            hit,
            t,
            point: CameraPoint::new(d[0] * t, d[1] * t, t),
            facing,
        })
    }

    /// The static index of the ground polygon under a ground point (the
    /// last drawn where polygons overlap), `None` on bare ground.
    pub(super) fn ground_under(&self, p: CameraPoint) -> Option<usize> {
        let world = self.state.camera_pose.camera_to_world(p).bev();
        self.grounds
            .iter()
            .rev()
            .find(|(_, polygon)| inside_polygon(world, polygon))
            .map(|(i, _)| *i)
    }
}

/// A box in world coordinates expressed in the camera frame of `state`.
fn world_box_to_camera(state: &SceneState, b: &Box3D) -> Box3D {
    Box3D {
        center: state
            .camera_pose
            .world_to_camera(WorldPoint::from_array(b.center))
            .to_array(),
        size: b.size,
        yaw: b.yaw - state.camera_pose.yaw,
    }
}

/// A point of a camera-frame box's camera in the box's local frame (along
/// heading, along lateral, height offset); with [`from_local`], a point
/// riding on the box from one frame to the next.
fn to_local(b: &Box3D, p: CameraPoint) -> [f64; 3] {
    let (s, c) = b.yaw.sin_cos();
    let p = p.0;
    let q = [p.x - b.center[0], p.y - b.center[1], p.z - b.center[2]];
    [q[0] * c - q[2] * s, q[1], q[0] * s + q[2] * c]
}

/// The camera point of local coordinates `q` of a camera-frame box.
fn from_local(b: &Box3D, q: [f64; 3]) -> CameraPoint {
    let (s, c) = b.yaw.sin_cos();
    CameraPoint::new(
        b.center[0] + q[0] * c + q[2] * s,
        b.center[1] + q[1],
        b.center[2] - q[0] * s + q[2] * c,
    )
}

fn inside_polygon(p: WorldBev, poly: &[WorldBev]) -> bool {
    let mut inside = false;
    let n = poly.len();
    let p = p.0;
    for i in 0..n {
        let (a, b) = (poly[i].0, poly[(i + n - 1) % n].0);
        if (a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x {
            inside = !inside;
        }
    }
    inside
}

/// Renders the semantic, instance (object or static id + 1) and depth maps of
/// `state` seen by `camera` (usually [`scaled_camera`] of the state's), and
/// the forward flow into `next` when given.
pub fn render(
    state: &SceneState,
    next: Option<&SceneState>,
    camera: &CameraConfig,
    labels: &RenderLabels,
) -> DenseFrame {
    let k = camera.intrinsics;
    let (w, h) = (k.image_width as usize, k.image_height as usize);
    let mut semantic = vec![0u16; w * h];
    let mut instance = vec![0u32; w * h];
    let mut depth = vec![0.0f32; w * h];
    let mut flow = next.map(|_| vec![0.0f32; w * h * 2]);
    let scene = Scene::new(state, camera);
    let next_objects: BTreeMap<u32, &Box3D> = next
        .map(|n| n.objects.iter().map(|o| (o.track_id, &o.camera)).collect())
        .unwrap_or_default();
    for v in 0..h {
        for u in 0..w {
            let Some(RayHit {
                hit, t, point: p, ..
            }) = scene.cast(u, v)
            else {
                continue;
            };
            let idx = v * w + u;
            depth[idx] = t as f32;
            // Where the hit point is in the next frame's camera coordinates.
            let mut moved: Option<CameraPoint> = None;
            match hit {
                Hit::Object(i) => {
                    if let Some(o) = state.objects.get(i) {
                        semantic[idx] = labels.id(o.class, o.type_name.as_deref());
                        instance[idx] = o.track_id + 1;
                        moved = next_objects
                            .get(&o.track_id)
                            .map(|nb| from_local(nb, to_local(&o.camera, p)));
                    }
                }
                Hit::Solid(i) => {
                    if let Some(e) = state.statics.get(i) {
                        semantic[idx] = labels.id(e.class, None);
                        instance[idx] = e.id + 1;
                    }
                }
                Hit::Ground => {
                    if let Some(e) = scene.ground_under(p).and_then(|i| state.statics.get(i)) {
                        semantic[idx] = labels.id(e.class, None);
                        instance[idx] = e.id + 1;
                    }
                }
            }
            if let (Some(f), Some(n)) = (flow.as_mut(), next) {
                if !matches!(hit, Hit::Object(_)) {
                    moved = Some(
                        n.camera_pose
                            .world_to_camera(state.camera_pose.camera_to_world(p)),
                    );
                }
                if let Some(uv2) = moved.and_then(|q| k.project(q, 1e-3)) {
                    f[2 * idx] = (uv2.x - u as f64) as f32;
                    f[2 * idx + 1] = (uv2.y - v as f64) as f32;
                }
            }
        }
    }
    DenseFrame {
        width: w,
        height: h,
        semantic: Some(DenseMap {
            width: w,
            height: h,
            channels: 1,
            data: semantic,
        }),
        instance: Some(DenseMap {
            width: w,
            height: h,
            channels: 1,
            data: instance,
        }),
        depth: Some(DenseMap {
            width: w,
            height: h,
            channels: 1,
            data: depth,
        }),
        flow: flow.map(|data| DenseMap {
            width: w,
            height: h,
            channels: 2,
            data,
        }),
    }
}

/// Renders every state (flow into the following one; the last frame has no
/// flow) at `scale` times the camera resolution; returns the frames and the
/// scaled camera.
pub fn render_sequence(
    states: &[SceneState],
    scale: f64,
    labels: &RenderLabels,
) -> Option<(Vec<DenseFrame>, CameraConfig)> {
    let first = states.first()?;
    let camera = scaled_camera(&first.camera, scale);
    let frames = states
        .iter()
        .enumerate()
        .map(|(i, s)| render(s, states.get(i + 1), &camera, labels))
        .collect();
    Some((frames, camera))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ray_hits_a_box_in_front_and_misses_beside_it() {
        let b = Box3D {
            center: [0.0, 1.65, 10.0],
            size: [1.5, 1.6, 4.0],
            yaw: 0.3,
        };
        let (t, _) = ray_box_face([0.0, 0.1, 1.0], &b).unwrap();
        assert!(t > 7.5 && t < 10.0, "{t}");
        assert!(ray_box_face([0.5, 0.0, 1.0], &b).is_none());
        assert!(
            ray_box_face([0.0, 0.1, -1.0], &b).is_none(),
            "behind the camera"
        );
    }

    #[test]
    fn every_pixel_a_box_covers_is_inside_its_pixel_bounds() {
        let k = CameraIntrinsics {
            fx: 120.0,
            fy: 120.0,
            cx: 79.5,
            cy: 29.5,
            image_width: 160,
            image_height: 60,
        };
        let boxes = [
            ([0.0, 1.65, 10.0], 0.3),
            ([-3.0, 1.65, 6.0], 1.2),
            ([4.0, 1.0, 2.5], -0.7),
            // Reaching behind the camera: any pixel.
            ([2.5, 1.65, 0.5], 0.0),
        ];
        let mut hits = 0;
        for (center, yaw) in boxes {
            let b = Box3D {
                center,
                size: [1.5, 1.6, 4.0],
                yaw,
            };
            let r = box_pixels(&b, &k).expect("in front");
            for v in 0..k.image_height {
                for u in 0..k.image_width {
                    let (uf, vf) = (f64::from(u), f64::from(v));
                    let d = [(uf - k.cx) / k.fx, (vf - k.cy) / k.fy, 1.0];
                    if ray_box_face(d, &b).is_some_and(|(t, _)| t > MIN_HIT_DEPTH_M) {
                        hits += 1;
                        assert!(r.contains(uf, vf), "({u}, {v}) outside {r:?}");
                    }
                }
            }
        }
        assert!(hits > 500, "{hits}");
        let behind = Box3D {
            center: [0.0, 1.65, -10.0],
            size: [1.5, 1.6, 4.0],
            yaw: 0.0,
        };
        assert!(box_pixels(&behind, &k).is_none());
    }

    #[test]
    fn local_frame_round_trips() {
        let b = Box3D {
            center: [1.0, 1.65, 10.0],
            size: [1.5, 1.6, 4.0],
            yaw: 0.7,
        };
        let p = CameraPoint::new(1.5, 1.0, 9.0);
        let q = from_local(&b, to_local(&b, p));
        for i in 0..3 {
            assert!((p.0[i] - q.0[i]).abs() < 1e-12);
        }
    }

    #[test]
    fn polygon_membership() {
        let sq = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0], [0.0, 2.0]].map(WorldBev::from_xz);
        assert!(inside_polygon(WorldBev::new(1.0, 1.0), &sq));
        assert!(!inside_polygon(WorldBev::new(3.0, 1.0), &sq));
    }
}
