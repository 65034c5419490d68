//! `logicrag ask`: a question or query on every window of a source (or
//! one), or a batch of `window<TAB>query` lines.

use super::{LlmArgs, SourceArgs};
use anyhow::{Context, Result, bail};
use clap::Args;
use logicrag::ask::{AskOptions, AskResult};
use logicrag::batch::{parse_queries, run_batch_in_order};
use logicrag::llm::{Condition, Lmm, LmmAnswer};
use logicrag::pipeline::Answer;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct AskArgs {
    #[command(flatten)]
    pub src: SourceArgs,
    /// A question in English or a query (`TypeOf(x, Car) ^ Moving(x)`).
    pub text: Option<String>,
    /// A batch of `window<TAB>query` lines.
    #[arg(long, conflicts_with = "text")]
    pub queries: Option<PathBuf>,
    /// Only this window id (default: every window). A temporal query
    /// (`(Q1) THEN (Q2)`, `EVER: Q`, …) looks at every window up to and
    /// including it.
    #[arg(long = "window-id")]
    pub window_id: Option<String>,
    /// One JSON object per line and answer, then one `summary` object.
    #[arg(long)]
    pub json: bool,
    /// `window<TAB>index<TAB>yes|no<TAB>count` lines (the KB benchmark's answer format).
    #[arg(long, conflicts_with = "json")]
    pub tsv: bool,
    /// Skip proofs and why-not (faster batches).
    #[arg(long)]
    pub no_proofs: bool,
    /// Write the batch's answers to FILE as Parquet (the answers table of
    /// docs/formats.md, proofs as JSON unless --no-proofs) instead of
    /// printing them.
    #[cfg(feature = "arrow")]
    #[arg(long, value_name = "FILE", requires = "queries", conflicts_with_all = ["text", "json", "tsv"])]
    pub parquet: Option<PathBuf>,
    /// The most bindings a query may have; more is refused as too large
    /// instead of taking memory without bound.
    /// List at most N bindings per window: a query with more is answered
    /// from the first N the engine finds (not sorted), saying that more
    /// exist, at the cost of N answers however many there are.
    #[arg(long, value_name = "N", conflicts_with_all = ["queries", "tsv"], value_parser = clap::value_parser!(u64).range(1..))]
    pub limit: Option<u64>,
    /// With --limit: skip the first K bindings (the next page).
    #[arg(long, value_name = "K", requires = "limit")]
    pub offset: Option<u64>,
    #[arg(long = "max-answers", default_value_t = logicpad::DEFAULT_MAX_ANSWERS, value_parser = clap::value_parser!(usize))]
    pub max_answers: usize,
    /// How many rule steps deep each proof goes; a derived fact deeper than
    /// that is shown as truncated (0: the answer's own facts only). Output
    /// costs what is rendered.
    #[arg(long = "proof-depth", default_value_t = logicpad::ProofLimits::DEFAULT_MAX_DEPTH, conflicts_with = "no_proofs")]
    pub proof_depth: usize,
    /// Also ask a multimodal model under a condition of the paper: c1
    /// (frames and question), c2 (plus the logic answer), c3 (plus the facts).
    #[arg(long, conflicts_with_all = ["queries", "tsv"])]
    pub lmm: Option<Condition>,
    #[command(flatten)]
    pub llm: LlmArgs,
}

/// Frames of a window as PNGs for the model; a source without pictures
/// gives none (said once on stderr by the caller).
pub fn window_pngs(
    images: Option<&logicrag::images::FrameImages>,
    first: u32,
    last: u32,
    n: usize,
) -> Result<Vec<Vec<u8>>> {
    let Some(images) = images else {
        return Ok(Vec::new());
    };
    Ok(images.pngs(first, last, n, logicrag::images::DEFAULT_MAX_SIDE)?)
}

/// Characters of a reply shown on the terminal (`--json` has it whole).
const REPLY_CHARS: usize = 400;

