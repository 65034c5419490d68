//! Line formats: text KBs, `window<TAB>query` files, KITTI labels and
//! calibrations.

use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::select;
use proptest::test_runner::TestRunner;

use super::logic::{CONSTS, pred_name, query_text};
use super::{sample, wild_count, wild_num};

// --------------------------------------------------------------------- facts

fn ident() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => select(CONSTS).prop_map(str::to_string),
        2 => "[a-zA-Z_][a-zA-Z0-9_.'-]{0,12}",
        1 => "\\PC{0,6}",
    ]
}

fn fact_line() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => (pred_name(), vec(ident(), 0..4), select(&[", ", ",", " , ", ",,"][..]),
              select(&["", ".", " ", "\r"][..]))
            .prop_map(|((p, _), args, sep, end)| format!("{p}({}){end}", args.join(sep))),
        1 => select(&["# comment", "% comment", "", "   ", "Vehicles(", ")(", "()", "P()",
                      "Vehicles(car_1", "TypeOf(car_1, \"Car\")", "TypeOf(car_1, \"Ca,r\")"][..])
            .prop_map(str::to_string),
    ]
}

/// Text KBs.
pub fn facts(runner: &mut TestRunner) -> Vec<u8> {
    sample(vec(fact_line(), 0..30).prop_map(|ls| ls.join("\n")), runner).into_bytes()
}

/// `window<TAB>query` files.
pub fn queries_tsv(runner: &mut TestRunner) -> Vec<u8> {
    let line = prop_oneof![
        6 => (select(&["w0", "w1", "w2", "", " w0", "w0\t"][..]), query_text())
            .prop_map(|(w, q)| format!("{w}\t{q}")),
        1 => select(&["# comment", "", "w0", "\t", "w0\t ", "w1\tVehicles(x)\tMoving(x)"][..])
            .prop_map(str::to_string),
    ];
    sample(vec(line, 0..20).prop_map(|ls| ls.join("\n")), runner).into_bytes()
}

// --------------------------------------------------------------------- KITTI

const KITTI_TYPES: &[&str] = &[
    "Car",
    "Van",
    "Truck",
    "Tram",
    "Pedestrian",
    "Person",
    "Person_sitting",
    "Cyclist",
    "Misc",
    "DontCare",
    "car",
    "Bus",
];

fn kitti_line() -> impl Strategy<Value = String> {
    let frame = prop_oneof![6 => (0u32..6).prop_map(|v| v.to_string()), 1 => wild_count()];
    let track = prop_oneof![
        6 => (0u32..8).prop_map(|v| v.to_string()),
        1 => Just("-1".to_string()),
        1 => wild_count()
    ];
    let occluded = prop_oneof![6 => (0u8..4).prop_map(|v| v.to_string()), 1 => wild_count()];
    // A plausible box, sometimes wild.
    let bbox = prop_oneof![
        6 => (0.0f64..1200.0, 0.0f64..350.0, 1.0f64..200.0, 1.0f64..100.0)
            .prop_map(|(l, t, w, h)| format!("{l:.2} {t:.2} {:.2} {:.2}", l + w, t + h)),
        1 => vec(wild_num(), 4).prop_map(|v| v.join(" ")),
    ];
    let dims = prop_oneof![
        6 => (0.5f64..4.0, 0.5f64..3.0, 0.5f64..12.0)
            .prop_map(|(h, w, l)| format!("{h:.2} {w:.2} {l:.2}")),
        1 => Just("-1 -1 -1".to_string()),
        1 => vec(wild_num(), 3).prop_map(|v| v.join(" ")),
    ];
    let loc = prop_oneof![
        6 => (-20.0f64..20.0, 0.5f64..2.5, 1.0f64..80.0)
            .prop_map(|(x, y, z)| format!("{x:.2} {y:.2} {z:.2}")),
        1 => Just("-1000 -1000 -1000".to_string()),
        1 => vec(wild_num(), 3).prop_map(|v| v.join(" ")),
    ];
    let score = prop_oneof![
        6 => Just(String::new()),
        1 => wild_num().prop_map(|s| format!(" {s}")),
    ];
    (
        frame,
        track,
        select(KITTI_TYPES),
        prop_oneof![3 => Just("0".to_string()), 1 => wild_num()],
        occluded,
        wild_num(),
        bbox,
        dims,
        loc,
        wild_num(),
        score,
    )
        .prop_map(|(f, t, ty, tr, oc, alpha, bbox, dims, loc, rot, score)| {
            format!("{f} {t} {ty} {tr} {oc} {alpha} {bbox} {dims} {loc} {rot}{score}")
        })
}

/// KITTI tracking label files.
pub fn kitti_labels(runner: &mut TestRunner) -> Vec<u8> {
    sample(
        prop_oneof![
            8 => vec(kitti_line(), 0..40),
            // One frame crowded with objects.
            1 => (200usize..400).prop_map(|n| (0..n)
                .map(|i| format!("0 {i} Car 0 0 0 10 10 20 20 1.5 1.6 4 0 1.7 {}", 5 + i % 60))
                .collect()),
        ]
        .prop_map(|ls| ls.join("\n")),
        runner,
    )
    .into_bytes()
}

/// KITTI calibration files.
pub fn kitti_calib(runner: &mut TestRunner) -> Vec<u8> {
    let p_line = (
        select(
            &[
                "P0:",
                "P1:",
                "P2:",
                "P3:",
                "R0_rect:",
                "Tr_velo_cam:",
                " P2:",
                "P2 :",
            ][..],
        ),
        prop_oneof![6 => Just(12usize), 1 => 0usize..16],
        vec(wild_num(), 16),
    )
        .prop_map(|(key, n, nums)| {
            format!(
                "{key} {}",
                nums.into_iter().take(n).collect::<Vec<_>>().join(" ")
            )
        });
    let p2_real = (500.0f64..1500.0, 100.0f64..1300.0, 50.0f64..400.0).prop_map(|(f, cx, cy)| {
        format!("P2: {f:.3} 0 {cx:.3} 44.8 0 {f:.3} {cy:.3} 0.2 0 0 1 0.003")
    });
    sample(
        (vec(p_line, 0..6), proptest::option::of(p2_real)).prop_map(|(mut ls, p2)| {
            ls.extend(p2);
            ls.join("\n")
        }),
        runner,
    )
    .into_bytes()
}
