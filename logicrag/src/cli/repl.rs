//! `logicrag repl`: the interactive session ([`logicrag::repl::Session`])
//! behind a line editor with history and tab completion.

use super::{LlmArgs, SourceArgs};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct ReplArgs {
    #[command(flatten)]
    pub src: SourceArgs,
    #[command(flatten)]
    pub llm: LlmArgs,
}

pub fn run(a: ReplArgs) -> Result<ExitCode> {
    use rustyline::error::ReadlineError;
    let mut pipeline = a.src.open(None)?;
    let images = pipeline.take_images();
    let label = pipeline.label().to_string();
    let mut session = logicrag::repl::Session::new(pipeline, a.src.logicpad.clone())?;
    // `:lmm`, and the LLM translator (`--translator llm|auto`, or later
    // `:translator auto`), work when a server is named (flag or
    // environment); `--translator llm` without one is refused here.
    let named = a.llm.llm.is_some() || std::env::var_os("LOGICRAG_LLM_URL").is_some();
    let setup = if named {
        session.set_lmm(
            a.llm.chat()?,
            a.llm.templates(None)?,
            images,
            a.llm.lmm_frames,
        );
        Some(logicrag::engine::LlmSetup {
            chat: a.llm.chat()?,
            templates: a.llm.templates(None)?,
            repairs: a.llm.llm_repairs,
        })
    } else {
        a.llm.llm_setup()?
    };
    session.set_translator(a.llm.translator, setup);
    let words = std::rc::Rc::new(std::cell::RefCell::new(session.completions()));
    let mut rl: rustyline::Editor<Completion, rustyline::history::DefaultHistory> =
        rustyline::Editor::new()?;
    rl.set_helper(Some(Completion {
        words: words.clone(),
    }));
    let history = std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".logicrag_history"));
    if let Some(h) = &history {
        let _ = rl.load_history(h);
    }
    eprintln!(
        "logicrag repl on {label}: {} windows, starting at {}; `:help` for commands, Ctrl-D to leave",
        session.window_count(),
        session.window().id
    );
    loop {
        let prompt = format!("{}> ", session.window().id);
        match rl.readline(&prompt) {
            Ok(line) => {
                let t = line.trim();
                if t == ":quit" || t == ":q" {
                    break;
                }
                if !t.is_empty() {
                    let _ = rl.add_history_entry(t);
                }
                outp!("{}", session.handle(&line));
                *words.borrow_mut() = session.completions();
            }
            Err(ReadlineError::Interrupted) => continue,
            Err(ReadlineError::Eof) => break,
            // One undecodable line ended the session; it is skipped.
            Err(ReadlineError::Io(e)) if e.kind() == std::io::ErrorKind::InvalidData => {
                eprintln!("skipped a line that is not UTF-8 text");
                continue;
            }
            Err(e) => return Err(e.into()),
        }
    }
    if let Some(h) = &history {
        let _ = rl.save_history(h);
    }
    Ok(ExitCode::SUCCESS)
}

/// Tab completion over predicates, values, objects and commands.
struct Completion {
    words: std::rc::Rc<std::cell::RefCell<Vec<String>>>,
}

impl rustyline::completion::Completer for Completion {
    type Candidate = String;
    fn complete(
        &self,
        line: &str,
        pos: usize,
        _ctx: &rustyline::Context<'_>,
    ) -> rustyline::Result<(usize, Vec<String>)> {
        let head = line.get(..pos).unwrap_or(line);
        let start = head
            .rfind(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
            .map_or(0, |i| i + 1);
        let prefix = head.get(start..).unwrap_or("");
        if prefix.is_empty() {
            return Ok((pos, Vec::new()));
        }
        let found = self
            .words
            .borrow()
            .iter()
            .filter(|w| w.starts_with(prefix))
            .cloned()
            .collect();
        Ok((start, found))
    }
}
impl rustyline::hint::Hinter for Completion {
    type Hint = String;
}
impl rustyline::highlight::Highlighter for Completion {}
impl rustyline::validate::Validator for Completion {}
impl rustyline::Helper for Completion {}
