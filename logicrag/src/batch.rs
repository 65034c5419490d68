//! Batches of `window<TAB>query` lines, answered window by window in
//! parallel. This is the path the KB benchmark takes through the CLI.

use crate::ask::{AskOptions, AskResult};
use crate::engine::Prepared;
use crate::kb::KbError;
use crate::pipeline::Pipeline;
use std::collections::HashMap;

/// Errors of a batch.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    /// Occurs when a line of the queries file is not `window<TAB>query`.
    #[error("{file}:{line}: expected `window<TAB>query`, found `{text}`")]
    Syntax {
        /// The queries file.
        file: String,
        /// 1-based line.
        line: usize,
        /// The line.
        text: String,
    },
    /// Occurs when a query names a window the source does not have.
    #[error("{file}:{line}: {window}")]
    UnknownWindow {
        /// The queries file.
        file: String,
        /// 1-based line.
        line: usize,
        /// The window the line names, and the source's.
        window: crate::kb::NoWindow,
    },
    /// Occurs when a window's KB cannot be built.
    #[error(transparent)]
    Kb(#[from] KbError),
    /// Occurs when the answers cannot be written as Parquet (a full disk,
    /// a folder that cannot be written).
    #[cfg(feature = "arrow")]
    #[error(transparent)]
    Table(#[from] crate::arrow::TableError),
}

/// One query of a batch.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BatchQuery {
    /// Window id.
    pub window: String,
    /// 0-based position among its window's queries.
    pub index: usize,
    /// Query text.
    pub query: String,
    /// 1-based line in the queries file.
    pub line: usize,
}

/// Parses a queries file (`window<TAB>query` per line; blank lines and `#`
/// comments allowed). Indexes count per window, in file order.
pub fn parse_queries(text: &str, file: &str) -> Result<Vec<BatchQuery>, BatchError> {
    let mut out = Vec::new();
    let mut per_window: HashMap<String, usize> = HashMap::new();
    for (i, line) in text.lines().enumerate() {
        let t = line.trim_end_matches('\r');
        if t.trim().is_empty() || t.trim_start().starts_with('#') {
            continue;
        }
        let Some((w, q)) = t.split_once('\t') else {
            return Err(BatchError::Syntax {
                file: file.into(),
                line: i + 1,
                text: t.into(),
            });
        };
        if w.is_empty() || q.trim().is_empty() {
            return Err(BatchError::Syntax {
                file: file.into(),
                line: i + 1,
                text: t.into(),
            });
        }
        // Looked up before inserting: a window's name is copied into the
        // map once, not once per line.
        let index = match per_window.get_mut(w) {
            Some(n) => {
                *n += 1;
                *n - 1
            }
            None => {
                per_window.insert(w.to_string(), 1);
                0
            }
        };
        out.push(BatchQuery {
            window: w.to_string(),
            index,
            query: q.to_string(),
            line: i + 1,
        });
    }
    Ok(out)
}

/// Answers a batch on `pipeline`'s windows; results come back in the
/// order of `queries`. Windows are reasoned once each, in parallel.
pub fn run_batch(
    pipeline: Pipeline,
    queries: &[BatchQuery],
    file: &str,
    opts: AskOptions,
) -> Result<Vec<AskResult>, BatchError> {
    let mut out = Vec::with_capacity(queries.len());
    run_batch_in_order(pipeline, queries, file, opts, &|_, r| r, &mut |_, r| {
        out.push(r)
    })?;
    Ok(out)
}

