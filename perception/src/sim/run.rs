//! The simulation: kinematics of the ego camera and the agents, contacts,
//! the pinhole camera's view, the ground-truth event log and optional noise.

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::noise::apply_noise;
use super::scenario::{AgentSpec, MotionSpec, Phase, Scenario, default_size};
use crate::error::PerceptionError;
use nalgebra::Vector2;

use crate::coords::{CameraBev, CameraPoint, WorldBev, WorldPoint};
use crate::geometry::{convex_gap, footprint, point_in_polygon};
use crate::model::{
    BBox2D, Box3D, CameraConfig, CameraPose, ObjectClass, Observation, SceneObject, SceneState,
    Sequence, StaticElement, StaticShape, object_name_for,
};

/// Commanded acceleration (m/s²) beyond which a frame is labelled
/// `Accelerate` / `Brake` in the event log.
pub const EVENT_ACCEL_MPS2: f64 = 0.3;
/// Speed (m/s) below which a pedestrian stands.
pub const EVENT_STAND_MPS: f64 = 0.05;
/// Gap rate (m/s) beyond which a pair is `Approach` / `Recede` in the log.
pub const EVENT_GAP_RATE_MPS: f64 = 1.0;
/// Gap (m) at which a pedestrian reaches the vehicle it enters.
pub const ENTER_CONTACT_M: f64 = 0.25;
/// First track id handed out by simulated id switches.
pub const ID_SWITCH_BASE: u32 = 10_000;

/// What happens in a ground-truth event.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum EventKind {
    /// Commanded speed increase.
    Accelerate,
    /// Commanded speed decrease.
    Brake,
    /// Moving at constant commanded speed.
    ConstantSpeed,
    /// A vehicle at speed zero (stopped or crashed).
    Stop,
    /// A parked vehicle (never moves).
    Parked,
    /// A pedestrian walking off road and sidewalk.
    Walk,
    /// A pedestrian walking on a road (`other` = the road).
    CrossRoad,
    /// A pedestrian walking on a sidewalk (`other` = the sidewalk).
    WalkOnSidewalk,
    /// A pedestrian standing.
    Stand,
    /// A pedestrian gets into a vehicle (`other`), vanishing after `last_frame`.
    EnterVehicle,
    /// The object becomes visible at `first_frame`.
    AppearInView,
    /// The object is visible for the last time at `last_frame`.
    LeaveView,
    /// The gap to `other` shrinks faster than [`EVENT_GAP_RATE_MPS`].
    Approach,
    /// The gap to `other` grows faster than [`EVENT_GAP_RATE_MPS`].
    Recede,
    /// Footprints of the object and `other` touch at `first_frame`.
    Collide,
    /// Commanded merge into `other`'s lane.
    Merge,
}

/// One entry of the ground-truth event log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// What happens.
    pub kind: EventKind,
    /// The acting object's name (`car_3`).
    pub object: String,
    /// The other object, for relations.
    pub other: Option<String>,
    /// First frame (inclusive).
    pub first_frame: u32,
    /// Last frame (inclusive).
    pub last_frame: u32,
    /// Mean commanded acceleration (m/s²), speed (m/s) or gap rate (m/s).
    pub magnitude: f64,
}

impl Event {
    /// Whether the event spans every frame of `first..=last`.
    pub fn covers(&self, first: u32, last: u32) -> bool {
        self.first_frame <= first && self.last_frame >= last
    }
}

/// Everything one simulation produces.
#[derive(Debug, Clone)]
pub struct SimRun {
    /// The scenario simulated.
    pub scenario: Scenario,
    /// What the (possibly noisy) perception observed.
    pub sequence: Sequence,
    /// Ground-truth events, sorted by `(first_frame, object, kind)`.
    pub events: Vec<Event>,
    /// Per-frame ground-truth scene for renderers.
    pub states: Vec<SceneState>,
    /// True visibility per frame and object name (before noise).
    pub visible: Vec<std::collections::BTreeSet<String>>,
}