fn clip(text: &str, max: usize) -> String {
    if text.chars().count() <= max {
        return text.to_string();
    }
    let cut: String = text.chars().take(max).collect();
    format!("{cut}… (--json has the whole reply)")
}

/// The model's answer as a line: condition, verdict, reply.
pub fn lmm_line(a: &LmmAnswer) -> String {
    format!(
        "  lmm {}: {} — {}{}",
        a.condition.as_str(),
        a.verdict.as_str().to_uppercase(),
        clip(&a.reply.trim().replace('\n', " "), REPLY_CHARS),
        if a.cached { "  (cached)" } else { "" }
    )
}

/// One window's answer as text: the headline, then the evidence.
pub fn print_result(out: &mut impl Write, r: &AskResult) -> Result<()> {
    writeln!(
        out,
        "[{}] {} → {}{}",
        r.window,
        r.query,
        r.answer.as_str().to_uppercase(),
        logicrag::render::count_suffix(r)
    )?;
    for line in logicrag::render::detail_lines(r) {
        writeln!(out, "{line}")?;
    }
    Ok(())
}

/// One batch answer as rendered on a worker thread.
#[derive(Default)]
struct Rendered {
    /// The output line(s).
    bytes: Vec<u8>,
    /// What the `--tsv` line cannot say ([`tsv_note`]).
    invalid: Option<String>,
    /// Why rendering failed.
    error: Option<String>,
}

