//! The `flicker` command line over the scene models this crate ships (see
//! [`flicker::cli`]; a program with models of its own calls
//! [`flicker::cli::main`] with a registry that knows them).

fn main() {
    std::process::exit(flicker::cli::main(flicker::scene::Registry::builtin()));
}