#[derive(Debug, Clone, Copy)]
struct Kin {
    pos: WorldBev,
    heading: f64,
    speed: f64,
}

#[derive(Debug, Clone)]
struct AgentRt {
    spec: AgentSpec,
    motion: MotionSpec,
    name: String,
    size: [f64; 3],
    kin: Kin,
    alive: bool,
    crashed: bool,
}

/// The unit vector of heading `h` in the world's `(X, Z)`.
fn dir(h: f64) -> Vector2<f64> {
    Vector2::new(h.sin(), h.cos())
}

fn active(phases: &[Phase], f: u32) -> Option<&Phase> {
    phases.iter().find(|p| p.from <= f && f < p.to)
}

/// Advances one frame; returns the realised acceleration.
fn step(kin: &mut Kin, phase: Option<&Phase>, f: u32, dt: f64, aim: Option<WorldBev>) -> f64 {
    let mut a = 0.0;
    let mut yaw_rate = 0.0;
    if let Some(p) = phase {
        let dur = f64::from(p.to - p.from) * dt;
        if let Some(acc) = p.accel {
            a = acc;
        } else if let Some(target) = p.speed_to {
            a = (target - kin.speed) / (f64::from(p.to - f) * dt);
        }
        if let Some(t) = p.turn_deg {
            yaw_rate = t.to_radians() / dur;
        }
    }
    if let Some(target) = aim {
        let d = target.0 - kin.pos.0;
        if d.x.abs() + d.y.abs() > 1e-9 {
            kin.heading = d.x.atan2(d.y);
        }
    }
    let v0 = kin.speed;
    let v1 = (v0 + a * dt).max(0.0);
    kin.heading += yaw_rate * dt;
    let d = dir(kin.heading);
    let s = 0.5 * (v0 + v1) * dt;
    kin.pos = WorldBev(kin.pos.0 + d * s);
    kin.speed = v1;
    (v1 - v0) / dt
}

fn world_box(kin: &Kin, size: [f64; 3]) -> Box3D {
    // KITTI yaw: heading direction (cos yaw, −sin yaw) = (sin h, cos h).
    Box3D {
        center: kin.pos.at_y(0.0).to_array(),
        size,
        yaw: kin.heading - std::f64::consts::FRAC_PI_2,
    }
}

/// The footprint of a box given in world coordinates.
fn world_footprint(b: &Box3D) -> [WorldBev; 4] {
    let center = WorldPoint::from_array(b.center).bev();
    footprint(center, b.size[1], b.size[2], b.yaw)
}

fn to_camera(pose: &CameraPose, b: &Box3D) -> Box3D {
    Box3D {
        center: pose
            .world_to_camera(WorldPoint::from_array(b.center))
            .to_array(),
        size: b.size,
        yaw: crate::geometry::wrap_angle(b.yaw - pose.yaw),
    }
}

