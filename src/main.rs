//! The demx command line: parse arguments, run, map the result to an exit code.
fn main() -> std::process::ExitCode {
    demx::cli::main()
}
