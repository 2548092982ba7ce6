//! End-to-end and physics tests, compiled into one binary. Run in release mode:
//! `cargo test --release --workspace`.

mod util;

mod cli_bench;
mod cli_boundary;
mod cli_case_errors;
mod cli_checkpoint;
mod cli_compare;
mod cli_draws;
mod cli_export;
mod cli_extrapolate;
mod cli_import;
mod cli_import_sizes;
mod cli_import_walls;
mod cli_inspect;
mod cli_outputs;
mod cli_record;
mod cli_recorded_periods;
mod cli_report;
mod cli_run;
mod cli_sizes;
mod cli_study;
mod drum;
mod fuzz_corpus;
mod golden_outputs;
mod physics_collision;
mod physics_conduction;
mod physics_periodic;
mod record;
mod replay;
