//! Translates questions given as arguments, or one per line on stdin.
//!
//! Usage: `cargo run -p logicrag --example translate_ask -- "Is there a white car on the left?"`

use std::io::BufRead;

use logicrag::translate::Translator;

fn main() {
    let translator = Translator::builtin();
    let args: Vec<String> = std::env::args().skip(1).collect();
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
}
