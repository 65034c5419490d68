//! The interactive session behind `logicrag repl`: the state and the
//! commands, separate from the line editor so every command is testable.
//!
//! Input is a question in English, a query, or a command:
//! `:windows`, `:window ID|N`, `:facts [OBJECT]`, `:why FACT`, `:rules`,
//! `:load FILE`, `:help`. The LogicPad file (when one was loaded from disk)
//! is re-read whenever it changes on disk.

use crate::ask::{AskOptions, AskResult, Outcome};
use crate::engine::Engine;
use crate::kb::WindowKb;
use crate::pipeline::Pipeline;
use logicpad::LogicPad;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::SystemTime;

/// One REPL session.
///
/// Invariant: `pipeline`'s windows are reasoned, with its current
/// LogicPad, and there is at least one; `current` is the window in focus.
pub struct Session {
    /// The source, its engine, its translator (`:translator`) and its
    /// reasoned windows; replaced when the LogicPad changes.
    pipeline: Pipeline,
    pad_path: Option<PathBuf>,
    pad_mtime: Option<SystemTime>,
    current: usize,
    lmm: Option<LmmSetup>,
    /// The LLM translator's server, when one was given.
    llm: Option<crate::engine::LlmSetup>,
    /// The answers not shown yet of the last question (`more` or `;`).
    pending: Option<Pending>,
}

/// Answers shown a page at a time, like a Prolog top level.
enum Pending {
    /// The rest of an answer that was computed whole.
    Computed {
        /// Boxed: an answer is several times the size of the lazy variant.
        result: Box<AskResult>,
        shown: usize,
    },
}

/// Answers per page.
const PAGE: usize = 10;

/// What `:lmm` needs: a chat server, prompts and the source's pictures.
struct LmmSetup {
    chat: crate::llm::Chat,
    templates: crate::llm::Templates,
    images: Option<crate::images::FrameImages>,
    frames: usize,
}

/// Errors that end a session before it starts.
#[derive(Debug, thiserror::Error)]
pub enum ReplError {
    /// Occurs when the source has no window.
    #[error("the source has no window to ask about")]
    NoWindows,
    /// Occurs when the windows cannot be reasoned.
    #[error(transparent)]
    Reason(#[from] crate::session::SessionError),
}

fn mtime(p: &PathBuf) -> Option<SystemTime> {
    std::fs::metadata(p).and_then(|m| m.modified()).ok()
}

impl Session {
    /// Starts a session over a pipeline's windows (reasoned now), whose
    /// LogicPad was read from `pad_path` (re-read when the file changes).
    /// The pipeline must keep its inputs (not be made reasoned): a new
    /// LogicPad reasons them again.
    pub fn new(pipeline: Pipeline, pad_path: Option<PathBuf>) -> Result<Session, ReplError> {
        if pipeline.window_count() == 0 {
            return Err(ReplError::NoWindows);
        }
        pipeline.build(&|| {})?;
        let pad_mtime = pad_path.as_ref().and_then(mtime);
        Ok(Session {
            pipeline,
            pad_path,
            pad_mtime,
            current: 0,
            lmm: None,
            llm: None,
            pending: None,
        })
    }

    /// The reasoned windows (every one: see the invariant).
    fn kbs(&self) -> &[WindowKb] {
        self.pipeline.reasoned_windows().unwrap_or_default()
    }

    /// The engine of the current LogicPad.
    fn engine(&self) -> &Engine {
        self.pipeline.engine()
    }

    /// Enables `:lmm c1|c2|c3 QUESTION` with this server, prompts, the
    /// source's pictures and this many frames per window.
    pub fn set_lmm(
        &mut self,
        chat: crate::llm::Chat,
        templates: crate::llm::Templates,
        images: Option<crate::images::FrameImages>,
        frames: usize,
    ) {
        self.lmm = Some(LmmSetup {
            chat,
            templates,
            images,
            frames,
        });
    }

