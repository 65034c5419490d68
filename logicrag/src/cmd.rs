//! Subcommands that combine several library steps: demo, simulate,
//! context, eval, repl.

use super::*;
use logicrag::context::RagContext;

pub fn simulate(a: SimulateArgs) -> Result<ExitCode> {
    let spec = format!("sim:{}@{}", a.scenario, a.seed);
    let source = perception::Source::parse(&spec)?;
    let run = source.simulate()?;
    let windows = perception::window_facts(&run.sequence, WindowSpec::PAPER, &FactConfig::default())?;
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir.join("facts")).with_context(|| format!("creating {}", dir.display()))?;
        std::fs::write(dir.join("tracks.json"), perception::json::to_tracks_json(&run.sequence)?)?;
        std::fs::write(dir.join("events.json"), serde_json::to_string_pretty(&run.events)?)?;
        for w in &windows {
            let id = format!("{}_{:06}", run.sequence.name, w.first_frame);
            std::fs::write(dir.join("facts").join(format!("{id}.facts")), w.to_kb())?;
        }
        eprintln!(
            "wrote {}/tracks.json, events.json and {} window KBs under facts/",
            dir.display(),
            windows.len()
        );
    }
    if a.json {
        println!(
            "{}",
            serde_json::json!({
                "scenario": run.sequence.name, "frames": run.sequence.frame_count,
                "observations": run.sequence.observations.len(), "events": run.events,
                "windows": windows.len(),
            })
        );
    } else {
        println!(
            "scenario {}: {} frames, {} observations, {} tracks, {} windows",
            run.sequence.name,
            run.sequence.frame_count,
            run.sequence.observations.len(),
            run.sequence.tracks().len(),
            windows.len()
        );
        println!("ground-truth events:");
        for e in &run.events {
            let other = e.other.as_ref().map(|o| format!(" → {o}")).unwrap_or_default();
            println!("  frames {:>3}-{:<3} {:<14} {}{}", e.first_frame, e.last_frame, format!("{:?}", e.kind), e.object, other);
        }
    }
    Ok(ExitCode::SUCCESS)
}

pub fn context(a: ContextArgs) -> Result<ExitCode> {
    let pad = load_pad(&a.src.logicpad)?;
    let translator = Translator::builtin();
    let (query, question) = to_query(&translator, &a.text)?;
    let loaded = load_source(&a.src)?;
    let observed = loaded.observability.classify(&pad);
    for w in loaded.windows {
        if a.window_id.as_ref().is_some_and(|id| *id != w.id) {
            continue;
        }
        let kb = WindowKb::build(w, pad.program())?;
        let r = ask(&pad, &kb, &observed, &query, AskOptions::default());
        let ctx = RagContext::new(&kb, question.as_deref(), &r);
        if a.json {
            println!("{}", serde_json::to_string(&ctx)?);
        } else {
            println!("{}", ctx.to_text());
        }
    }
    Ok(ExitCode::SUCCESS)
}

pub fn demo(_a: DemoArgs) -> Result<ExitCode> {
    bail!("demo: being built")
}

pub fn eval(_a: EvalArgs) -> Result<ExitCode> {
    bail!("eval: being built")
}

pub fn repl(_a: ReplArgs) -> Result<ExitCode> {
    bail!("repl: being built")
}
