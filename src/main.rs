//! tdex command line: parse flags, validate them into a plan before any work, run, and map
//! errors to an exit code (2: bad input, 1: the run failed).

mod cli;
mod run;

use std::process::ExitCode;

fn main() -> ExitCode {
    let args = cli::Cli::parse_args();
    let result = cli::Plan::from_args(args).and_then(|plan| match plan {
        cli::Plan::Run(p) => run::run(&p),
    });
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("error: {err:#}");
            if err
                .chain()
                .any(|e| e.is::<recorder::CaseError>() || e.is::<cli::UsageError>())
            {
                ExitCode::from(2)
            } else {
                ExitCode::from(1)
            }
        }
    }
}
