//! Raw command-line flags (clap derive).

use clap::{Parser, Subcommand};
use std::path::PathBuf;

#[derive(Debug, Parser)]
#[command(
    name = "tdex",
    version,
    about = "Long-time thermal DEM: record one period, extrapolate many"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Run a case: insert, settle, spin up, assign temperatures at t0 and heat; print a summary.
    Run {
        /// The case file (TOML).
        case: PathBuf,
        /// Worker threads (default: all cores). Results do not depend on it.
        #[arg(long)]
        threads: Option<usize>,
        /// Print the summary as one JSON object on stdout.
        #[arg(long)]
        json: bool,
    },
}

impl Cli {
    pub fn parse_args() -> Self {
        Self::parse()
    }
}