/// Writes `chunks` in order with vectored writes (a `BufWriter` passes a
/// write at least as large as its buffer straight through) and empties it.
fn write_chunks(out: &mut impl Write, chunks: &mut Vec<Vec<u8>>) -> std::io::Result<()> {
    use std::io::IoSlice;
    let mut slices: Vec<IoSlice<'_>> = chunks
        .iter()
        .filter(|c| !c.is_empty())
        .map(|c| IoSlice::new(c))
        .collect();
    let mut bufs = &mut slices[..];
    while !bufs.is_empty() {
        match out.write_vectored(bufs) {
            Ok(0) => return Err(std::io::ErrorKind::WriteZero.into()),
            Ok(n) => IoSlice::advance_slices(&mut bufs, n),
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    drop(slices);
    chunks.clear();
    Ok(())
}

/// About how many bytes the `--json` line of `r` takes, so that its
/// buffer is allocated once: grown from empty, a line with proofs (3.5 KB
/// on average on the KITTI benchmark) was reallocated and copied about
/// ten times.
fn rendered_size(r: &AskResult) -> usize {
    fn nodes(n: &[logicrag::proof::ProofNode]) -> usize {
        n.iter().map(|n| 1 + nodes(&n.premises)).sum()
    }
    let proof_nodes: usize = r.proofs.iter().map(|p| nodes(p)).sum();
    1024 + 64 * r.bindings.len() + 192 * proof_nodes + 256 * r.why_not.len()
}

/// The output buffer of `ask`.
const OUT_BUFFER_BYTES: usize = 1 << 20;

/// The most invalid queries of a `--tsv` run whose reasons are printed.
const INVALID_REPORTED: usize = 20;

/// What a `--tsv` line cannot say about an answer, for stderr: why it is
/// invalid, or that its run stopped at a limit (its count is then a lower
/// bound). `None` for an answer its line says whole.
fn tsv_note(r: &AskResult) -> Option<String> {
    if r.answer == logicrag::ask::Outcome::Invalid {
        return Some(
            r.reasons
                .first()
                .map_or("invalid", String::as_str)
                .to_string(),
        );
    }
    let why = r.stopped?;
    Some(match r.reasons.first() {
        Some(reason) if r.answer == logicrag::ask::Outcome::Unknown => reason.clone(),
        _ => format!(
            "the run stopped at its {why} limit: the count {} is a lower bound",
            r.count
        ),
    })
}

/// Prints what the lines of a `--tsv` run cannot say (see [`tsv_note`])
/// on stderr, the first [`INVALID_REPORTED`] of them.
fn report_invalid<'a>(file: &str, answers: impl Iterator<Item = (&'a str, usize, &'a AskResult)>) {
    let mut n = 0usize;
    for (window, index, r) in answers {
        let Some(reason) = tsv_note(r) else {
            continue;
        };
        n += 1;
        if n <= INVALID_REPORTED {
            eprintln!("{file}: window {window}, query {index}: {reason}");
        }
    }
    if n > INVALID_REPORTED {
        eprintln!("{file}: … and {} more", n - INVALID_REPORTED);
    }
}

pub fn run(a: AskArgs) -> Result<ExitCode> {
    let base = if a.tsv {
        AskOptions::COUNT
    } else if a.no_proofs {
        AskOptions::BINDINGS
    } else {
        AskOptions::default()
    };
    let opts = logicrag::session::ask_options(base, a.max_answers, a.proof_depth)?;
    let out = std::io::stdout();
    // Not locked: a batch writes from whichever worker thread completes
    // the next answers (the buffer takes the lock only when it flushes).
    // A large buffer: a batch with proofs writes hundreds of megabytes,
    // and 8 KiB writes were one system call per two or three answers.
    let mut out = std::io::BufWriter::with_capacity(OUT_BUFFER_BYTES, out);
    if let Some(qfile) = &a.queries {
        if a.window_id.is_some() {
            bail!("--window-id does not apply to --queries (each line names its window)");
        }
        let file = qfile.display().to_string();
        let read_batch = || -> Result<_> {
            let text = perception::textfile::read_text_file(qfile)
                .with_context(|| format!("reading {}", qfile.display()))?;
            Ok(parse_queries(&text, &file)?)
        };
        // The queries file and the LogicPad are read while a source that is
        // read (facts, labels, the simulator) loads on the other threads:
        // reading 80,000 query lines was a serial tenth of a large batch's
        // wall time, and a bad queries file is still the error reported
        // first. Frames are perceived only after both have been read, so
        // that a mistake in either is reported at once, not after minutes
        // of detection.
        let perceived = a
            .src
            .spec()
            .is_ok_and(|s| matches!(s, logicrag::source::SourceSpec::Frames { .. }));
        let (queries, pipeline) = if perceived {
            let read = read_batch()?;
            (read, a.src.open(None)?)
        } else {
            let (read, opened) = rayon::join(read_batch, || a.src.open(None));
            (read?, opened?)
        };
        #[cfg(feature = "arrow")]
        if let Some(path) = &a.parquet {
            let rows = logicrag::batch::write_parquet(pipeline, &queries, &file, opts, path)?;
            eprintln!("wrote {rows} answers to {}", path.display());
            return Ok(ExitCode::SUCCESS);
        }
        // Each result is rendered on the worker that answered it and
        // written as soon as it and every earlier one are answered; a write
        // error stops the output and is reported after.
        let render = |i: usize, r: AskResult| -> Rendered {
            let mut bytes = Vec::with_capacity(if a.json { rendered_size(&r) } else { 64 });
            let Some(q) = queries.get(i) else {
                return Rendered {
                    error: Some(format!("no query {i} in the batch")),
                    ..Rendered::default()
                };
            };
            let invalid = tsv_note(&r);
            let written = if a.tsv {
                writeln!(
                    bytes,
                    "{}\t{}\t{}\t{}",
                    q.window,
                    q.index,
                    r.answer.as_str(),
                    r.count
                )
                .map_err(anyhow::Error::from)
            } else if a.json {
                // Straight to bytes: building a `Value` tree per answer
                // first cost more than answering.
                logicrag::json::write_batch_line(&mut bytes, &r, q.index, &q.query)
                    .map_err(anyhow::Error::from)
                    .map(|()| bytes.push(b'\n'))
            } else {
                print_result(&mut bytes, &r)
            };
            Rendered {
                bytes,
                invalid,
                error: written.err().map(|e| e.to_string()),
            }
        };
        let mut write_error: Option<anyhow::Error> = None;
        // The rendered answers, written a megabyte at a time by one
        // vectored write rather than copied into the output buffer (a
        // batch with proofs writes hundreds of megabytes).
        let mut pending: Vec<Vec<u8>> = Vec::new();
        let mut pending_bytes = 0usize;
        let mut invalid: Vec<(usize, String)> = Vec::new();
        let mut invalid_count = 0usize;
        run_batch_in_order(pipeline, &queries, &file, opts, &render, &mut |i, r| {
            if write_error.is_some() {
                return;
            }
            if let Some(e) = r.error {
                write_error = Some(anyhow::anyhow!("rendering query {i}: {e}"));
                return;
            }
            if let Some(reason) = r.invalid {
                invalid_count += 1;
                if invalid.len() < INVALID_REPORTED {
                    invalid.push((i, reason));
                }
            }
            pending_bytes += r.bytes.len();
            pending.push(r.bytes);
            if pending_bytes >= OUT_BUFFER_BYTES {
                pending_bytes = 0;
                if let Err(e) = write_chunks(&mut out, &mut pending) {
                    write_error = Some(e.into());
                }
            }
        })?;
        if let Some(e) = write_error {
            return Err(e);
        }
        write_chunks(&mut out, &mut pending)?;
        out.flush()?;
        if a.tsv {
            // The TSV line says only `invalid`; the reason goes to stderr
            // (the first few; text and JSON output carry it themselves).
            for (i, reason) in &invalid {
                if let Some(q) = queries.get(*i) {
                    eprintln!("{file}: window {}, query {}: {reason}", q.window, q.index);
                }
            }
            if invalid_count > INVALID_REPORTED {
                eprintln!("{file}: … and {} more", invalid_count - INVALID_REPORTED);
            }
        }
        return Ok(ExitCode::SUCCESS);
    }
    let Some(text) = &a.text else {
        bail!("give a question or query, or --queries FILE")
    };
    let mut pipeline = a.src.open(Some(a.llm.translator()?))?;
    let images = pipeline.take_images();
    let prepared = pipeline.prepare(text)?;
    let lmm = match a.lmm {
        Some(c) => {
            if images.is_none() {
                eprintln!(
                    "note: {} has no pictures; the model sees only the text",
                    pipeline.label()
                );
            }
            Some((
                c,
                Lmm {
                    chat: a.llm.chat()?,
                    templates: a.llm.templates(Some(c))?,
                },
            ))
        }
        None => None,
    };
    if !a.json {
        if let Some(q) = &prepared.question {
            writeln!(out, "question: {q}\nquery:    {}", prepared.query)?;
        }
        for n in &prepared.notes {
            writeln!(out, "note:     {n}")?;
        }
    }
    // A temporal query is answered once, over every window up to the one
    // asked about (all of them without --window-id); any other question
    // is answered per window, and only the window asked about is reasoned.
    let timeline = pipeline.ask_temporal(&prepared, a.window_id.as_deref(), opts)?;
    let pipeline = if timeline.is_some() {
        pipeline
    } else {
        pipeline.only(a.window_id.as_deref())?
    };
    if timeline.is_some() && a.limit.is_some() {
        eprintln!(
            "note: --limit pages a window's bindings; a temporal query has one answer for the video, shown whole"
        );
    }
    let answers: Vec<Answer<'_>> = match a.limit {
        _ if timeline.is_some() => match (&timeline, pipeline.answered_at(a.window_id.as_deref())?)
        {
            (Some(t), Some(window)) => vec![Answer {
                window,
                result: t.result.clone(),
                truncated: None,
            }],
            _ => Vec::new(),
        },
        Some(limit) => {
            let page = logicrag::engine::Page {
                offset: usize::try_from(a.offset.unwrap_or(0)).unwrap_or(usize::MAX),
                limit: usize::try_from(limit).unwrap_or(usize::MAX),
            };
            // One run, stopped at the page's end: the page's cost, not
            // the query's.
            let opts = AskOptions {
                limits: logicpad::Limits {
                    answers: page
                        .offset
                        .saturating_add(page.limit)
                        .min(opts.limits.answers),
                    ..opts.limits
                },
                ..opts
            };
            pipeline.ask_page(&prepared, None, opts, page)?
        }
        None => pipeline.ask(&prepared, None, opts)?,
    };
    let mut kbs = Vec::with_capacity(answers.len());
    let mut results: Vec<AskResult> = Vec::with_capacity(answers.len());
    let mut cuts = Vec::with_capacity(answers.len());
    for Answer {
        window,
        result,
        truncated,
    } in answers
    {
        kbs.push(window);
        results.push(result);
        cuts.push(truncated);
    }
    let question = prepared.question.clone().unwrap_or_else(|| text.clone());
    let mut verdicts: Vec<Option<LmmAnswer>> = Vec::new();
    for (kb, r) in kbs.iter().zip(&results) {
        verdicts.push(match &lmm {
            Some((c, model)) => {
                let ctx = logicrag::context::RagContext::new(
                    kb,
                    Some(&question),
                    r,
                    pipeline.engine().words(),
                );
                let pngs = window_pngs(
                    images.as_ref(),
                    kb.first_frame,
                    kb.last_frame,
                    a.llm.lmm_frames,
                )?;
                Some(model.ask(*c, &question, &ctx, &pngs)?)
            }
            None => None,
        });
    }
    let summary = pipeline.summary(&prepared, &results);
    if !a.json && !a.tsv {
        let headline = match &timeline {
            Some(t) => t.headline.clone(),
            None => summary.headline(),
        };
        writeln!(out, "answer:   {headline}")?;
    }
    if a.tsv {
        report_invalid("query", results.iter().map(|r| (r.window.as_str(), 0, r)));
    }
    for ((r, lmm), cut) in results.iter().zip(&verdicts).zip(&cuts) {
        if a.tsv {
            writeln!(out, "{}\t0\t{}\t{}", r.window, r.answer.as_str(), r.count)?;
        } else if a.json {
            let mut v = match &timeline {
                Some(t) => {
                    let mut v = logicrag::json::temporal_result(t, &prepared)?;
                    if let (Some(l), Some(o)) = (lmm, v.as_object_mut()) {
                        o.insert("lmm".into(), serde_json::to_value(l)?);
                    }
                    v
                }
                None => logicrag::json::answer_object(r, &prepared, lmm.as_ref())?,
            };
            if let (Some(cut), Some(o)) = (cut, v.as_object_mut()) {
                o.insert("truncated".into(), serde_json::to_value(cut)?);
            }
            writeln!(out, "{v}")?;
        } else {
            print_result(&mut out, r)?;
            if let Some(cut) = cut {
                writeln!(
                    out,
                    "  ({} binding{} from {}{}{})",
                    cut.shown,
                    if cut.shown == 1 { "" } else { "s" },
                    cut.offset,
                    cut.total.map(|t| format!(" of {t}")).unwrap_or_default(),
                    if cut.more {
                        format!(
                            "; more exist: --offset {} for the next page",
                            cut.offset + cut.shown
                        )
                    } else {
                        String::new()
                    }
                )?;
            }
            if let Some(l) = lmm {
                writeln!(out, "{}", lmm_line(l))?;
            }
        }
    }
    if a.json {
        let object = match &timeline {
            Some(t) => logicrag::json::temporal_summary(t, pipeline.engine().words(), &prepared),
            None => logicrag::json::summary_object(&summary, &prepared),
        };
        writeln!(out, "{object}")?;
    }
    Ok(ExitCode::SUCCESS)
}
