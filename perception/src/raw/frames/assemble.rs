//! Per-frame candidates (detections or dense instances) into tracked
//! observations with a 3D position and a majority colour: the stage every
//! frames run and every dense-map run ends in.

use super::FramesOptions;
use crate::coords::CameraPoint;
use crate::model::{BBox2D, CameraConfig, DepthSource, ObjectClass, Observation, Sequence};
use crate::raw::RawError;
use crate::raw::config::{DepthMode, OutputSpec, RelativeDepth};
use crate::raw::decode::DenseMap;
use crate::raw::ground::GroundConfig;
use crate::raw::mono::{DepthEstimate, MonoDepthConfig, centre_offset_m, estimate};
use crate::raw::relative::{align, is_anchor};
use crate::raw::tracker::{TrackInput, Tracker};

/// One object of one frame before tracking.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Candidate {
    pub(super) class: ObjectClass,
    pub(super) type_name: Option<String>,
    pub(super) bbox: BBox2D,
    pub(super) score: f32,
    pub(super) color: Option<&'static str>,
    /// Metric depth of the visible near surface from a metric depth map,
    /// metres.
    pub(super) depth_m: Option<f64>,
    /// Raw sample of a relative depth map (near surface, unknown scale and
    /// shift) and how to read it.
    pub(super) relative: Option<(f64, RelativeDepth)>,
}

/// How the `depth:` model's map is used.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum DepthUse {
    /// Metres: each box's sample is its depth.
    Metric,
    /// Unknown scale (and shift): fitted per frame to the monocular
    /// estimates.
    Relative(RelativeDepth),
}

impl DepthUse {
    /// Relative for a `mode: relative` depth model (inverse depth unless its
    /// `relative:` says otherwise), metric for any other config: only a depth
    /// model yields a depth map, so the reading of other kinds never matters
    /// (and [`super::ModelSet::check_kinds`] refuses them in the `depth:` slot).
    pub(super) fn of(output: &OutputSpec) -> DepthUse {
        match output {
            OutputSpec::Depth {
                mode: DepthMode::Relative,
                relative,
                ..
            } => DepthUse::Relative(relative.unwrap_or_default()),
            _ => DepthUse::Metric,
        }
    }
}

/// Turns per-frame candidates into tracked observations: tracker ids, 3D
/// position (metric depth when known; else relative depth through the
/// frame's [`crate::raw::relative::Alignment`]; else the configured monocular
/// estimate — the source recorded in `Observation::depth_source`), and a
/// per-track majority colour. A depth map sees the object's near surface,
/// so a map depth gets the same nearest-face → centre offset as the
/// monocular estimate ([`centre_offset_m`]); one beyond
/// [`GroundConfig::max_depth_m`] (an inverse-depth sample near zero, sky) is
/// no estimate and the box keeps its monocular one.
pub(super) struct Assembler {
    tracker: Tracker,
    camera: CameraConfig,
    ground: GroundConfig,
    mono: MonoDepthConfig,
    observations: Vec<Observation>,
}

impl Assembler {
    pub(super) fn new(camera: CameraConfig, options: &FramesOptions) -> Assembler {
        Assembler {
            tracker: Tracker::new(options.tracker),
            camera,
            ground: options.ground,
            mono: options.mono.clone(),
            observations: Vec::new(),
        }
    }

