//! Case files: the TOML schema, loading with errors that name the file and field, and validation.

mod schema;
mod sizes;
mod validate;

pub use schema::*;
pub use sizes::{SizeClasses, FRACTION_SUM_TOLERANCE, MAX_SIZE_CLASSES};
pub use validate::{rayleigh_time, validate, MAX_FILL_FRACTION, MAX_RAYLEIGH_FRACTION};

use std::path::{Path, PathBuf};

/// Why a case file was refused. Every message names the file; `Invalid` also names the
/// field, the offending value and what is allowed.
#[derive(Debug, thiserror::Error)]
pub enum CaseError {
    /// The I/O error is in the message and not also the error's `source()` (a chain
    /// printed with `{:#}` would say it twice).
    #[error("cannot read case file {}: {error}", path.display())]
    Read {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{}: not a valid case file: {message}", path.display())]
    Parse { path: PathBuf, message: String },
    #[error("{}: {field} = {value} is not allowed: {limit}", path.display())]
    Invalid {
        path: PathBuf,
        field: String,
        value: String,
        limit: String,
    },
}

impl tdex_format::Classify for CaseError {
    /// A case that cannot be read or is refused is always the input's fault.
    fn fault(&self) -> tdex_format::Fault {
        tdex_format::Fault::Input
    }
}

/// Reads, parses and validates a case file.
pub fn load(path: &Path) -> Result<Case, CaseError> {
    load_with_text(path).map(|(case, _)| case)
}

/// [`load`], also returning the file's text as given (a recording stores it).
pub fn load_with_text(path: &Path) -> Result<(Case, String), CaseError> {
    let bytes = std::fs::read(path).map_err(|error| CaseError::Read {
        path: path.to_path_buf(),
        error,
    })?;
    parse_bytes(&bytes, path)
}

/// [`parse`] of a case file's bytes, which must be UTF-8 text; also returns the text.
pub fn parse_bytes(bytes: &[u8], path: &Path) -> Result<(Case, String), CaseError> {
    let text = std::str::from_utf8(bytes).map_err(|e| CaseError::Parse {
        path: path.to_path_buf(),
        message: format!(
            "not UTF-8 text: byte {:#04x} at offset {} (line {}) is not valid UTF-8",
            bytes[e.valid_up_to()],
            e.valid_up_to(),
            1 + bytes[..e.valid_up_to()]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
        ),
    })?;
    Ok((parse(text, path)?, text.to_string()))
}

/// Parses and validates case text; `path` is only used in messages.
pub fn parse(text: &str, path: &Path) -> Result<Case, CaseError> {
    let case: Case = toml::from_str(text).map_err(|e| CaseError::Parse {
        path: path.to_path_buf(),
        message: e.to_string().trim_end().to_string(),
    })?;
    validate(&case).map_err(|v| CaseError::Invalid {
        path: path.to_path_buf(),
        field: v.field,
        value: v.value,
        limit: v.limit,
    })?;
    Ok(case)
}

impl Case {
    /// Heating time of `tdex run`: the case's, or one revolution.
    pub fn heating_time(&self) -> f64 {
        self.time.heating.unwrap_or(self.drum.rotation_period)
    }

    /// Drum angular velocity (rad/s) about +y.
    pub fn angular_velocity(&self) -> f64 {
        2.0 * std::f64::consts::PI / self.drum.rotation_period
    }

    /// Number of DEM steps in `seconds`, rounded to the nearest step.
    pub fn steps_in(&self, seconds: f64) -> u64 {
        (seconds / self.time.dt).round() as u64
    }
}
