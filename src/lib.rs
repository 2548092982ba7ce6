//! tdex's analysis layer, as a library: the comparison of an extrapolation (or a second DEM
//! run) with the DEM reference ([`compare`]), the flow of the bed at one instant ([`flow`])
//! and the number formatting of every human-readable line ([`fmt`]). The `tdex` binary
//! (`src/main.rs`) is the command line on top of it and of the `recorder`, `extrapolate`
//! and `tdex-format` crates (docs/architecture.md).

pub mod compare;
pub mod flow;
pub mod fmt;
