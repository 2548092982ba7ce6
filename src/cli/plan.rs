//! Validated plans: every flag and the case file are checked here, before any simulation starts.

use super::args::{Cli, Command};
use anyhow::Result;
use recorder::Case;
use std::path::PathBuf;

/// A flag value outside its allowed range.
#[derive(Debug)]
pub struct UsageError(pub String);

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for UsageError {}

pub enum Plan {
    Run(RunPlan),
}

pub struct RunPlan {
    pub case_path: PathBuf,
    pub case: Case,
    pub threads: usize,
    pub json: bool,
}

fn threads(requested: Option<usize>) -> Result<usize> {
    match requested {
        Some(0) => Err(UsageError("--threads = 0 is not allowed: give at least 1".into()).into()),
        Some(n) => Ok(n),
        None => Ok(std::thread::available_parallelism().map_or(1, |n| n.get())),
    }
}

impl Plan {
    pub fn from_args(cli: Cli) -> Result<Self> {
        match cli.command {
            Command::Run {
                case,
                threads: t,
                json,
            } => {
                let threads = threads(t)?;
                let loaded = recorder::case::load(&case)?;
                Ok(Plan::Run(RunPlan {
                    case_path: case,
                    case: loaded,
                    threads,
                    json,
                }))
            }
        }
    }
}
