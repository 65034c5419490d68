//! Multi-object tracking by bipartite matching.
//!
//! Each frame, live tracks are predicted into the frame — shifted by the mean
//! optical flow inside their last box when a flow map is given, otherwise by
//! their constant per-frame box velocity — and matched to the frame's
//! detections with the Hungarian algorithm (`pathfinding::kuhn_munkres`) on
//! IoU, classes kept apart. Unmatched detections start tracks with fresh ids;
//! tracks survive up to `max_misses` frames without a match, so a detector's
//! short dropout does not change an object's id.

use pathfinding::kuhn_munkres::kuhn_munkres;
use pathfinding::matrix::Matrix;

use super::decode::DenseMap;
use crate::model::{BBox2D, ObjectClass};

/// Tracker settings.
///
/// Invariant: `min_iou` in `(0, 1]`, `velocity_smoothing` in `[0, 1]`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackerConfig {
    /// Least IoU between a predicted track box and a detection to match.
    pub min_iou: f64,
    /// Frames a track may go unmatched before it ends.
    pub max_misses: u32,
    /// Weight of the newest displacement in the velocity estimate
    /// (exponential smoothing; 1 = last displacement only).
    pub velocity_smoothing: f64,
}

impl Default for TrackerConfig {
    fn default() -> Self {
        TrackerConfig {
            min_iou: 0.25,
            max_misses: 3,
            velocity_smoothing: 0.6,
        }
    }
}

/// What the tracker needs of a detection.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackInput {
    /// Class (tracks never change class).
    pub class: ObjectClass,
    /// Box in frame pixels.
    pub bbox: BBox2D,
}

#[derive(Debug, Clone)]
struct LiveTrack {
    id: u32,
    class: ObjectClass,
    bbox: BBox2D,
    /// Per-frame change of (left, top, right, bottom).
    velocity: [f64; 4],
    last_frame: u32,
    hits: u32,
}

impl LiveTrack {
    fn predict(&self, frame: u32, flow: Option<&DenseMap<f32>>) -> BBox2D {
        let gap = f64::from(frame.saturating_sub(self.last_frame));
        if let Some(flow) = flow.filter(|_| gap <= 1.0)
            && let Some([dx, dy]) = mean_flow(flow, &self.bbox)
        {
            return shift(&self.bbox, [dx, dy, dx, dy], 1.0);
        }
        let b = shift(&self.bbox, self.velocity, gap);
        // A shrinking velocity must not invert the box.
        if b.is_valid() { b } else { self.bbox }
    }
}

fn shift(b: &BBox2D, d: [f64; 4], times: f64) -> BBox2D {
    BBox2D {
        left: b.left + d[0] * times,
        top: b.top + d[1] * times,
        right: b.right + d[2] * times,
        bottom: b.bottom + d[3] * times,
    }
}

/// Mean `(dx, dy)` of a two-channel flow map over the pixels of `b`; `None`
/// when the box covers no pixel of the map.
pub fn mean_flow(flow: &DenseMap<f32>, b: &BBox2D) -> Option<[f64; 2]> {
    if flow.channels < 2 {
        return None;
    }
    let x0 = b.left.max(0.0).floor() as usize;
    let y0 = b.top.max(0.0).floor() as usize;
    let x1 = (b.right.max(0.0).ceil() as usize).min(flow.width);
    let y1 = (b.bottom.max(0.0).ceil() as usize).min(flow.height);
    let (mut sx, mut sy, mut n) = (0.0f64, 0.0f64, 0usize);
    for y in y0..y1 {
        for x in x0..x1 {
            if let (Some(dx), Some(dy)) = (flow.get(x, y, 0), flow.get(x, y, 1)) {
                sx += f64::from(dx);
                sy += f64::from(dy);
                n += 1;
            }
        }
    }
    (n > 0).then(|| [sx / n as f64, sy / n as f64])
}

