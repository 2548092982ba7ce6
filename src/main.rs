//! tdex command line: parse flags, validate them into a plan before any work, run, and map
//! errors to an exit code (2: bad input, 1: the run failed).

mod bench;
mod cli;
mod compare_command;
mod demo;
mod export;
mod extrapolation;
mod import;
mod inspect;
mod pair;
mod progress;
mod record;
mod report;
mod run;
mod study;

use std::process::ExitCode;
// the analysis modules live in the library half of this package (src/lib.rs)
use tdex::{compare, fmt};

/// Runs `work` on a pool of `threads` workers (results never depend on the count).
fn with_workers<R: Send>(
    threads: usize,
    work: impl FnOnce() -> anyhow::Result<R> + Send,
) -> anyhow::Result<R> {
    use anyhow::Context;
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .context("cannot start the worker threads")?
        .install(work)
}

fn main() -> ExitCode {
    // Under a file-size limit (`ulimit -f`) the kernel kills a process whose write passes it
    // (SIGXFSZ), leaving its temporary file behind; ignored, the write fails with EFBIG
    // instead, which tdex reports in plain words after removing the temporary file.
    // SAFETY: setting a signal's disposition to SIG_IGN before any thread starts.
    unsafe {
        libc::signal(libc::SIGXFSZ, libc::SIG_IGN);
    }
    // Rust ignores SIGPIPE, so `tdex inspect run.mcap | head` would panic on its next print
    // once `head` has gone; the default disposition ends tdex quietly there, as any Unix
    // tool. tdex writes no pipe of its own (files go to a temporary file and are renamed).
    // SAFETY: as above, before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let args = cli::Cli::parse_args();
    let result = cli::Plan::from_args(args).and_then(|plan| match plan {
        cli::Plan::Run(p) => run::run(&p),
        cli::Plan::Record(p) => record::run(p),
        cli::Plan::Inspect(p) => inspect::run(&p),
        cli::Plan::Bench(p) => bench::engine(&p),
        cli::Plan::BenchRecord(p) => bench::record(&p),
        cli::Plan::Pair(p) => pair::run(&p),
        cli::Plan::Extrapolate(p) => extrapolation::run(&p),
        cli::Plan::Compare(p) => compare_command::run(&p),
        cli::Plan::Report(p) => report::run(&p),
        cli::Plan::Demo(p) => demo::run(&p),
        cli::Plan::Study(p) => study::run(&p),
        cli::Plan::ImportLiggghts(p) => import::run(&p),
        cli::Plan::ExportVtk(p) => export::run(&p),
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            // the flags' own errors, or any library error that marks the input at fault
            let bad_input = |e: &(dyn std::error::Error + 'static)| {
                e.is::<cli::UsageError>() || tdex::fault_of(e) == Some(tdex_format::Fault::Input)
            };
            if err.chain().any(bad_input) {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}