    /// Questions are translated under `mode`, with `llm` for the LLM
    /// translator (`--translator`, `--llm`); `:translator` changes the mode.
    pub fn set_translator(
        &mut self,
        mode: crate::engine::TranslatorMode,
        llm: Option<crate::engine::LlmSetup>,
    ) {
        self.llm = llm;
        self.use_mode(mode);
    }

    /// Translates under `mode` from now on, with the session's LLM server
    /// (`Llm` without one stays as it was).
    fn use_mode(&mut self, mode: crate::engine::TranslatorMode) -> bool {
        match crate::engine::translator(mode, self.llm.clone()) {
            Ok(t) => {
                self.pipeline.set_translator(t);
                true
            }
            Err(_) => false,
        }
    }

    /// A question through the session's translator.
    fn prepare(&self, text: &str) -> Result<crate::engine::Prepared, crate::engine::PrepareError> {
        self.pipeline.prepare(text)
    }

    /// `:translator [grammar|llm|auto]`: shows or sets the mode.
    fn set_mode(&mut self, arg: &str) -> String {
        use crate::engine::TranslatorMode;
        if arg.is_empty() {
            return format!(
                "translator: {}{}",
                self.pipeline.translator().mode().as_str(),
                if self.llm.is_some() {
                    " (an LLM server is set)"
                } else {
                    " (no LLM server: start with --llm URL)"
                }
            );
        }
        match arg.parse::<TranslatorMode>() {
            Ok(TranslatorMode::Grammar) => {
                self.use_mode(TranslatorMode::Grammar);
                "translator: grammar".into()
            }
            Ok(mode) if self.llm.is_none() => format!(
                "the {} translator needs an LLM server: start the REPL with --llm URL (or set LOGICRAG_LLM_URL)",
                mode.as_str()
            ),
            Ok(mode) => {
                self.use_mode(mode);
                format!("translator: {}", mode.as_str())
            }
            Err(e) => e,
        }
    }

    fn lmm(&self, arg: &str) -> String {
        let Some(setup) = &self.lmm else {
            return "`:lmm` needs a model: start the REPL with --llm URL (or set LOGICRAG_LLM_URL)\n".into();
        };
        let (cond, question) = arg.split_once(char::is_whitespace).unwrap_or((arg, ""));
        let condition: crate::llm::Condition = match cond.parse() {
            Ok(c) => c,
            Err(e) => return format!("{e}; usage: :lmm c1|c2|c3 QUESTION\n"),
        };
        let question = question.trim();
        if question.is_empty() {
            return "usage: :lmm c1|c2|c3 QUESTION\n".into();
        }
        let kb = self.window();
        let r = match self.prepare(question) {
            Ok(p) => self.pipeline.ask_window(kb, &p, AskOptions::default()),
            Err(e) => crate::ask::invalid(kb, question, &[]).with_reason(e.to_string()),
        };
        let ctx = crate::context::RagContext::new(kb, Some(question), &r, self.engine().words());
        let pngs: Result<Vec<Vec<u8>>, _> = setup.images.as_ref().map_or(Ok(Vec::new()), |i| {
            i.pngs(
                kb.first_frame,
                kb.last_frame,
                setup.frames,
                crate::images::DEFAULT_MAX_SIDE,
            )
        });
        let pngs = match pngs {
            Ok(p) => p,
            Err(e) => return format!("{e}\n"),
        };
        let lmm = crate::llm::Lmm {
            chat: setup.chat.clone(),
            templates: setup.templates.clone(),
        };
        match lmm.ask(condition, question, &ctx, &pngs) {
            Ok(a) => format!(
                "logic: {}\nlmm {} ({} frames): {} — {}\n",
                r.answer.as_str().to_uppercase(),
                condition.as_str(),
                a.frames,
                a.verdict.as_str().to_uppercase(),
                a.reply.trim()
            ),
            Err(e) => format!("{e}\n"),
        }
    }

    /// The window in focus.
    pub fn window(&self) -> &WindowKb {
        let kbs = self.kbs();
        &kbs[self.current.min(kbs.len() - 1)]
    }