/// Projects a camera-frame box; the clipped box and truncation when visible.
fn project_box(
    cam: &CameraConfig,
    view: &super::scenario::ViewSpec,
    b: &Box3D,
) -> Option<(BBox2D, f32)> {
    if b.center[2] > view.max_depth_m {
        return None;
    }
    let k = &cam.intrinsics;
    let corners = b
        .corners()
        .into_iter()
        .map(|c| k.project(CameraPoint(c), view.min_depth_m))
        .collect::<Option<Vec<_>>>()?;
    let full = BBox2D::enclosing(corners)?;
    let clipped = full.clip(k.image_width, k.image_height)?;
    if clipped.width() < view.min_box_px || clipped.height() < view.min_box_px {
        return None;
    }
    let trunc = if full.area() > 0.0 {
        (1.0 - clipped.area() / full.area()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    Some((clipped, trunc as f32))
}

/// Clips a camera-frame polygon to the half-plane `n·p <= c`.
fn clip_half(poly: &[CameraBev], n: Vector2<f64>, c: f64) -> Vec<CameraBev> {
    let mut out = Vec::with_capacity(poly.len() + 2);
    let m = poly.len();
    for i in 0..m {
        let (p, q) = (poly[i].0, poly[(i + 1) % m].0);
        let (dp, dq) = (n.dot(&p.coords) - c, n.dot(&q.coords) - c);
        if dp <= 0.0 {
            out.push(CameraBev(p));
        }
        if (dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0) {
            let t = dp / (dp - dq);
            out.push(CameraBev(p + (q - p) * t));
        }
    }
    out
}

fn polygon_area(p: &[CameraBev]) -> f64 {
    let n = p.len();
    (0..n)
        .map(|i| p[i].0.coords.perp(&p[(i + 1) % n].0.coords))
        .sum::<f64>()
        .abs()
        / 2.0
}

/// Visible part of a ground polygon in camera bird's-eye coordinates and its
/// image box.
fn view_surface(
    cam: &CameraConfig,
    view: &super::scenario::ViewSpec,
    pose: &CameraPose,
    poly: &[WorldBev],
) -> Option<(Vec<CameraBev>, BBox2D)> {
    let k = &cam.intrinsics;
    let mut p: Vec<CameraBev> = poly
        .iter()
        .map(|w| pose.world_to_camera(w.at_y(0.0)).bev())
        .collect();
    // Frustum: min/max depth and the left/right image edges.
    let right = (f64::from(k.image_width) - k.cx) / k.fx;
    let left = -k.cx / k.fx;
    p = clip_half(&p, Vector2::new(0.0, -1.0), -view.min_depth_m.max(1.0));
    p = clip_half(&p, Vector2::new(0.0, 1.0), view.max_depth_m);
    p = clip_half(&p, Vector2::new(1.0, -right), 0.0);
    p = clip_half(&p, Vector2::new(-1.0, left), 0.0);
    if p.len() < 3 || polygon_area(&p) < 1.0 {
        return None;
    }
    let projected = p
        .iter()
        .map(|v| k.project(v.at_y(cam.height_m), 0.0))
        .collect::<Option<Vec<_>>>()?;
    let bbox = BBox2D::enclosing(projected)?.clip(k.image_width, k.image_height)?;
    Some((p, bbox))
}

/// The serialized `[X, Z]` corners of a world rectangle.
fn rect(center: WorldBev, heading: f64, length: f64, width: f64) -> Vec<[f64; 2]> {
    // Heading h: along (sin h, cos h); across (cos h, −sin h).
    let (a, c) = (dir(heading), Vector2::new(heading.cos(), -heading.sin()));
    let (hl, hw) = (length / 2.0, width / 2.0);
    [(hl, hw), (hl, -hw), (-hl, -hw), (-hl, hw)]
        .iter()
        .map(|(u, v)| WorldBev(center.0 + a * *u + c * *v).xz())
        .collect()
}

/// Builds the static world; ids start at `base`.
/// The ground-truth observation of something seen in frame `f`: exact, with
/// no type, 3D box or surface yet (the callers add what they know).
fn truth(
    f: usize,
    id: u32,
    class: ObjectClass,
    color: &Option<String>,
    bbox: BBox2D,
) -> Observation {
    Observation {
        frame: f as u32,
        track_id: id,
        class,
        type_name: None,
        color: color.clone(),
        bbox: Some(bbox),
        position: None,
        size: None,
        yaw: None,
        confidence: 1.0,
        truncation: None,
        occlusion: None,
        footprint: None,
        depth_source: None,
    }
}

/// [`truth`] for a box `cb` (camera coordinates), unoccluded by definition.
fn truth_solid(
    f: usize,
    id: u32,
    class: ObjectClass,
    color: &Option<String>,
    bbox: BBox2D,
    cb: &Box3D,
    truncation: f32,
) -> Observation {
    Observation {
        position: Some(cb.center),
        size: Some(cb.size),
        yaw: Some(cb.yaw),
        truncation: Some(truncation),
        occlusion: Some(0),
        ..truth(f, id, class, color, bbox)
    }
}

fn statics(s: &Scenario, base: u32) -> Vec<StaticElement> {
    let mut out = Vec::new();
    let mut id = base;
    let mut add = |class: ObjectClass,
                   shape: StaticShape,
                   color: Option<String>,
                   out: &mut Vec<StaticElement>| {
        out.push(StaticElement {
            id,
            name: object_name_for(None, class, id),
            class,
            shape,
            color,
        });
        id += 1;
    };
    for r in &s.world.roads {
        let h = r.heading_deg.to_radians();
        add(
            ObjectClass::Road,
            StaticShape::Ground {
                polygon: rect(WorldBev::from_xz(r.center), h, r.length, r.width),
            },
            None,
            &mut out,
        );
    }
    for r in &s.world.roads {
        if r.sidewalk_width <= 0.0 {
            continue;
        }
        let h = r.heading_deg.to_radians();
        let across = Vector2::new(h.cos(), -h.sin());
        for side in [-1.0, 1.0] {
            let off = side * (r.width + r.sidewalk_width) / 2.0;
            let c = WorldBev(WorldBev::from_xz(r.center).0 + across * off);
            add(
                ObjectClass::Sidewalk,
                StaticShape::Ground {
                    polygon: rect(c, h, r.length, r.sidewalk_width),
                },
                None,
                &mut out,
            );
        }
    }
    for p in &s.world.props {
        let size = p.size.unwrap_or_else(|| default_size(p.class, None));
        let b = Box3D {
            center: WorldBev::from_xz(p.at).at_y(0.0).to_array(),
            size,
            yaw: p.heading_deg.to_radians() - std::f64::consts::FRAC_PI_2,
        };
        add(p.class, StaticShape::Solid(b), p.color.clone(), &mut out);
    }
    out
}

/// Runs a scenario. `seed` drives the noise model only; without noise the
/// run is fully determined by the scenario.
pub fn simulate(s: &Scenario, seed: u64) -> Result<SimRun, PerceptionError> {
    s.validate()?;
    let dt = 1.0 / s.fps;
    let frames = s.frames;
    let mut ego = Kin {
        pos: WorldBev::from_xz(s.ego.start),
        heading: s.ego.heading_deg.to_radians(),
        speed: s.ego.speed,
    };
    let mut agents: Vec<AgentRt> = s
        .agents
        .iter()
        .map(|a| AgentRt {
            spec: a.clone(),
            motion: a.motion(),
            name: object_name_for(a.type_name.as_deref(), a.class, a.id),
            size: a
                .size
                .unwrap_or_else(|| default_size(a.class, a.type_name.as_deref())),
            kin: Kin {
                pos: WorldBev::from_xz(a.start),
                heading: a.heading_deg.to_radians(),
                speed: if a.parked { 0.0 } else { a.speed },
            },
            alive: true,
            crashed: false,
        })
        .collect();
    agents.sort_by_key(|a| a.spec.id);
    let base = agents.iter().map(|a| a.spec.id + 1).max().unwrap_or(0);
    let world = Arc::new(statics(s, base));
    // The ground polygons as typed world points, once, by static index.
    let ground_polygons: Vec<Option<Vec<WorldBev>>> = world
        .iter()
        .map(|el| match &el.shape {
            StaticShape::Ground { polygon } => {
                Some(polygon.iter().copied().map(WorldBev::from_xz).collect())
            }
            StaticShape::Solid(_) => None,
        })
        .collect();
    let n_agents = agents.len();

    // Per frame, per agent: (alive, kin, realised accel).
    let mut history: Vec<Vec<(bool, Kin, f64)>> = Vec::with_capacity(frames as usize);
    let mut ego_history = Vec::with_capacity(frames as usize);
    let mut events = Vec::new();
    for f in 0..frames {
        ego_history.push(ego);
        history.push(agents.iter().map(|a| (a.alive, a.kin, 0.0)).collect());
        if f + 1 == frames {
            break;
        }
        step(&mut ego, active(&s.ego.phases, f), f, dt, None);
        for i in 0..n_agents {
            let (alive, parked, crashed) =
                (agents[i].alive, agents[i].spec.parked, agents[i].crashed);
            if !alive || parked || crashed {
                continue;
            }
            let phase = active(&agents[i].motion.phases, f).cloned();
            let aim = phase
                .as_ref()
                .and_then(|p| p.enter)
                .and_then(|v| agents.iter().find(|a| a.spec.id == v))
                .map(|a| a.kin.pos);
            let acc = step(&mut agents[i].kin, phase.as_ref(), f, dt, aim);
            if let Some(row) = history.last_mut() {
                row[i].2 = acc;
            }
        }
        // Contacts: collisions stop both vehicles; pedestrians entering a
        // vehicle vanish on contact.
        for i in 0..n_agents {
            for j in 0..n_agents {
                if i == j || !agents[i].alive || !agents[j].alive {
                    continue;
                }
                let fi = world_footprint(&world_box(&agents[i].kin, agents[i].size));
                let fj = world_footprint(&world_box(&agents[j].kin, agents[j].size));
                let gap = convex_gap(&fi, &fj);
                let enters = active(&agents[i].motion.phases, f).and_then(|p| p.enter)
                    == Some(agents[j].spec.id);
                if enters && gap <= ENTER_CONTACT_M {
                    agents[i].alive = false;
                    events.push(Event {
                        kind: EventKind::EnterVehicle,
                        object: agents[i].name.clone(),
                        other: Some(agents[j].name.clone()),
                        first_frame: f,
                        last_frame: f,
                        magnitude: gap,
                    });
                } else if i < j
                    && gap <= 0.0
                    && agents[i].spec.class == ObjectClass::Vehicle
                    && agents[j].spec.class == ObjectClass::Vehicle
                    && !(agents[i].crashed && agents[j].crashed)
                {
                    agents[i].crashed = true;
                    agents[j].crashed = true;
                    agents[i].kin.speed = 0.0;
                    agents[j].kin.speed = 0.0;
                    events.push(Event {
                        kind: EventKind::Collide,
                        object: agents[i].name.clone(),
                        other: Some(agents[j].name.clone()),
                        first_frame: f + 1,
                        last_frame: f + 1,
                        magnitude: 0.0,
                    });
                }
            }
        }
    }

    // Camera view and scene states.
    let mut states = Vec::with_capacity(frames as usize);
    let mut truth_obs: Vec<Observation> = Vec::new();
    let mut visible = vec![std::collections::BTreeSet::new(); frames as usize];
    for f in 0..frames as usize {
        let e = ego_history[f];
        let pose = CameraPose {
            position: e.pos.at_y(-s.camera.height_m).to_array(),
            yaw: e.heading,
        };
        let mut objects = Vec::with_capacity(n_agents);
        for (i, a) in agents.iter().enumerate() {
            let (alive, kin, _) = history[f][i];
            if !alive {
                continue;
            }
            let wb = world_box(&kin, a.size);
            let cb = to_camera(&pose, &wb);
            let seen = project_box(&s.camera, &s.view, &cb);
            if let Some((bbox, trunc)) = seen {
                visible[f].insert(a.name.clone());
                truth_obs.push(Observation {
                    type_name: a.spec.type_name.clone(),
                    ..truth_solid(f, a.spec.id, a.spec.class, &a.spec.color, bbox, &cb, trunc)
                });
            }
            objects.push(SceneObject {
                track_id: a.spec.id,
                name: a.name.clone(),
                class: a.spec.class,
                type_name: a.spec.type_name.clone(),
                color: a.spec.color.clone(),
                world: wb,
                camera: cb,
                bbox: seen.map(|x| x.0),
                visible: seen.is_some(),
            });
        }
        for (k, el) in world.iter().enumerate() {
            match &el.shape {
                StaticShape::Solid(wb) => {
                    let cb = to_camera(&pose, wb);
                    if let Some((bbox, trunc)) = project_box(&s.camera, &s.view, &cb) {
                        visible[f].insert(el.name.clone());
                        truth_obs
                            .push(truth_solid(f, el.id, el.class, &el.color, bbox, &cb, trunc));
                    }
                }
                StaticShape::Ground { .. } => {
                    if let Some(polygon) = ground_polygons[k].as_deref()
                        && let Some((poly, bbox)) = view_surface(&s.camera, &s.view, &pose, polygon)
                    {
                        visible[f].insert(el.name.clone());
                        truth_obs.push(Observation {
                            footprint: Some(poly.iter().map(CameraBev::xz).collect()),
                            ..truth(f, el.id, el.class, &el.color, bbox)
                        });
                    }
                }
            }
        }
        states.push(SceneState {
            frame: f as u32,
            camera_pose: pose,
            camera: s.camera,
            objects,
            statics: Arc::clone(&world),
        });
    }

    // Event log: motion labels, visibility, relations.
    #[allow(clippy::needless_range_loop)] // frames index several parallel per-frame tables
    for (i, a) in agents.iter().enumerate() {
        let mut labels: Vec<Option<(EventKind, Option<String>, f64)>> =
            Vec::with_capacity(frames as usize);
        for f in 0..frames as usize {
            let (alive, kin, acc) = history[f][i];
            if !alive {
                labels.push(None);
                continue;
            }
            let crashed_now = events.iter().any(|e| {
                e.kind == EventKind::Collide
                    && e.first_frame as usize <= f
                    && (e.object == a.name || e.other.as_deref() == Some(&a.name))
            });
            let label = if a.spec.class.is_person_like() {
                if kin.speed < EVENT_STAND_MPS {
                    (EventKind::Stand, None, kin.speed)
                } else {
                    let on = |class: ObjectClass| {
                        world
                            .iter()
                            .zip(&ground_polygons)
                            .find(|(el, polygon)| {
                                el.class == class
                                    && polygon
                                        .as_deref()
                                        .is_some_and(|p| point_in_polygon(kin.pos, p))
                            })
                            .map(|(el, _)| el)
                    };
                    match (on(ObjectClass::Road), on(ObjectClass::Sidewalk)) {
                        (Some(r), _) => (EventKind::CrossRoad, Some(r.name.clone()), kin.speed),
                        (None, Some(w)) => {
                            (EventKind::WalkOnSidewalk, Some(w.name.clone()), kin.speed)
                        }
                        _ => (EventKind::Walk, None, kin.speed),
                    }
                }
            } else if a.spec.parked {
                (EventKind::Parked, None, 0.0)
            } else if crashed_now || (kin.speed == 0.0 && acc.abs() < EVENT_ACCEL_MPS2) {
                (EventKind::Stop, None, 0.0)
            } else if acc > EVENT_ACCEL_MPS2 {
                (EventKind::Accelerate, None, acc)
            } else if acc < -EVENT_ACCEL_MPS2 {
                (EventKind::Brake, None, acc)
            } else {
                (EventKind::ConstantSpeed, None, kin.speed)
            };
            labels.push(Some(label));
        }
        // The last frame has no step of its own: it continues the previous label.
        let last_alive = (0..frames as usize).rev().find(|&f| history[f][i].0);
        if let Some(l) = last_alive.filter(|l| *l > 0)
            && let (Some(Some(prev)), true) = (labels.get(l - 1).cloned(), history[l - 1][i].0)
            && !matches!(
                labels[l],
                Some((
                    EventKind::Parked
                        | EventKind::Stand
                        | EventKind::CrossRoad
                        | EventKind::WalkOnSidewalk
                        | EventKind::Walk,
                    _,
                    _
                ))
            )
        {
            labels[l] = Some(prev);
        }
        group_labels(&labels, &a.name, &mut events);
        // Visibility transitions.
        for f in 0..frames as usize {
            let v = visible[f].contains(&a.name);
            if v && f > 0 && !visible[f - 1].contains(&a.name) {
                events.push(Event {
                    kind: EventKind::AppearInView,
                    object: a.name.clone(),
                    other: None,
                    first_frame: f as u32,
                    last_frame: f as u32,
                    magnitude: 0.0,
                });
            }
            if v && f + 1 < frames as usize && !visible[f + 1].contains(&a.name) {
                events.push(Event {
                    kind: EventKind::LeaveView,
                    object: a.name.clone(),
                    other: None,
                    first_frame: f as u32,
                    last_frame: f as u32,
                    magnitude: 0.0,
                });
            }
        }
        for p in &a.motion.phases {
            if let Some(v) = p
                .merge_into
                .and_then(|id| agents.iter().find(|b| b.spec.id == id))
            {
                events.push(Event {
                    kind: EventKind::Merge,
                    object: a.name.clone(),
                    other: Some(v.name.clone()),
                    first_frame: p.from,
                    last_frame: p.to.saturating_sub(1),
                    magnitude: p.turn_deg.unwrap_or(0.0),
                });
            }
        }
    }
    // Approach / Recede between road users, from the true footprint gaps.
    for i in 0..n_agents {
        for j in i + 1..n_agents {
            let gaps: Vec<Option<f64>> = (0..frames as usize)
                .map(|f| {
                    let (ai, ki, _) = history[f][i];
                    let (aj, kj, _) = history[f][j];
                    (ai && aj).then(|| {
                        convex_gap(
                            &world_footprint(&world_box(&ki, agents[i].size)),
                            &world_footprint(&world_box(&kj, agents[j].size)),
                        )
                    })
                })
                .collect();
            let mut labels: Vec<Option<(EventKind, Option<String>, f64)>> =
                vec![None; frames as usize];
            for f in 0..frames as usize {
                let (lo, hi) = (f.saturating_sub(1), (f + 1).min(frames as usize - 1));
                if let (Some(a), Some(b), Some(_)) = (gaps[lo], gaps[hi], gaps[f])
                    && hi > lo
                {
                    let rate = (b - a) / ((hi - lo) as f64 * dt);
                    if rate < -EVENT_GAP_RATE_MPS {
                        labels[f] = Some((EventKind::Approach, Some(agents[j].name.clone()), rate));
                    } else if rate > EVENT_GAP_RATE_MPS {
                        labels[f] = Some((EventKind::Recede, Some(agents[j].name.clone()), rate));
                    }
                }
            }
            group_labels(&labels, &agents[i].name, &mut events);
        }
    }
    events.sort_by(|a, b| {
        (a.first_frame, &a.object, a.kind, &a.other).cmp(&(
            b.first_frame,
            &b.object,
            b.kind,
            &b.other,
        ))
    });

    let mut observations = truth_obs;
    if let Some(spec) = s.noise {
        observations = apply_noise(observations, spec, seed, &s.camera);
    }
    let mut sequence = Sequence {
        name: s.name.clone(),
        source: "sim".into(),
        camera: s.camera,
        frame_count: frames,
        fps: s.fps,
        observations,
        timestamps_ns: None,
        ego_poses: None,
        map: None,
        track_keys: Default::default(),
        skipped: Vec::new(),
    };
    sequence.sort();
    sequence.validate()?;
    Ok(SimRun {
        scenario: s.clone(),
        sequence,
        events,
        states,
        visible,
    })
}

/// Groups runs of equal per-frame labels into events.
fn group_labels(
    labels: &[Option<(EventKind, Option<String>, f64)>],
    object: &str,
    out: &mut Vec<Event>,
) {
    let mut f = 0;
    while f < labels.len() {
        let Some((kind, other, _)) = &labels[f] else {
            f += 1;
            continue;
        };
        let mut g = f;
        let mut sum = 0.0;
        while g < labels.len()
            && labels[g]
                .as_ref()
                .is_some_and(|(k, o, _)| k == kind && o == other)
        {
            sum += labels[g].as_ref().map_or(0.0, |l| l.2);
            g += 1;
        }
        out.push(Event {
            kind: *kind,
            object: object.to_string(),
            other: other.clone(),
            first_frame: f as u32,
            last_frame: (g - 1) as u32,
            magnitude: sum / (g - f) as f64,
        });
        f = g;
    }
}

/// Per-frame scene states of a scenario, for renderers.
pub fn scene_states(s: &Scenario) -> Result<Vec<SceneState>, PerceptionError> {
    Ok(simulate(s, 0)?.states)
}