    pub(super) fn frame(
        &mut self,
        frame: u32,
        candidates: Vec<Candidate>,
        flow: Option<&DenseMap<f32>>,
    ) {
        let inputs: Vec<TrackInput> = candidates
            .iter()
            .map(|c| TrackInput {
                class: c.class,
                bbox: c.bbox,
            })
            .collect();
        let ids = self.tracker.step(frame, &inputs, flow);
        let monos: Vec<Option<DepthEstimate>> = candidates
            .iter()
            .map(|c| {
                estimate(
                    &c.bbox,
                    c.type_name.as_deref(),
                    &self.camera,
                    &self.ground,
                    &self.mono,
                )
            })
            .collect();
        // The frame's fit of relative samples onto the near-face depths of
        // the anchor boxes (one depth model per run, so one reading).
        let kind = candidates.iter().find_map(|c| c.relative.map(|(_, k)| k));
        let alignment = kind.and_then(|kind| {
            align(
                kind,
                candidates.iter().zip(&monos).filter_map(|(c, m)| {
                    let m = m.as_ref().filter(|m| is_anchor(m))?;
                    let (sample, _) = c.relative.filter(|(_, k)| *k == kind)?;
                    Some((sample, m.near_z()))
                }),
            )
        });
        let k = self.camera.intrinsics;
        let max_depth = self.ground.max_depth_m;
        for ((c, mono), track_id) in candidates.into_iter().zip(monos).zip(ids) {
            let offset = centre_offset_m(&self.mono, c.type_name.as_deref());
            // A map's near-surface depth placed as the monocular estimate
            // places its own: the footprint centre `offset` behind the near
            // face, on the ground seen at the box's bottom row.
            let place = |near: f64| {
                let z = near + offset;
                if !(near > 0.0 && z.is_finite() && z <= max_depth) {
                    return None;
                }
                let (u, v) = (c.bbox.center_x(), c.bbox.bottom);
                let ground_y = k.back_project(u, v, near).0.y;
                let centre = k.back_project(u, v, z).0;
                Some(CameraPoint::new(centre.x, ground_y, centre.z))
            };
            let from_map = c
                .depth_m
                .and_then(place)
                .map(|p| (p, DepthSource::DepthMap));
            let from_relative = || {
                let (sample, _) = c.relative?;
                let p = place(alignment?.depth(sample)?)?;
                Some((p, DepthSource::RelativeAligned))
            };
            let (position, depth_source) = from_map
                .or_else(from_relative)
                .or(mono.map(|e| (e.position, e.source)))
                .unzip();
            self.observations.push(Observation {
                frame,
                track_id,
                class: c.class,
                type_name: c.type_name,
                color: c.color.map(str::to_string),
                bbox: Some(c.bbox),
                position: position.map(|p| p.to_array()),
                size: None,
                yaw: None,
                confidence: c.score.clamp(0.0, 1.0),
                truncation: None,
                occlusion: None,
                footprint: None,
                depth_source,
            });
        }
    }

