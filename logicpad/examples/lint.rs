//! `cargo run -p logicpad --example lint -- FILE [--strict]`: prints every
//! diagnostic of a LogicPad file; exit code 0 clean, 1 warnings only, 2 errors.

fn main() {
    let mut args = std::env::args().skip(1);
    let Some(path) = args.next() else {
        eprintln!("usage: lint FILE.yaml [--strict]");
        std::process::exit(2);
    };
    let strict = args.any(|a| a == "--strict");
    let report = logicpad::lint_with(&path, strict);
    print!("{}", report.render());
    std::process::exit(report.exit_code());
}
