//! tdex's analysis layer, as a library: the comparison of an extrapolation (or a second DEM
//! run) with the DEM reference ([`compare`]), the flow of the bed at one instant ([`flow`])
//! and the number formatting of every human-readable line ([`fmt`]). The `tdex` binary
//! (`src/main.rs`) is the command line on top of it and of the `recorder`, `extrapolate`
//! and `tdex-format` crates (docs/architecture.md).

pub mod compare;
pub mod flow;
pub mod fmt;

/// Whose fault `error` is, if it is an error of any tdex library (the analyses here, the
/// recorder, the extrapolation, the file format): how the command line picks its exit code.
pub fn fault_of(error: &(dyn std::error::Error + 'static)) -> Option<tdex_format::Fault> {
    tdex_format::fault_as::<compare::CompareError>(error)
        .or_else(|| recorder::fault_of(error))
        .or_else(|| extrapolate::fault_of(error))
}