    pub(super) fn finish(
        mut self,
        name: String,
        source: &str,
        frame_count: u32,
        fps: f64,
    ) -> Result<Sequence, RawError> {
        // One colour per object: the most frequent per-frame name (ties to
        // the earlier value), so a shadowed frame does not recolour a car.
        let mut votes: std::collections::BTreeMap<u32, std::collections::BTreeMap<String, usize>> =
            Default::default();
        for o in &self.observations {
            if let Some(c) = &o.color {
                *votes
                    .entry(o.track_id)
                    .or_default()
                    .entry(c.clone())
                    .or_default() += 1;
            }
        }
        let winner = |id: u32| -> Option<String> {
            votes.get(&id).and_then(|v| {
                v.iter()
                    .max_by(|a, b| a.1.cmp(b.1).then(b.0.cmp(a.0)))
                    .map(|(c, _)| c.clone())
            })
        };
        for o in &mut self.observations {
            o.color = winner(o.track_id);
        }
        let mut seq = Sequence {
            name,
            source: source.to_string(),
            camera: self.camera,
            frame_count,
            fps,
            observations: self.observations,
            timestamps_ns: None,
            ego_poses: None,
            map: None,
            track_keys: Default::default(),
            skipped: Vec::new(),
        };
        seq.sort();
        seq.validate()?;
        Ok(seq)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::raw::mono::test_support::car_box;
    use crate::raw::mono::{KITTI_CAR, MonoDepthMethod};

    fn kitti() -> CameraConfig {
        crate::kitti::KITTI_2011_09_26_CAMERA
    }

    fn car(bbox: BBox2D, depth_m: Option<f64>) -> Candidate {
        Candidate {
            class: ObjectClass::Vehicle,
            type_name: Some("Car".into()),
            bbox,
            score: 0.9,
            color: None,
            depth_m,
            relative: None,
        }
    }

    fn with_relative(c: Candidate, sample: f64, kind: RelativeDepth) -> Candidate {
        Candidate {
            relative: Some((sample, kind)),
            ..c
        }
    }

    fn z_of(o: &Observation) -> f64 {
        o.position.map_or(f64::NAN, |p| p[2])
    }

    #[test]
    fn a_depth_map_overrides_the_monocular_estimate_and_each_position_names_its_method() {
        let bbox = BBox2D {
            left: 500.0,
            top: 180.0,
            right: 600.0,
            bottom: 260.0,
        };
        let mut asm = Assembler::new(kitti(), &FramesOptions::default());
        asm.frame(
            0,
            vec![
                car(bbox, Some(23.0)),
                car(
                    BBox2D {
                        left: 800.0,
                        right: 900.0,
                        ..bbox
                    },
                    None,
                ),
            ],
            None,
        );
        let [with_map, without] = [&asm.observations[0], &asm.observations[1]];
        assert_eq!(with_map.depth_source, Some(DepthSource::DepthMap));
        // The map sees the near face; the position is the footprint centre.
        let want = 23.0 + KITTI_CAR.half_depth_extent_m();
        assert!((z_of(with_map) - want).abs() < 1e-9, "{with_map:?}");
        assert_eq!(without.depth_source, Some(DepthSource::Fused));
        let z = without.position.map(|p| p[2]).unwrap_or(f64::NAN);
        assert!(z > 5.0 && z < 20.0, "{z}");
        // The configured method is the one used.
        let flat = FramesOptions {
            mono: MonoDepthConfig::default().with_method(MonoDepthMethod::FlatGround),
            ..FramesOptions::default()
        };
        let mut asm = Assembler::new(kitti(), &flat);
        asm.frame(0, vec![car(bbox, None)], None);
        assert_eq!(
            asm.observations[0].depth_source,
            Some(DepthSource::FlatGround)
        );
    }

    #[test]
    fn relative_depth_is_scaled_per_frame_onto_the_monocular_near_faces() {
        let camera = kitti();
        let options = FramesOptions::default();
        let boxes = [
            BBox2D {
                left: 500.0,
                top: 180.0,
                right: 600.0,
                bottom: 260.0,
            },
            BBox2D {
                left: 800.0,
                top: 170.0,
                right: 860.0,
                bottom: 215.0,
            },
            BBox2D {
                left: 200.0,
                top: 175.0,
                right: 280.0,
                bottom: 235.0,
            },
            // Bottom above the horizon (cy 172.9) and top cut by the image:
            // no monocular estimate, but the relative map still places it.
            BBox2D {
                left: 1000.0,
                top: 0.0,
                right: 1040.0,
                bottom: 150.0,
            },
        ];
        let mono: Vec<Option<f64>> = boxes
            .iter()
            .map(|b| {
                estimate(b, Some("Car"), &camera, &options.ground, &options.mono)
                    .map(|e| e.near_z())
            })
            .collect();
        assert!(
            mono[..3].iter().all(Option::is_some) && mono[3].is_none(),
            "{mono:?}"
        );
        // Relative values with other ratios than the monocular depths.
        let relative = [2.0, 5.0, 3.0, 9.0];
        let mut ratios: Vec<f64> = (0..3)
            .map(|i| mono[i].unwrap_or(f64::NAN) / relative[i])
            .collect();
        ratios.sort_by(f64::total_cmp);
        let scale = ratios[1];
        let mut asm = Assembler::new(camera, &options);
        let candidates = boxes
            .iter()
            .zip(relative)
            .map(|(b, r)| with_relative(car(*b, None), r, RelativeDepth::Depth))
            .collect();
        asm.frame(0, candidates, None);
        for (o, r) in asm.observations.iter().zip(relative) {
            assert_eq!(o.depth_source, Some(DepthSource::RelativeAligned), "{o:?}");
            let want = scale * r + KITTI_CAR.half_depth_extent_m();
            assert!((z_of(o) - want).abs() < 1e-9, "{} vs {want}", z_of(o));
        }
        // A metric depth still wins over an aligned relative one.
        let mut asm = Assembler::new(camera, &options);
        asm.frame(
            0,
            vec![
                with_relative(car(boxes[0], Some(23.0)), 2.0, RelativeDepth::Depth),
                with_relative(car(boxes[1], None), 5.0, RelativeDepth::Depth),
            ],
            None,
        );
        assert_eq!(
            asm.observations[0].depth_source,
            Some(DepthSource::DepthMap)
        );
        assert_eq!(
            asm.observations[1].depth_source,
            Some(DepthSource::RelativeAligned)
        );
    }

    #[test]
    fn a_frame_without_an_alignable_box_keeps_the_monocular_estimates() {
        let camera = kitti();
        let options = FramesOptions::default();
        // Cut by the image's bottom edge (375 rows): its flat-ground depth is
        // an overestimate and is not used to align.
        let cut = BBox2D {
            left: 500.0,
            top: 200.0,
            right: 700.0,
            bottom: 374.0,
        };
        let above = BBox2D {
            left: 1000.0,
            top: 0.0,
            right: 1040.0,
            bottom: 150.0,
        };
        let mut asm = Assembler::new(camera, &options);
        asm.frame(
            0,
            vec![
                with_relative(car(cut, None), 2.0, RelativeDepth::Depth),
                with_relative(car(above, None), 4.0, RelativeDepth::Depth),
            ],
            None,
        );
        let mono = estimate(&cut, Some("Car"), &camera, &options.ground, &options.mono);
        assert!(mono.is_some_and(|m| m.cut_by_image), "{mono:?}");
        assert_eq!(asm.observations[0].depth_source, mono.map(|m| m.source));
        assert_eq!(
            asm.observations[0].camera_position(),
            mono.map(|m| m.position)
        );
        assert_eq!(asm.observations[1].depth_source, None);
        assert_eq!(asm.observations[1].position, None);
    }

    /// Road-aligned KITTI-sized cars with footprint centres at `zs` (x
    /// spread across the image), their boxes, and exact monocular estimates.
    fn cars_at(zs: &[f64]) -> Vec<(f64, BBox2D)> {
        let camera = kitti();
        zs.iter()
            .enumerate()
            .map(|(i, &z)| {
                let x = -4.0 + 3.0 * i as f64;
                (z, car_box(&camera, &KITTI_CAR, x, camera.height_m, z))
            })
            .collect()
    }

    #[test]
    fn a_map_of_the_near_face_gives_the_footprint_centre_back() {
        // Regression: alignment compared mono's footprint centres with the
        // map's near-surface samples, a distance-dependent bias (−15% at
        // 8 m to +6% at 40 m here), and a metric map's surface depth was
        // used as the centre.
        let camera = kitti();
        let options = FramesOptions::default();
        let cars = cars_at(&[8.0, 15.0, 25.0, 40.0]);
        let half = KITTI_CAR.half_depth_extent_m();
        for (z, b) in &cars {
            let e = estimate(b, Some("Car"), &camera, &options.ground, &options.mono);
            assert!(e.is_some_and(|e| (e.z() - z).abs() < 1e-6), "{e:?}");
        }
        // Each map's value for a near-face depth.
        let maps: [(&str, MapOf); 3] = [
            ("depth", |near| {
                with_relative(car(BBOX0, None), near / 7.0, RelativeDepth::Depth)
            }),
            ("inverse depth", |near| {
                with_relative(car(BBOX0, None), 7.0 / near, RelativeDepth::InverseDepth)
            }),
            ("metric", |near| car(BBOX0, Some(near))),
        ];
        for (name, make) in maps {
            let mut asm = Assembler::new(camera, &options);
            let candidates = cars
                .iter()
                .map(|(z, b)| Candidate {
                    bbox: *b,
                    ..make(z - half)
                })
                .collect();
            asm.frame(0, candidates, None);
            for ((z, _), o) in cars.iter().zip(&asm.observations) {
                assert_ne!(o.depth_source, Some(DepthSource::Fused), "{name}: {o:?}");
                assert!((z_of(o) - z).abs() < 1e-6, "{name}: {} vs {z}", z_of(o));
                // On the ground seen under the box, like the mono estimate.
                let y = o.position.map_or(f64::NAN, |p| p[1]);
                assert!((y - camera.height_m).abs() < 1e-6, "{name}: {o:?}");
            }
        }
    }

    /// A candidate carrying a map's value for a near-face depth.
    type MapOf = fn(f64) -> Candidate;

    /// A placeholder box, replaced by each test.
    const BBOX0: BBox2D = BBox2D {
        left: 0.0,
        top: 0.0,
        right: 1.0,
        bottom: 1.0,
    };

    #[test]
    fn a_shifted_inverse_depth_map_is_fitted_in_the_frame() {
        let camera = kitti();
        let options = FramesOptions::default();
        let cars = cars_at(&[7.0, 10.0, 12.0, 16.0, 20.0, 30.0, 45.0]);
        let half = KITTI_CAR.half_depth_extent_m();
        for shift in [0.05, 0.2] {
            let mut asm = Assembler::new(camera, &options);
            let candidates = cars
                .iter()
                .map(|(z, b)| {
                    with_relative(
                        car(*b, None),
                        7.0 / (z - half) + shift,
                        RelativeDepth::InverseDepth,
                    )
                })
                .collect();
            asm.frame(0, candidates, None);
            for ((z, _), o) in cars.iter().zip(&asm.observations) {
                assert_eq!(o.depth_source, Some(DepthSource::RelativeAligned));
                assert!(
                    (z_of(o) / z - 1.0).abs() < 0.01,
                    "{shift}: {} vs {z}",
                    z_of(o)
                );
            }
        }
    }

    #[test]
    fn only_ground_contacts_and_size_priors_anchor_the_alignment() {
        let camera = kitti();
        let options = FramesOptions::default();
        let cars = cars_at(&[10.0]);
        let (z, b) = cars[0];
        let half = KITTI_CAR.half_depth_extent_m();
        // A traffic sign: flat ground without a prior puts its box bottom
        // (well above the ground) far away; it must not pull the scale.
        let sign_box = BBox2D {
            left: 900.0,
            top: 190.0,
            right: 930.0,
            bottom: 200.0,
        };
        let sign = Candidate {
            class: ObjectClass::TrafficSign,
            type_name: None,
            ..car(sign_box, None)
        };
        let sign_mono = estimate(&sign_box, None, &camera, &options.ground, &options.mono);
        assert!(
            sign_mono.is_some_and(|m| m.source == DepthSource::FlatGround && m.z() > 40.0),
            "{sign_mono:?}"
        );
        let mut asm = Assembler::new(camera, &options);
        asm.frame(
            0,
            vec![
                with_relative(car(b, None), (z - half) / 7.0, RelativeDepth::Depth),
                // The sign is in truth 12 m away.
                with_relative(sign, 12.0 / 7.0, RelativeDepth::Depth),
            ],
            None,
        );
        let [c, s] = [&asm.observations[0], &asm.observations[1]];
        assert!((z_of(c) - z).abs() < 1e-6, "{c:?}");
        assert_eq!(s.depth_source, Some(DepthSource::RelativeAligned));
        assert!((z_of(s) - 12.0).abs() < 1e-6, "{s:?}");
    }

    #[test]
    fn a_map_depth_beyond_the_cap_falls_back_to_the_monocular_estimate() {
        let camera = kitti();
        let options = FramesOptions::default();
        let cars = cars_at(&[10.0, 20.0, 30.0, 40.0, 50.0]);
        let half = KITTI_CAR.half_depth_extent_m();
        let mut candidates: Vec<Candidate> = cars
            .iter()
            .map(|(z, b)| {
                with_relative(car(*b, None), 7.0 / (z - half), RelativeDepth::InverseDepth)
            })
            .collect();
        // Sky inside one box: an inverse depth near zero, 70 km. The robust
        // fit follows the other four.
        candidates[2].relative = Some((1e-4, RelativeDepth::InverseDepth));
        let mut asm = Assembler::new(camera, &options);
        asm.frame(0, candidates, None);
        let sky = &asm.observations[2];
        assert_eq!(sky.depth_source, Some(DepthSource::Fused), "{sky:?}");
        assert!((z_of(sky) - 30.0).abs() < 1e-6, "{sky:?}");
        // The other boxes still take their depth from the map.
        for (k, o) in asm.observations.iter().enumerate().filter(|(k, _)| *k != 2) {
            assert_eq!(o.depth_source, Some(DepthSource::RelativeAligned), "{o:?}");
            assert!((z_of(o) / cars[k].0 - 1.0).abs() < 0.01, "{o:?}");
        }
        // The same cap for a metric map.
        let mut asm = Assembler::new(camera, &options);
        asm.frame(0, vec![car(cars[0].1, Some(500.0))], None);
        assert_eq!(asm.observations[0].depth_source, Some(DepthSource::Fused));
        let flat = FramesOptions {
            mono: MonoDepthConfig::default().with_method(MonoDepthMethod::FlatGround),
            ..FramesOptions::default()
        };
        let mut asm = Assembler::new(camera, &flat);
        asm.frame(0, vec![car(cars[0].1, Some(f64::INFINITY))], None);
        assert_eq!(
            asm.observations[0].depth_source,
            Some(DepthSource::FlatGround)
        );
    }
}
