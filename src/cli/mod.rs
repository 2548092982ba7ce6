//! Flags as parsed (`args`) and the validated plan built from them before any work (`plan`).

mod args;
mod plan;

pub use args::Cli;
pub use plan::{
    BenchRecordPlan, ExtrapolatePlan, InspectPlan, PairPlan, Plan, RecordPlan, RunPlan, UsageError,
};