    /// Number of windows in the session.
    pub fn window_count(&self) -> usize {
        self.kbs().len()
    }

    /// Words for tab completion: commands, predicates, declared values and
    /// the current window's objects.
    pub fn completions(&self) -> Vec<String> {
        let mut v: Vec<String> = COMMANDS
            .iter()
            .filter(|c| c.len() > 1)
            .map(|c| format!(":{c}"))
            .collect();
        for p in self.engine().pad().schema().predicates() {
            v.push(p.name.clone());
            if let Some(vals) = &p.values {
                v.extend(vals.iter().cloned());
            }
        }
        v.extend(self.window().objects.iter().map(|o| o.to_string()));
        v.sort();
        v.dedup();
        v
    }

    /// Re-reads the LogicPad when its file changed; returns a message when it did.
    pub(crate) fn reload_if_changed(&mut self) -> Option<String> {
        let path = self.pad_path.clone()?;
        let now = mtime(&path);
        if now == self.pad_mtime {
            return None;
        }
        self.pad_mtime = now;
        Some(self.load_pad(path))
    }

    fn load_pad(&mut self, path: PathBuf) -> String {
        self.pending = None;
        let pad = match LogicPad::load(&path) {
            Ok(p) => p,
            Err(e) => return format!("kept the previous LogicPad: {e}"),
        };
        let errors = pad.diagnostics().iter().filter(|d| d.is_error()).count();
        // An empty file would silently replace the whole vocabulary.
        if pad.schema().is_empty() {
            return format!(
                "kept the previous LogicPad: {} declares no predicates",
                path.display()
            );
        }
        // One engine: the translator and observability follow the new pad.
        let pipeline = match self.pipeline.with_logicpad(pad) {
            Ok(p) => p,
            Err(e) => return format!("kept the previous LogicPad: {e}"),
        };
        self.pipeline = pipeline;
        self.pad_mtime = mtime(&path);
        self.pad_path = Some(path.clone());
        format!(
            "loaded {} ({} rules{})",
            path.display(),
            self.engine().pad().program().rules().len(),
            if errors > 0 {
                format!(", {errors} error(s): rules left out; see `logicrag lint`")
            } else {
                String::new()
            }
        )
    }

    /// `:rule` (FOL) and `:define` (English, under the session's translator
    /// mode, as questions are: `:translator auto` with `--llm` sends what the
    /// grammar cannot read to the LLM): the rule joins this
    /// session's LogicPad after the LogicPad checker accepts it, and every
    /// window is reasoned again, so the next question can use it and its
    /// proofs cite it. The file on disk is not changed (`logicrag rule
    /// --append FILE` does that); a change to it reloads it, without the
    /// rules added here.
    fn add_rule(&mut self, fol: bool, text: &str) -> String {
        use crate::compose;
        let rule = if fol {
            compose::from_fol(text)
        } else {
            compose::from_definition(
                self.engine(),
                text,
                None,
                self.pipeline.translator().mode(),
                self.llm.as_ref(),
            )
        };
        let rule = match rule {
            Ok(r) => r,
            Err(e) => return format!("no rule added: {e}"),
        };
        let ext = match compose::extend(self.engine().pad(), &rule) {
            Ok(x) => x,
            Err(e) => return format!("no rule added: {e}"),
        };
        let pipeline = match self.pipeline.with_logicpad(ext.pad) {
            Ok(p) => p,
            Err(e) => return format!("no rule added: {e}"),
        };
        self.pipeline = pipeline;
        self.pending = None;
        let mut msg = format!("added (line {}): {}", ext.line, rule.logic);
        for n in rule.notes.iter().chain(&ext.warnings) {
            let _ = write!(msg, "\nnote: {n}");
        }
        let _ = write!(
            msg,
            "\nask with \"{}\" — every window was reasoned again",
            rule.phrases.join("\", \"")
        );
        msg
    }

