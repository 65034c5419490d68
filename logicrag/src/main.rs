//! The `logicrag` command line: a thin layer over the library crates. One
//! file per subcommand under `cli/`, each an `Args` struct and a `run`
//! function over [`logicrag::engine::Engine`]; `cli/mod.rs` holds what they
//! share (the source flags, loading, output).

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
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

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
