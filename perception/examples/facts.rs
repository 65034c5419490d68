//! Prints window facts for a source, as a text KB or JSON.
//!
//! ```sh
//! cargo run -p perception --example facts -- kitti:../shared/data/kitti-tracking --sequence 0000 --frames 0-9
//! cargo run -p perception --example facts -- sim:urban_crossing --window 10 --stride 10 --json
//! ```
//! Flags: `--sequence NAME`, `--frames A-B` (one window), `--window N`,
//! `--stride N`, `--json` (facts with provenance), `--tables` (relation
//! tables: predicate → argument tuples), `--provenance` (text KB with provenance notes),
//! `--config FILE` (FactConfig JSON/YAML).

use perception::{FactConfig, Source, WindowSpec};

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let mut spec = None;
    let (mut sequence, mut frames, mut json, mut prov, mut config_path) =
        (None, None, false, false, None);
    let mut window = WindowSpec::PAPER;
    let mut tables = false;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--sequence" => sequence = args.next(),
            "--frames" => frames = args.next(),
            "--window" => window.size = args.next().ok_or("--window needs a number")?.parse()?,
            "--stride" => window.stride = args.next().ok_or("--stride needs a number")?.parse()?,
            "--json" => json = true,
            "--tables" => tables = true,
            "--provenance" => prov = true,
            "--config" => config_path = args.next(),
            _ if spec.is_none() => spec = Some(a),
            _ => return Err(format!("unexpected argument `{a}`").into()),
        }
    }
    let spec = spec.ok_or("usage: facts SOURCE [--sequence NAME] [--frames A-B] [--window N --stride N] [--json] [--provenance]")?;
    let config = match config_path {
        Some(p) => perception::config::FactConfig::load(std::path::Path::new(&p))?,
        None => FactConfig::default(),
    };
    let source = Source::parse(&spec)?;
    let seq = source.load(sequence.as_deref())?;
    let windows = match frames {
        Some(r) => {
            let (a, b) = perception::source::parse_frame_range(&r)?;
            vec![perception::range_facts(&seq, a, b, &config)?]
        }
        None => perception::window_facts(&seq, window, &config)?,
    };
    if json {
        println!("{}", serde_json::to_string_pretty(&windows)?);
        return Ok(());
    }
    if tables {
        let t: Vec<_> = windows
            .iter()
            .map(|w| {
                serde_json::json!({"index": w.index, "first_frame": w.first_frame,
                "last_frame": w.last_frame, "relations": w.relation_tables()})
            })
            .collect();
        println!("{}", serde_json::to_string_pretty(&t)?);
        return Ok(());
    }
    for w in &windows {
        println!(
            "# {} window {} frames {}-{}",
            seq.source_label(),
            w.index,
            w.first_frame,
            w.last_frame
        );
        for f in &w.facts {
            if prov {
                println!("{:<48} % {}", f.to_kb_line(), f.provenance.note);
            } else {
                println!("{}", f.to_kb_line());
            }
        }
    }
    Ok(())
}
