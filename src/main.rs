//! The demx command line: parse arguments, run, map the result to an exit code.

/// Large arrays on huge pages: fewer TLB misses on beds beyond the cache.
#[global_allocator]
static ALLOC: demx::engine::hugepages::HugePages = demx::engine::hugepages::HugePages;

fn main() -> std::process::ExitCode {
    // a reader that stops early (`demx dump info ... | head`) ends demx as it
    // ends other Unix tools, instead of a failed print and a panic
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of one signal before any
    // thread starts; no handler is installed
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    demx::cli::main()
}
