//! Translates questions given as arguments, or one per line on stdin.
//!
//! Usage: `cargo run -p logicrag --example translate_ask -- [--logicpad [FILE]] "Is there a white car on the left?"`
//! With `--logicpad` the vocabulary comes from a LogicPad's schema (the
//! project's default LogicPad when no file follows), else the built-in one.

use std::io::BufRead;

use logicrag::translate::{Translator, Vocabulary};

fn main() -> anyhow::Result<()> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let translator = if args.first().is_some_and(|a| a == "--logicpad") {
        args.remove(0);
        let pad = match args
            .first()
            .filter(|a| a.ends_with(".yaml") || a.ends_with(".yml"))
            .cloned()
        {
            Some(path) => {
                args.remove(0);
                logicpad::LogicPad::load(&path).map_err(|e| anyhow::anyhow!("{path}: {e:?}"))?
            }
            None => logicpad::LogicPad::builtin(),
        };
        Translator::new(Vocabulary::from_schema(pad.schema())?.with_rules(pad.program()))
    } else {
        Translator::builtin()
    };
    let questions: Vec<String> = if args.is_empty() {
        std::io::stdin()
            .lock()
            .lines()
            .map_while(Result::ok)
            .filter(|l| !l.trim().is_empty())
            .collect()
    } else {
        args
    };
    for q in questions {
        match translator.translate(&q) {
            Ok(t) => {
                println!("{q}\n    {}", t.query);
                for n in &t.notes {
                    println!("    note: {n}");
                }
            }
            Err(e) => println!("{q}\n    ERROR {e}"),
        }
    }
    Ok(())
}