/// [`run_batch`], handing each result, as `render(query index, result)`
/// made it on the worker that answered it, to `emit(query index, rendered)`
/// in the order of `queries` as soon as it and every earlier one are
/// answered (see `Pipeline::answer_each_in_order`): output is
/// written while the batch runs, a large batch is not held in memory, and
/// the rendering (JSON with proofs: most of the output's cost) runs on
/// every worker rather than on the one writer.
pub fn run_batch_in_order<R: Send>(
    pipeline: Pipeline,
    queries: &[BatchQuery],
    file: &str,
    opts: AskOptions,
    render: &(dyn Fn(usize, AskResult) -> R + Sync),
    emit: &mut (dyn FnMut(usize, R) + Send),
) -> Result<(), BatchError> {
    // Each distinct query text is parsed and checked once: a benchmark
    // repeats its queries across windows (the KITTI one: 8,378 distinct of
    // 79,600), and parsing every line was a quarter of the run.
    let mut distinct: HashMap<&str, usize> = HashMap::new();
    let mut texts: Vec<&str> = Vec::new();
    let of_item: Vec<usize> = queries
        .iter()
        .map(|q| {
            *distinct.entry(q.query.as_str()).or_insert_with(|| {
                texts.push(&q.query);
                texts.len() - 1
            })
        })
        .collect();
    // Every line is a query as written, whatever it looks like: a batch
    // is never translated.
    let prepared: Vec<Prepared> = {
        use rayon::prelude::*;
        let engine = pipeline.engine();
        texts.par_iter().map(|t| engine.prepare_query(t)).collect()
    };
    pipeline.answer_each_in_order(
        queries.len(),
        |i| queries[i].window.clone(),
        |i, window| BatchError::UnknownWindow {
            file: file.into(),
            line: queries[i].line,
            window,
        },
        |engine, kb, i| {
            let r = match of_item.get(i).and_then(|&p| prepared.get(p)) {
                Some(p) => engine.ask(kb, p, opts),
                // `of_item` covers every item; should it not, the query is
                // prepared here rather than dropped.
                None => engine.ask(kb, &engine.prepare_query(&queries[i].query), opts),
            };
            render(i, r)
        },
        &|_| {},
        emit,
    )
}

/// A batch's answers written to `path` as one Parquet file of the answers
/// schema (docs/formats.md), batch by batch as they come, in the order of
/// `queries` (proofs, when `opts` asks for them, as the nested `proofs`
/// column); the number of rows written. A write that fails stops the
/// batch at once.
#[cfg(feature = "arrow")]
pub fn write_parquet(
    pipeline: Pipeline,
    queries: &[BatchQuery],
    file: &str,
    opts: AskOptions,
    path: &std::path::Path,
) -> Result<usize, BatchError> {
    use crate::arrow::{AnswersBuilder, ParquetWriter, TableError, answers_schema};
    let video = pipeline.label().to_string();
    let mut writer = ParquetWriter::create(path, answers_schema())?;
    let mut builder = AnswersBuilder::new(opts.proofs && !opts.count_only);
    let mut failed: Option<TableError> = None;
    run_batch_in_order(pipeline, queries, file, opts, &|_, r| r, &mut |i, r| {
        if failed.is_some() {
            return;
        }
        let Some(q) = queries.get(i) else {
            failed = Some(TableError::Malformed(format!("no query {i} in the batch")));
            return;
        };
        builder.push(&video, None, q.index, &r);
        if builder.is_full()
            && let Err(e) = builder.finish().and_then(|b| writer.write(&b))
        {
            failed = Some(e);
        }
    })?;
    if let Some(e) = failed {
        return Err(e.into());
    }
    if !builder.is_empty() {
        writer.write(&builder.finish()?)?;
    }
    Ok(writer.finish()?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn queries_file_indexes_count_per_window() {
        let q = parse_queries("w1\tA(x)\nw2\tB(x)\n\n# c\nw1\tC(x)^D(x, y)\n", "q.tsv").unwrap();
        assert_eq!(q.len(), 3);
        assert_eq!((q[2].window.as_str(), q[2].index), ("w1", 1));
        assert_eq!(q[1].index, 0);
        let err = parse_queries("w1 A(x)\n", "q.tsv").unwrap_err();
        assert!(err.to_string().starts_with("q.tsv:1:"), "{err}");
    }
}
