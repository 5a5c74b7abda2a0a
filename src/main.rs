//! The `imitate` command. Everything it does lives in the library; this
//! binary parses arguments and turns the outcome into an exit code.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