    /// Handles one input line and returns what to print.
    pub fn handle(&mut self, line: &str) -> String {
        // Control characters are never echoed back raw (an escape sequence
        // in a question would reach the terminal through an error message).
        let cleaned: String = line
            .chars()
            .map(|c| {
                if c.is_control() && c != '\t' {
                    '\u{fffd}'
                } else {
                    c
                }
            })
            .collect();
        let line = cleaned.as_str();
        let mut out = String::new();
        if let Some(msg) = self.reload_if_changed() {
            let _ = writeln!(out, "{msg}");
        }
        let line = line.trim();
        if line.is_empty() {
            return out;
        }
        if matches!(line, "more" | ";" | ":more") {
            out.push_str(&self.more());
            return out;
        }
        // A bare command word that no question could be (`help`,
        // `windows`, `rules`) is the command: typing the colon is the slip
        // users make most.
        let bare =
            (BARE_COMMANDS.contains(&line.to_lowercase().as_str())).then(|| line.to_lowercase());
        if let Some(cmd) = line.strip_prefix(':').or(bare.as_deref()) {
            let (name, arg) = cmd
                .split_once(char::is_whitespace)
                .map_or((cmd, ""), |(a, b)| (a, b.trim()));
            match name {
                "help" | "h" => out.push_str(HELP),
                "windows" => {
                    for (i, k) in self.kbs().iter().enumerate() {
                        let mark = if i == self.current { "*" } else { " " };
                        let _ = writeln!(
                            out,
                            "{mark} {i:>3} {} frames {}-{}, {} facts",
                            k.id,
                            k.first_frame,
                            k.last_frame,
                            k.fact_count()
                        );
                    }
                }
                "window" | "w" => {
                    let found = match arg.parse::<usize>() {
                        Ok(i) if i < self.window_count() => Ok(i),
                        _ => self.pipeline.position(arg),
                    };
                    match found {
                        Ok(i) => {
                            self.current = i;
                            let k = self.window();
                            let _ = writeln!(
                                out,
                                "window {} (frames {}-{}): {} objects, {} facts",
                                k.id,
                                k.first_frame,
                                k.last_frame,
                                k.objects.len(),
                                k.fact_count()
                            );
                        }
                        Err(no) => {
                            let _ = writeln!(out, "{no}; `:windows` lists them");
                        }
                    }
                }
                "facts" | "f" => {
                    // Pair bookkeeping (`SharesFrames`) grows with the square
                    // of the objects and says nothing a user asked for: it is
                    // counted, and listed with `:facts all` or an object.
                    let all = arg == "all";
                    let mut hidden = 0;
                    for f in self.window().facts() {
                        if arg.is_empty() && HIDDEN_FACTS.contains(&f.predicate()) {
                            hidden += 1;
                            continue;
                        }
                        if arg.is_empty() || all || f.args().any(|a| a == arg) {
                            let _ = writeln!(
                                out,
                                "{f}    # {}",
                                crate::proof::describe_provenance(f.provenance())
                            );
                        }
                    }
                    if hidden > 0 {
                        let _ = writeln!(
                            out,
                            "({hidden} {} facts not shown; `:facts all` lists them)",
                            HIDDEN_FACTS.join("/")
                        );
                    }
                }
                "why" => match parse_ground(arg) {
                    // An atom with variables (by the query name rule) is a
                    // query: every binding with its proof.
                    Some((_, args)) if args.iter().any(|a| logicpad::is_variable_name(a)) => {
                        let p = self.engine().prepare_query(arg);
                        let r = self
                            .pipeline
                            .ask_window(self.window(), &p, AskOptions::default());
                        let _ = writeln!(
                            out,
                            "{}{}",
                            r.answer.as_str().to_uppercase(),
                            crate::render::count_suffix(&r)
                        );
                        for line in crate::render::detail_lines(&r) {
                            let _ = writeln!(out, "{line}");
                        }
                    }
                    Some((pred, args)) => {
                        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
                        match self.window().model.explain(&pred, &refs) {
                            Some(tree) => {
                                let nodes = [crate::proof::node(self.window(), &tree)];
                                for l in crate::proof::lines(&nodes) {
                                    let _ = writeln!(out, "{l}");
                                }
                            }
                            None => {
                                let _ = writeln!(
                                    out,
                                    "{arg} does not hold in window {} (closed world)",
                                    self.window().id
                                );
                            }
                        }
                    }
                    None => {
                        let _ = writeln!(out, "usage: :why Pred(a, b)");
                    }
                },
                "lmm" => out.push_str(&self.lmm(arg)),
                "translator" => {
                    let msg = self.set_mode(arg);
                    let _ = writeln!(out, "{msg}");
                }
                "rules" => {
                    for r in self.engine().pad().program().rules() {
                        let _ = writeln!(out, "line {:>4}: {}", r.source.line, r.source.text);
                    }
                }
                "rule" | "define" => {
                    let msg = if arg.is_empty() {
                        format!(
                            "usage: :{name} {}",
                            if name == "rule" {
                                "∀x : Pedestrian(x) ∧ On(x, y) ∧ Road(y) ==> Crossing(x)"
                            } else {
                                "A pedestrian is jaywalking when it is on a road and moving"
                            }
                        )
                    } else {
                        self.add_rule(name == "rule", arg)
                    };
                    let _ = writeln!(out, "{msg}");
                }
                "load" => {
                    if arg.is_empty() {
                        out.push_str("usage: :load FILE.yaml\n");
                    } else {
                        let msg = self.load_pad(PathBuf::from(arg));
                        let _ = writeln!(out, "{msg}");
                    }
                }
                other => {
                    let _ = writeln!(
                        out,
                        "unknown command `:{other}`; `:help` lists the commands"
                    );
                }
            }
            return out;
        }
        let prepared = match self.prepare(line) {
            Ok(p) => {
                if p.question.is_some() {
                    let _ = writeln!(out, "query: {}", p.query);
                }
                for n in &p.notes {
                    let _ = writeln!(out, "note: {n}");
                }
                p
            }
            Err(e) => {
                let _ = writeln!(out, "{e}");
                if let Some(hint) = command_hint(line) {
                    let _ = writeln!(out, "{hint}");
                }
                return out;
            }
        };
        if prepared.temporal.is_some() {
            // A temporal question looks back from the window in focus.
            let at = self.window().id.clone();
            match self
                .pipeline
                .ask_temporal(&prepared, Some(&at), AskOptions::default())
            {
                Ok(Some(t)) => {
                    let _ = writeln!(
                        out,
                        "{}{} (windows up to {at})\n{}",
                        t.result.answer.as_str().to_uppercase(),
                        crate::render::count_suffix(&t.result),
                        t.headline
                    );
                    out.push_str(&self.show_page(t.result));
                }
                Ok(None) => {}
                Err(e) => {
                    let _ = writeln!(out, "{}", crate::session::message(&e));
                }
            }
            return out;
        }
        let r = self
            .pipeline
            .ask_window(self.window(), &prepared, AskOptions::default());
        let _ = writeln!(
            out,
            "{}{} (window {})",
            r.answer.as_str().to_uppercase(),
            crate::render::count_suffix(&r),
            r.window
        );
        let invalid = r.answer == Outcome::Invalid;
        out.push_str(&self.show_page(r));
        if invalid && let Some(hint) = command_hint(line) {
            let _ = writeln!(out, "{hint}");
        }
        out
    }

