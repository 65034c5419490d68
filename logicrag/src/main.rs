//! The `logicrag` command line: a thin layer over the library crates. One
//! file per subcommand under `cli/`, each an `Args` struct and a `run`
//! function over [`logicrag::engine::Engine`]; `cli/mod.rs` holds what they
//! share (the source flags, loading, output).

use std::alloc::GlobalAlloc;
use std::process::ExitCode;

/// `println!` that reports a closed stdout (e.g. `| head`) as an error
/// instead of panicking.
macro_rules! outln {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout(), $($t)*)?
    }};
}
/// `print!` counterpart of [`outln!`].
macro_rules! outp {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout(), $($t)*)?
    }};
}

mod cli;

#[global_allocator]
static GLOBAL: Allocator = Allocator;

/// mimalloc, asked for a plain block whenever the layout's alignment is one
/// every mimalloc block has (8 bytes), and for an aligned one otherwise.
/// `mimalloc::MiMalloc` always asks for an aligned block, whose fast path
/// needs a free block already waiting in the size class; otherwise it took
/// the generic path, and for sizes that are not a power of two allocated
/// `size + align - 1` bytes (a tenth of a KITTI `--json` run's
/// instructions went into allocating).
struct Allocator;

/// The alignment of every block mimalloc hands out: block sizes are whole
/// words and a page's first block is 16-byte aligned.
const PLAIN_ALIGN: usize = 8;

// SAFETY: every layout goes to mimalloc; a block from `mi_malloc` is
// aligned to `PLAIN_ALIGN` at least, and larger alignments go through
// `MiMalloc`'s aligned calls. mimalloc frees and reallocates either kind.
unsafe impl GlobalAlloc for Allocator {
    #[inline]
    unsafe fn alloc(&self, layout: std::alloc::Layout) -> *mut u8 {
        if layout.align() <= PLAIN_ALIGN {
            // SAFETY: as for `MiMalloc::alloc`; the alignment is met above.
            unsafe { libmimalloc_sys::mi_malloc(layout.size()).cast() }
        } else {
            // SAFETY: the caller's contract, passed on.
            unsafe { mimalloc::MiMalloc.alloc(layout) }
        }
    }

    #[inline]
    unsafe fn alloc_zeroed(&self, layout: std::alloc::Layout) -> *mut u8 {
        if layout.align() <= PLAIN_ALIGN {
            // SAFETY: as for `alloc`.
            unsafe { libmimalloc_sys::mi_zalloc(layout.size()).cast() }
        } else {
            // SAFETY: the caller's contract, passed on.
            unsafe { mimalloc::MiMalloc.alloc_zeroed(layout) }
        }
    }

    #[inline]
    unsafe fn dealloc(&self, ptr: *mut u8, layout: std::alloc::Layout) {
        // SAFETY: `ptr` came from mimalloc (either call above).
        unsafe { mimalloc::MiMalloc.dealloc(ptr, layout) }
    }

    #[inline]
    unsafe fn realloc(&self, ptr: *mut u8, layout: std::alloc::Layout, new_size: usize) -> *mut u8 {
        if layout.align() <= PLAIN_ALIGN {
            // SAFETY: `ptr` came from mimalloc; the new block keeps the
            // alignment every block has.
            unsafe { libmimalloc_sys::mi_realloc(ptr.cast(), new_size).cast() }
        } else {
            // SAFETY: the caller's contract, passed on.
            unsafe { mimalloc::MiMalloc.realloc(ptr, layout, new_size) }
        }
    }
}

fn main() -> ExitCode {
    use clap::Parser as _;
    let args = cli::Cli::parse();
    match cli::run(args) {
        Ok(code) => code,
        Err(e) => {
            // A reader that stopped early (`| head`) is not an error.
            if e.downcast_ref::<std::io::Error>()
                .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
            {
                return ExitCode::SUCCESS;
            }
            eprintln!("error: {}", error_text(&e));
            ExitCode::from(2)
        }
    }
}

/// The error and its causes on one line, each cause once (as the Python
/// package words it: [`logicrag::session::message`]).
fn error_text(e: &anyhow::Error) -> String {
    logicrag::session::message(e.as_ref())
}
