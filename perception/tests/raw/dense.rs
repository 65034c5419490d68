//! The dense path end to end against the simulator's truth: maps rendered
//! from the scene states (semantic, instance, depth, flow) → instances →
//! tracker → 3D → window facts, and the same through PNG files on disk.

use std::collections::{BTreeMap, BTreeSet};

use perception::raw::frames::{FramesOptions, read_dense_dir, sequence_from_dense};
use perception::raw::render::{RenderLabels, render_sequence};
use perception::sim::{Scenario, simulate};
use perception::{BBox2D, ObjectClass, WindowSpec};

const SCALE: f64 = 0.25;

fn scaled(b: &BBox2D) -> BBox2D {
    // Matches render::scaled_camera's pixel-centre alignment.
    let s = |v: f64| (v + 0.5) * SCALE - 0.5;
    BBox2D {
        left: s(b.left),
        top: s(b.top),
        right: s(b.right),
        bottom: s(b.bottom),
    }
}

#[test]
fn rendered_maps_give_back_the_simulated_objects() {
    let scenario = Scenario::builtin("urban_crossing").unwrap();
    let run = simulate(&scenario, 0).unwrap();
    let labels = RenderLabels::from_states(&run.states);
    let (frames, camera) = render_sequence(&run.states, SCALE, &labels).unwrap();
    assert_eq!(frames.len(), run.states.len());
    let options = FramesOptions::default();
    let seq = sequence_from_dense(
        "urban_crossing",
        "dense",
        camera,
        &frames,
        &labels.class_table(),
        &options,
    )
    .unwrap();
    assert_eq!(seq.frame_count as usize, run.states.len());

    // Every dynamic object that the render shows with enough pixels and whose
    // projected box is mostly unoccluded must be found, in the right place.
    let mut expected = 0usize;
    let mut found = 0usize;
    let mut ids: BTreeMap<u32, BTreeSet<u32>> = BTreeMap::new();
    let mut worst_z: f64 = 0.0;
    for (state, frame) in run.states.iter().zip(&frames) {
        let inst = frame.instance.as_ref().unwrap();
        for o in state.objects.iter() {
            let Some(truth_box) = o.bbox.map(|b| scaled(&b)) else {
                continue;
            };
            let pixels = inst.data.iter().filter(|&&v| v == o.track_id + 1).count();
            // Unoccluded enough: the visible pixels fill most of the projected box.
            if pixels < 40 || (pixels as f64) < 0.6 * truth_box.area() {
                continue;
            }
            expected += 1;
            let best = seq
                .observations
                .iter()
                .filter(|ob| ob.frame == state.frame)
                .max_by(|a, b| a.iou(&truth_box).total_cmp(&b.iou(&truth_box)));
            let Some(ob) = best.filter(|ob| ob.iou(&truth_box) >= 0.5) else {
                continue;
            };
            found += 1;
            assert_eq!(ob.class, o.class, "frame {} {}", state.frame, o.name);
            assert_eq!(
                ob.type_name, o.type_name,
                "frame {} {}",
                state.frame, o.name
            );
            ids.entry(o.track_id).or_default().insert(ob.track_id);
            // Depth of the nearest surface vs the box centre: within half the
            // footprint diagonal.
            let [_, w, l] = o.camera.size;
            let z = ob.position.unwrap()[2];
            let err = (z - o.camera.center[2]).abs() - 0.5 * (w * w + l * l).sqrt();
            worst_z = worst_z.max(err);
            assert!(
                err <= 0.3,
                "frame {} {}: z {z:.2} vs centre {:.2}",
                state.frame,
                o.name,
                o.camera.center[2]
            );
        }
    }
    eprintln!(
        "found {found} of {expected} unoccluded object-frames; ids {ids:?}; worst extra depth error {worst_z:.2} m"
    );
    assert!(expected > 50, "the scenario shows objects: {expected}");
    assert!(
        found as f64 >= 0.95 * expected as f64,
        "found {found} of {expected}"
    );
    // Stable ids: each simulated object keeps one track id.
    for (truth, ours) in &ids {
        assert_eq!(ours.len(), 1, "object {truth} got track ids {ours:?}");
    }
    let all: Vec<u32> = ids.values().flatten().copied().collect();
    assert_eq!(
        all.len(),
        all.iter().collect::<BTreeSet<_>>().len(),
        "two objects share a track id: {ids:?}"
    );

    // The same window facts machinery as every other source.
    let windows = perception::window_facts(&seq, WindowSpec::PAPER, &Default::default()).unwrap();
    assert_eq!(windows.len(), 8);
    let ped = seq
        .observations
        .iter()
        .find(|o| o.class == ObjectClass::Pedestrian)
        .map(|o| seq.object_name(o.track_id))
        .unwrap();
    assert!(
        windows.iter().any(|w| w.contains("Pedestrian", &[&ped])),
        "no Pedestrian({ped})"
    );
    let sedan = seq
        .observations
        .iter()
        .find(|o| o.type_name.as_deref() == Some("Sedan"))
        .map(|o| seq.object_name(o.track_id))
        .unwrap();
    assert!(
        windows.iter().any(|w| w.contains("Moving", &[&sedan])),
        "the oncoming sedan moves"
    );
    let parked = seq
        .observations
        .iter()
        .find(|o| o.type_name.as_deref() == Some("Van"))
        .map(|o| seq.object_name(o.track_id))
        .unwrap();
    assert!(
        !windows.iter().any(|w| w.contains("Moving", &[&parked])),
        "the parked van does not move"
    );

    // Through PNG files: the same sequence (depth quantised to 1/256 m).
    let dir = std::env::temp_dir().join(format!("pframes-dense-seq-{}", std::process::id()));
    for (i, f) in frames.iter().enumerate() {
        f.write_pngs(&dir, &format!("{i:06}")).unwrap();
    }
    let back = read_dense_dir(&dir).unwrap();
    let seq2 = sequence_from_dense(
        "urban_crossing",
        "dense",
        camera,
        &back,
        &labels.class_table(),
        &options,
    )
    .unwrap();
    assert_eq!(seq2.observations.len(), seq.observations.len());
    for (a, b) in seq.observations.iter().zip(&seq2.observations) {
        assert_eq!(
            (a.frame, a.track_id, a.class, &a.type_name, a.bbox),
            (b.frame, b.track_id, b.class, &b.type_name, b.bbox)
        );
        let (pa, pb) = (a.position.unwrap(), b.position.unwrap());
        assert!((pa[2] - pb[2]).abs() < 0.01, "{pa:?} {pb:?}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