    /// Shows the first page of an answer and keeps the rest for `more`:
    /// the pages of an answer come from its one run (one that stopped at
    /// a limit lists what it found before it), never from running the
    /// query again.
    fn show_page(&mut self, r: AskResult) -> String {
        let mut out = String::new();
        for line in crate::render::detail_lines_page(&r, 0, PAGE) {
            let _ = writeln!(out, "{line}");
        }
        self.pending = None;
        if r.answer == Outcome::Yes && r.bindings.len() > PAGE {
            let _ = writeln!(
                out,
                "  … {} more: `more` (or `;`) shows the next {PAGE}",
                r.bindings.len() - PAGE
            );
            self.pending = Some(Pending::Computed {
                result: Box::new(r),
                shown: PAGE,
            });
        }
        out
    }

    /// The next page of the last question's answers.
    fn more(&mut self) -> String {
        let mut out = String::new();
        match self.pending.take() {
            None => out.push_str("no more answers\n"),
            Some(Pending::Computed { result, shown }) => {
                for line in crate::render::detail_lines_page(&result, shown, PAGE) {
                    let _ = writeln!(out, "{line}");
                }
                let shown = shown + PAGE;
                if shown < result.bindings.len() {
                    let _ = writeln!(
                        out,
                        "  … {} more: `more` (or `;`)",
                        result.bindings.len() - shown
                    );
                    self.pending = Some(Pending::Computed { result, shown });
                }
            }
        }
        out
    }
}

/// Parses `Pred(a, b)` into its parts.
fn parse_ground(text: &str) -> Option<(String, Vec<String>)> {
    let f = crate::facts_text::parse_fact_line(text.trim()).ok()?;
    Some((f.predicate, f.args))
}

/// Every command name and alias (`:quit`/`:q` are handled by the line
/// loop, which stops on them); completion and the missing-colon hint read
/// this one list.
/// Commands that also work without their colon: one word that no question
/// or query could be.
const BARE_COMMANDS: &[&str] = &["help", "windows", "rules", "facts"];

/// Facts `:facts` counts instead of listing, unless asked for.
const HIDDEN_FACTS: &[&str] = &["SharesFrames"];

/// The REPL's commands (without their colon), for completion and hints.
pub(crate) const COMMANDS: &[&str] = &[
    "windows", "window", "w", "facts", "f", "why", "rules", "load", "rule", "define", "lmm",
    "more", "help", "h", "quit", "q",
];

/// A command typed without its colon (`help`, `why Moving(car_1)`) is the
/// likeliest slip; say so instead of leaving only a vocabulary or syntax
/// error.
fn command_hint(line: &str) -> Option<String> {
    let (first, rest) = line
        .split_once(char::is_whitespace)
        .map_or((line, ""), |(a, b)| (a, b.trim()));
    let name = first.to_lowercase();
    // Only what could be the command's own argument: one word (`window 3`,
    // `facts car_1`) or, for `why`, an atom. "Why is the white car moving?"
    // is a question, not a command without its colon.
    let argument_like = rest.is_empty()
        || !rest.contains(char::is_whitespace)
        || (name == "why" && rest.contains('(') && rest.ends_with(')'));
    (argument_like && COMMANDS.contains(&name.as_str())).then(|| {
        let example = if rest.is_empty() {
            format!(":{name}")
        } else {
            format!(":{name} {rest}")
        };
        format!("commands start with ':', e.g. `{example}`")
    })
}

const HELP: &str = "\
Ask a question (\"Is the white car moving?\") or a query (TypeOf(x, Car) ^ Moving(x)).
  :windows            list the windows (* marks the current one)
  :window ID|N        switch window
  :facts [OBJECT|all] the window's facts with provenance (SharesFrames only with `all`)
  :why Pred(a, b)     why a fact holds (its derivation)
  :rules              the LogicPad rules
  :load FILE          load another LogicPad (it is also re-read when it changes)
  :rule ∀x: … ==> N(x) add a rule in FOL (checked by the LogicPad checker) for this session
  :define SENTENCE    add a rule from English: \"A pedestrian is jaywalking when it is on a road and moving\"
  :translator [MODE]  show or set how questions become queries: grammar, llm or auto (needs --llm URL)
  :lmm c1|c2|c3 Q     ask the multimodal model (start with --llm URL) under a condition
  more  (or ;)        the next answers of the last question (answers come 10 at a time)
  :quit               leave
";

#[cfg(test)]
mod tests;
