//! Flags as parsed (`args`) and the validated plan built from them before any work (`plan`).

mod args;
mod plan;
mod values;

pub use args::Cli;
pub use args::SamplingFlags;
pub(crate) use plan::record_options;
pub use plan::{
    BenchPlan, BenchRecordPlan, ComparePlan, DemoPlan, ExportVtkPlan, ExtrapolatePlan,
    HorizonSource, ImportPlan, InspectPlan, PairPlan, Plan, RecordPlan, RecordStart, RegimeRun,
    ReportPlan, RunPlan, StudyKind, StudyPlan, Tau, UsageError,
};
