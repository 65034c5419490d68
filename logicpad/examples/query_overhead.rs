//! Fixed cost of one query: `cargo run --release -p logicpad --example query_overhead`
//! asks small queries of a small model many times and prints ns per query.

use logicpad::{FactBase, LogicPad, parse_query};
use std::time::Instant;

fn main() {
    let pad = LogicPad::builtin();
    let mut fb = FactBase::new();
    for i in 0..20 {
        let car = format!("car_{i}");
        fb.add("Vehicles", &[&car]).ok();
        if i % 3 == 0 {
            fb.add("SpeedUp", &[&car]).ok();
        }
    }
    let model = match pad.program().evaluate(fb) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let reps = 200_000;
    for q in [
        "Vehicles(car_3)",
        "Vehicles(x) ^ SpeedUp(x)",
        "Vehicles(x) ^ ¬SpeedUp(x)",
        "Pedestrian(x)",
    ] {
        if std::env::args()
            .nth(1)
            .is_some_and(|f| !q.contains(f.as_str()))
        {
            continue;
        }
        let Ok(ast) = parse_query(q) else { continue };
        let t = Instant::now();
        let mut n = 0;
        for _ in 0..reps {
            n += model.count(&ast).unwrap_or(0);
        }
        let ns = t.elapsed().as_nanos() as f64 / reps as f64;
        println!("{q:30} {ns:8.0} ns per count ({} answers)", n / reps);
    }
}