/// The tracker. Feed it frames in increasing order with [`Tracker::step`].
///
/// Invariant: ids are handed out in increasing order from 0 and never reused;
/// live tracks are kept sorted by id.
#[derive(Debug, Clone)]
pub struct Tracker {
    config: TrackerConfig,
    live: Vec<LiveTrack>,
    next_id: u32,
}

/// IoU is scaled to integers for the assignment: `kuhn_munkres` needs an
/// exactly ordered weight type.
const WEIGHT_SCALE: f64 = 1_000_000.0;

impl Tracker {
    /// A tracker with no tracks.
    pub fn new(config: TrackerConfig) -> Tracker {
        Tracker {
            config,
            live: Vec::new(),
            next_id: 0,
        }
    }

    /// Number of live tracks.
    pub fn live_tracks(&self) -> usize {
        self.live.len()
    }

    /// Assigns a track id to every detection of `frame`. `flow` is the forward
    /// flow of the previous frame (its pixels' motion into this frame), when
    /// known.
    pub fn step(
        &mut self,
        frame: u32,
        detections: &[TrackInput],
        flow: Option<&DenseMap<f32>>,
    ) -> Vec<u32> {
        // A track last seen at frame f has missed frames f+1 .. frame-1.
        let max_gap = self.config.max_misses.saturating_add(1);
        self.live
            .retain(|t| frame.saturating_sub(t.last_frame) <= max_gap);
        let predicted: Vec<BBox2D> = self.live.iter().map(|t| t.predict(frame, flow)).collect();
        let mut assigned: Vec<Option<usize>> = vec![None; detections.len()];
        let weight = |ti: usize, di: usize| -> i64 {
            let (Some(t), Some(p), Some(d)) =
                (self.live.get(ti), predicted.get(ti), detections.get(di))
            else {
                return 0;
            };
            if t.class != d.class {
                return 0;
            }
            let iou = p.iou(&d.bbox);
            if iou >= self.config.min_iou {
                (iou * WEIGHT_SCALE).round() as i64
            } else {
                0
            }
        };
        let (nt, nd) = (self.live.len(), detections.len());
        if nt > 0 && nd > 0 {
            if nt <= nd {
                let m = Matrix::from_fn(nt, nd, |(t, d)| weight(t, d));
                let (_, cols) = kuhn_munkres(&m);
                for (t, &d) in cols.iter().enumerate() {
                    if weight(t, d) > 0
                        && let Some(slot) = assigned.get_mut(d)
                    {
                        *slot = Some(t);
                    }
                }
            } else {
                let m = Matrix::from_fn(nd, nt, |(d, t)| weight(t, d));
                let (_, cols) = kuhn_munkres(&m);
                for (d, &t) in cols.iter().enumerate() {
                    if weight(t, d) > 0
                        && let Some(slot) = assigned.get_mut(d)
                    {
                        *slot = Some(t);
                    }
                }
            }
        }
        let alpha = self.config.velocity_smoothing;
        let mut ids = Vec::with_capacity(nd);
        for (di, det) in detections.iter().enumerate() {
            match assigned
                .get(di)
                .copied()
                .flatten()
                .and_then(|t| self.live.get_mut(t))
            {
                Some(track) => {
                    let gap = f64::from(frame.saturating_sub(track.last_frame).max(1));
                    let step = [
                        (det.bbox.left - track.bbox.left) / gap,
                        (det.bbox.top - track.bbox.top) / gap,
                        (det.bbox.right - track.bbox.right) / gap,
                        (det.bbox.bottom - track.bbox.bottom) / gap,
                    ];
                    for (v, s) in track.velocity.iter_mut().zip(step) {
                        *v = if track.hits == 1 {
                            s
                        } else {
                            alpha * s + (1.0 - alpha) * *v
                        };
                    }
                    track.bbox = det.bbox;
                    track.last_frame = frame;
                    track.hits += 1;
                    ids.push(track.id);
                }
                None => {
                    let id = self.next_id;
                    self.next_id += 1;
                    self.live.push(LiveTrack {
                        id,
                        class: det.class,
                        bbox: det.bbox,
                        velocity: [0.0; 4],
                        last_frame: frame,
                        hits: 1,
                    });
                    ids.push(id);
                }
            }
        }
        self.live.sort_by_key(|t| t.id);
        ids
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn b(l: f64, t: f64, w: f64, h: f64) -> BBox2D {
        BBox2D {
            left: l,
            top: t,
            right: l + w,
            bottom: t + h,
        }
    }

    fn car(bbox: BBox2D) -> TrackInput {
        TrackInput {
            class: ObjectClass::Vehicle,
            bbox,
        }
    }

    #[test]
    fn ids_are_stable_through_crossing_and_short_misses() {
        let mut tr = Tracker::new(TrackerConfig::default());
        // Two cars moving towards each other 12 px per frame, overlapping
        // mid-way; car B is missed for two frames.
        let mut a_ids = Vec::new();
        let mut b_ids = Vec::new();
        for f in 0..20u32 {
            let ax = 10.0 + 12.0 * f64::from(f);
            let bx = 250.0 - 12.0 * f64::from(f);
            let mut dets = vec![car(b(ax, 50.0, 40.0, 30.0))];
            let b_seen = !(8..10).contains(&f);
            if b_seen {
                dets.push(car(b(bx, 52.0, 40.0, 30.0)));
            }
            let ids = tr.step(f, &dets, None);
            a_ids.push(ids[0]);
            if b_seen {
                b_ids.push(ids[1]);
            }
        }
        assert!(a_ids.iter().all(|&i| i == a_ids[0]), "{a_ids:?}");
        assert!(b_ids.iter().all(|&i| i == b_ids[0]), "{b_ids:?}");
        assert_ne!(a_ids[0], b_ids[0]);
    }

    #[test]
    fn classes_never_match_and_long_misses_end_tracks() {
        let mut tr = Tracker::new(TrackerConfig::default());
        let box0 = b(0.0, 0.0, 20.0, 40.0);
        let first = tr.step(0, &[car(box0)], None);
        let ped = tr.step(
            1,
            &[TrackInput {
                class: ObjectClass::Pedestrian,
                bbox: box0,
            }],
            None,
        );
        assert_ne!(first, ped);
        let again = tr.step(10, &[car(box0)], None);
        assert_ne!(
            again, first,
            "a track missed for 9 frames must not come back"
        );
        assert_eq!(tr.live_tracks(), 1);
    }

    #[test]
    fn flow_prediction_carries_fast_objects() {
        // A 20 px wide box jumping 30 px per frame never overlaps its last
        // position; flow says where it went.
        let mut flow = DenseMap {
            width: 200,
            height: 50,
            channels: 2,
            data: vec![0.0f32; 200 * 50 * 2],
        };
        for px in flow.data.chunks_exact_mut(2) {
            px[0] = 30.0;
        }
        let mut with = Tracker::new(TrackerConfig::default());
        let mut without = Tracker::new(TrackerConfig::default());
        let a = with.step(0, &[car(b(10.0, 10.0, 20.0, 20.0))], None);
        let _ = without.step(0, &[car(b(10.0, 10.0, 20.0, 20.0))], None);
        assert_eq!(
            with.step(1, &[car(b(40.0, 10.0, 20.0, 20.0))], Some(&flow)),
            a
        );
        assert_ne!(without.step(1, &[car(b(40.0, 10.0, 20.0, 20.0))], None), a);
    }

    proptest! {
        #[test]
        fn ids_are_unique_within_a_frame(boxes in proptest::collection::vec((0.0f64..300.0, 0.0f64..100.0, 5.0f64..60.0), 0..12), frames in 1u32..5) {
            let mut tr = Tracker::new(TrackerConfig::default());
            for f in 0..frames {
                let dets: Vec<TrackInput> = boxes.iter().map(|&(x, y, s)| car(b(x + f64::from(f), y, s, s))).collect();
                let ids = tr.step(f, &dets, None);
                let mut sorted = ids.clone();
                sorted.sort_unstable();
                sorted.dedup();
                prop_assert_eq!(sorted.len(), ids.len());
            }
        }
    }
}
