//! Scheduling the windows: [`build_all`] reasons them in parallel over
//! contiguous runs (each window reusing its predecessor's derivations), and
//! [`answer_by_window_in_order`] builds each window once and answers every
//! item that names it (what `crate::pipeline::Pipeline` streams batches and
//! evaluations through).

use super::*;

/// Answers items addressed to windows by id, reasoning over each window
/// once and windows in parallel, handing each answer to `emit` in item
/// order as soon as every earlier item is answered, instead of keeping
/// them all: a batch writes its output while it runs and holds only the
/// answers that wait for an earlier one. Runs of consecutive windows are taken in
/// order by the worker threads, so for items listed window by window (a
/// benchmark's queries file) few answers wait. `emit` runs under a lock on
/// whichever worker completes the run of items.
///
/// `window_of(i)` names item `i`'s window; an id that names no window is
/// `unknown(i)` for the first such item, before any reasoning. `answer`
/// runs on worker threads, and so does `done(n)`, called when a window's
/// `n` items are answered.
///
/// On an error (a window's facts cannot be stored) the items before it have
/// been emitted and the others are not.
#[allow(clippy::too_many_arguments)]
pub(crate) fn answer_by_window_in_order<T, E>(
    program: &Program,
    windows: Vec<WindowInput>,
    items: usize,
    window_of: impl Fn(usize) -> String,
    unknown: impl FnOnce(usize) -> E,
    answer: impl Fn(&WindowKb, usize) -> T + Sync,
    done: &(dyn Fn(usize) + Sync),
    emit: &mut (dyn FnMut(usize, T) + Send),
) -> Result<(), E>
where
    T: Send,
    E: Send + From<KbError>,
{
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
    let by_id: std::collections::HashMap<&str, usize> = windows
        .iter()
        .enumerate()
        .map(|(i, w)| (w.id.as_str(), i))
        .collect();
    // Item positions grouped by window, in the windows' own order.
    let mut groups: Vec<Vec<usize>> = vec![Vec::new(); windows.len()];
    for i in 0..items {
        match by_id.get(window_of(i).as_str()) {
            Some(&w) => groups[w].push(i),
            None => return Err(unknown(i)),
        }
    }
    let work: Vec<(WindowInput, Vec<usize>)> = windows
        .into_iter()
        .zip(groups)
        .filter(|(_, g)| !g.is_empty())
        .collect();
    // Contiguous runs of windows, each reasoned in order so that a window
    // reuses its predecessor's unchanged components; a KB is dropped as soon
    // as the next one is built. Workers take runs by a shared counter, in
    // order, so answers come out roughly in item order.
    type Run = Vec<(WindowInput, Vec<usize>)>;
    let runs: Vec<Mutex<Option<Run>>> = chained_runs(work)
        .into_iter()
        .map(|r| Mutex::new(Some(r)))
        .collect();
    let next_run = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    struct Reorder<'e, T> {
        next: usize,
        waiting: BTreeMap<usize, T>,
        emit: &'e mut (dyn FnMut(usize, T) + Send),
        error: Option<KbError>,
    }
    let state = Mutex::new(Reorder {
        next: 0,
        waiting: BTreeMap::new(),
        emit,
        error: None,
    });
    let worker = || {
        loop {
            if failed.load(Ordering::Relaxed) {
                return;
            }
            let r = next_run.fetch_add(1, Ordering::Relaxed);
            let Some(slot) = runs.get(r) else { return };
            let Some(run) = slot.lock().ok().and_then(|mut g| g.take()) else {
                continue;
            };
            let mut prev: Option<WindowKb> = None;
            for (input, group) in run {
                let kb = match WindowKb::build_after(input, program, prev.as_ref()) {
                    Ok(kb) => kb,
                    Err(e) => {
                        failed.store(true, Ordering::Relaxed);
                        if let Ok(mut st) = state.lock() {
                            st.error.get_or_insert(e);
                        }
                        return;
                    }
                };
                let n = group.len();
                // A window's items are answered in parallel too: a large
                // window with many questions (the 2M-fact benchmark window,
                // 100 queries) is otherwise one thread's work while the
                // others have no window to take. Rayon's work stealing
                // keeps the threads busy with other runs' items meanwhile.
                let answered: Vec<(usize, T)> = {
                    use rayon::prelude::*;
                    group.into_par_iter().map(|i| (i, answer(&kb, i))).collect()
                };
                done(n);
                // A poisoned lock means `emit` panicked on another worker;
                // that panic is re-raised by the scope.
                let Ok(mut st) = state.lock() else { return };
                st.waiting.extend(answered);
                loop {
                    let next = st.next;
                    let Some(t) = st.waiting.remove(&next) else {
                        break;
                    };
                    (st.emit)(next, t);
                    st.next += 1;
                }
                drop(st);
                prev = Some(kb);
            }
        }
    };
    let threads = rayon::current_num_threads().clamp(1, runs.len().max(1));
    rayon::scope(|s| {
        for _ in 0..threads {
            s.spawn(|_| worker());
        }
    });
    let st = state.into_inner().unwrap_or_else(|e| e.into_inner());
    match st.error {
        Some(e) => Err(E::from(e)),
        None => Ok(()),
    }
}

/// Windows are chained (each reasoned from the previous one's model) in
/// runs of this many at most, so that a long sequence still spreads over
/// every thread while each run keeps the reuse of overlapping windows.
pub(super) const CHAIN: usize = 16;

/// Reasons every window, in parallel over contiguous runs of windows; within
/// a run each window reuses what its predecessor's model derived from
/// unchanged inputs (`WindowKb::build_after`). The KBs come back in input
/// order; `done` is called once per window built (on worker threads).
pub fn build_all(
    program: &Program,
    windows: Vec<WindowInput>,
    done: &(dyn Fn() + Sync),
) -> Result<Vec<WindowKb>, KbError> {
    use rayon::prelude::*;
    let runs = chained_runs(windows);
    let built: Result<Vec<Vec<WindowKb>>, KbError> = runs
        .into_par_iter()
        .map(|run| {
            let mut out: Vec<WindowKb> = Vec::with_capacity(run.len());
            for input in run {
                let kb = WindowKb::build_after(input, program, out.last())?;
                done();
                out.push(kb);
            }
            Ok(out)
        })
        .collect();
    Ok(built?.into_iter().flatten().collect())
}

/// Splits `items` into contiguous runs for [`build_all`]: at most
/// [`CHAIN`] long, and enough of them for every thread.
pub(super) fn chained_runs<T>(items: Vec<T>) -> Vec<Vec<T>> {
    let threads = rayon::current_num_threads().max(1);
    let len = items.len().div_ceil(threads).clamp(1, CHAIN);
    let mut runs: Vec<Vec<T>> = Vec::with_capacity(items.len().div_ceil(len));
    for item in items {
        match runs.last_mut() {
            Some(run) if run.len() < len => run.push(item),
            _ => runs.push(vec![item]),
        }
    }
    runs
}
