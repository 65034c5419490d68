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
#[derive(Debug, Clone, Copy)]
enum Hit {
    /// Object `index` of the state's objects.
    Object(usize),
    /// A static solid, by index into the statics.
    Solid(usize),
    /// The ground.
    Ground,
}

/// Entry distance `t` of the ray `t · d` (from the camera centre) into an
/// oriented box given in camera coordinates, if it hits in front.
fn ray_box(d: [f64; 3], b: &Box3D) -> Option<f64> {
    let (s, c) = b.yaw.sin_cos();
    let heading = [c, 0.0, -s];
    let lateral = [s, 0.0, c];
    let dot = |u: [f64; 3], v: [f64; 3]| u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
    let o = [-b.center[0], -b.center[1], -b.center[2]];
    let [h, w, l] = b.size;
    // (origin, direction, min, max) per slab; height spans Y in [-h, 0]
    // relative to the bottom centre (Y points down).
    let slabs = [
        (dot(o, heading), dot(d, heading), -l / 2.0, l / 2.0),
        (dot(o, lateral), dot(d, lateral), -w / 2.0, w / 2.0),
        (o[1], d[1], -h, 0.0),
    ];
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for (oo, dd, lo, hi) in slabs {
        if dd.abs() < 1e-12 {
            if oo < lo || oo > hi {
                return None;
            }
            continue;
        }
        let (a, b2) = ((lo - oo) / dd, (hi - oo) / dd);
        t0 = t0.max(a.min(b2));
        t1 = t1.min(a.max(b2));
    }
    (t0 <= t1 && t1 > 0.0).then_some(t0.max(0.0))
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
    let solids: Vec<(usize, Box3D)> = state
        .statics
        .iter()
        .enumerate()
        .filter_map(|(i, e)| match &e.shape {
            StaticShape::Solid(b) => Some((i, world_box_to_camera(state, b))),
            StaticShape::Ground { .. } => None,
        })
        .collect();
    // Ground polygons as typed world points, once per frame, in draw order.
    let grounds: Vec<(usize, Vec<WorldBev>)> = state
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
    let next_objects: BTreeMap<u32, &Box3D> = next
        .map(|n| n.objects.iter().map(|o| (o.track_id, &o.camera)).collect())
        .unwrap_or_default();
    let height = -state.camera_pose.position[1];
    for v in 0..h {
        for u in 0..w {
            let d = [(u as f64 - k.cx) / k.fx, (v as f64 - k.cy) / k.fy, 1.0];
            let mut best: Option<(f64, Hit)> = None;
            let mut consider = |t: f64, hit: Hit| {
                if t > 1e-6 && best.is_none_or(|(bt, _)| t < bt) {
                    best = Some((t, hit));
                }
            };
            if d[1] > 0.0 && height > 0.0 {
                consider(height / d[1], Hit::Ground);
            }
            for (i, o) in state.objects.iter().enumerate() {
                if let Some(t) = ray_box(d, &o.camera) {
                    consider(t, Hit::Object(i));
                }
            }
            for (i, b) in &solids {
                if let Some(t) = ray_box(d, b) {
                    consider(t, Hit::Solid(*i));
                }
            }
            let Some((t, hit)) = best else { continue };
            let p = CameraPoint::new(d[0] * t, d[1] * t, t);
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
                    let world = state.camera_pose.camera_to_world(p).bev();
                    for (i, polygon) in &grounds {
                        if let Some(e) = state.statics.get(*i)
                            && inside_polygon(world, polygon)
                        {
                            semantic[idx] = labels.id(e.class, None);
                            instance[idx] = e.id + 1;
                        }
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
        let t = ray_box([0.0, 0.1, 1.0], &b).unwrap();
        assert!(t > 7.5 && t < 10.0, "{t}");
        assert!(ray_box([0.5, 0.0, 1.0], &b).is_none());
        assert!(ray_box([0.0, 0.1, -1.0], &b).is_none(), "behind the camera");
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
