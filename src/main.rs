//! The `flicker` command line: run scenes and inspect event logs.
//!
//! Exit codes, decided in one place ([`cli::exit`]): 0 completed (or a Zeno
//! accumulation recognised and handled), 2 bad input, 3 the run cannot be
//! trusted (a method failed), 130 interrupted.

mod cli;

use clap::Parser;

fn main() {
    let args = cli::Cli::parse();
    let code = match cli::dispatch(args) {
        Ok(code) => code,
        Err(error) => {
            eprintln!("flicker: {}", error.message);
            error.code
        }
    };
    std::process::exit(code as i32);
}
