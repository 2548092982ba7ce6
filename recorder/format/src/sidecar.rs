//! The pairing sidecars (`RECORDING.pairing.json` and, for several recorded periods,
//! `RECORDING.pairing.t<end>-t<start>.json`, written by `tdex pair` and `tdex extrapolate`):
//! their contents and a reader that refuses any file that is not a pairing of the
//! recording's particles.

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The pairing summary (`tdex pair --json`; keys in docs/user-guide.md).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PairingSummary {
    pub particles: usize,
    pub diameter: f64,
    pub total_distance_diameters: f64,
    pub mean_distance_diameters: f64,
    pub k_used: usize,
    pub certified: bool,
    pub rounds: u32,
    /// Particle size classes (distinct radii) paired apart, a particle only taking the role
    /// of one of its own radius; absent for a bed of one size, where the whole bed is one
    /// class (and in sidecars written before sizes were kept apart, which a bed of several
    /// sizes therefore does not reuse).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub size_classes: Option<usize>,
    /// The period along the axis (m) of a section periodic along it, whose pair distances
    /// were taken across the seam; absent for a drum with end caps (and in sidecars
    /// written before periodic sections were paired across their seam, which such a
    /// section therefore does not reuse).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axial_period: Option<f64>,
    /// Wall time and worker threads of the solve; left out of a reproducible pairing
    /// (`tdex pair --reproducible`), the only fields that depend on the machine.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seconds: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub threads: Option<usize>,
}

impl PairingSummary {
    /// The summary without the machine-dependent fields (time, threads).
    pub fn reproducible(mut self) -> Self {
        self.seconds = None;
        self.threads = None;
        self
    }
}

/// The stored pairing: `g[p]` = the role particle `p` takes in the next period.
#[derive(Debug, Serialize, Deserialize)]
pub struct StoredPairing {
    /// Fingerprint of the snapshots it pairs (`extrapolate::cache::fingerprint`, a hash whose algorithm is fixed): reused only for
    /// the same positions.
    pub snapshots_fingerprint: u64,
    pub summary: PairingSummary,
    pub g: Vec<u32>,
}

/// Why a sidecar cannot be used; every message names the file.
#[derive(Debug, thiserror::Error)]
pub enum SidecarError {
    #[error("{path}: cannot read: {error}")]
    Read {
        path: PathBuf,
        error: std::io::Error,
    },
    #[error("{path}: not a tdex pairing file: {detail}")]
    Parse { path: PathBuf, detail: String },
    #[error("{path}: g has {found} entries for a recording of {particles} particles")]
    Length {
        path: PathBuf,
        found: usize,
        particles: usize,
    },
    #[error("{path}: g[{index}] = {value} is {why} (g must be a permutation of 0..{particles})")]
    NotPermutation {
        path: PathBuf,
        index: usize,
        value: u32,
        why: &'static str,
        particles: usize,
    },
}

impl crate::Classify for SidecarError {
    /// A sidecar that cannot be read or is not a pairing of the recording is bad input.
    fn fault(&self) -> crate::Fault {
        crate::Fault::Input
    }
}

/// The sidecar of the recording `recording`: its path with `.pairing.json` appended.
pub fn path_of(recording: &Path) -> PathBuf {
    let mut name = recording.as_os_str().to_owned();
    name.push(".pairing.json");
    PathBuf::from(name)
}

/// The sidecar of the pairing of snapshot `t_end` to `t_start` of the recording
/// `recording`: [`path_of`] for `t1` to `t0` (the only pairing of one recorded period, under
/// the name it has always had), else the path with `.pairing.t<end>-t<start>.json` appended.
pub fn path_between(recording: &Path, end: u32, start: u32) -> PathBuf {
    if (end, start) == (1, 0) {
        return path_of(recording);
    }
    let mut name = recording.as_os_str().to_owned();
    name.push(format!(".pairing.t{end}-t{start}.json"));
    PathBuf::from(name)
}

/// The sidecar of the pairing of snapshot `t_end` to the mirror image (`y → −y`) of
/// `t_start` ([`crate::extrapolation::Symmetry::AxialMirror`]): the path with
/// `.pairing.t<end>-mirror-t<start>.json` appended, apart from the plain pairings' names.
pub fn path_to_mirror_image(recording: &Path, end: u32, start: u32) -> PathBuf {
    let mut name = recording.as_os_str().to_owned();
    name.push(format!(".pairing.t{end}-mirror-t{start}.json"));
    PathBuf::from(name)
}

/// Reads the sidecar `path` of a recording of `particles` particles; `Ok(None)` if there is
/// no such file.
pub fn read(path: &Path, particles: usize) -> Result<Option<StoredPairing>, SidecarError> {
    match std::fs::read(path) {
        Ok(bytes) => parse(&bytes, path, particles).map(Some),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(error) => Err(SidecarError::Read {
            path: path.to_path_buf(),
            error,
        }),
    }
}

/// Parses a sidecar's bytes (`path` names it in messages) and checks that `g` is a
/// permutation of `0..particles`.
pub fn parse(bytes: &[u8], path: &Path, particles: usize) -> Result<StoredPairing, SidecarError> {
    let stored: StoredPairing = serde_json::from_slice(bytes).map_err(|e| SidecarError::Parse {
        path: path.to_path_buf(),
        detail: e.to_string(),
    })?;
    if stored.g.len() != particles {
        return Err(SidecarError::Length {
            path: path.to_path_buf(),
            found: stored.g.len(),
            particles,
        });
    }
    let mut seen = vec![false; particles];
    for (index, &value) in stored.g.iter().enumerate() {
        let why = if value as usize >= particles {
            "out of range"
        } else if std::mem::replace(&mut seen[value as usize], true) {
            "a repeat"
        } else {
            continue;
        };
        return Err(SidecarError::NotPermutation {
            path: path.to_path_buf(),
            index,
            value,
            why,
            particles,
        });
    }
    Ok(stored)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sidecar(g: &str) -> String {
        format!(
            r#"{{"snapshots_fingerprint":7,"summary":{{"particles":3,"diameter":0.01,
            "total_distance_diameters":1.0,"mean_distance_diameters":0.3,"k_used":3,
            "certified":true,"rounds":1,"seconds":0.0,"threads":1}},"g":{g}}}"#
        )
    }

    #[test]
    fn a_permutation_is_read_and_anything_else_refused_naming_the_file() {
        let p = Path::new("r.mcap.pairing.json");
        assert_eq!(
            parse(sidecar("[2,0,1]").as_bytes(), p, 3).unwrap().g,
            [2, 0, 1]
        );
        for (g, expect) in [
            ("[2,0]", "g has 2 entries for a recording of 3 particles"),
            ("[2,0,3]", "g[2] = 3 is out of range"),
            ("[2,0,2]", "g[2] = 2 is a repeat"),
            ("[2,0,-1]", "not a tdex pairing file"),
        ] {
            let e = parse(sidecar(g).as_bytes(), p, 3).unwrap_err().to_string();
            assert!(
                e.starts_with("r.mcap.pairing.json: ") && e.contains(expect),
                "{e}"
            );
        }
        assert_eq!(
            path_of(Path::new("a/r.mcap")),
            Path::new("a/r.mcap.pairing.json")
        );
        assert_eq!(
            path_between(Path::new("a/r.mcap"), 1, 0),
            Path::new("a/r.mcap.pairing.json")
        );
        assert_eq!(
            path_between(Path::new("a/r.mcap"), 3, 0),
            Path::new("a/r.mcap.pairing.t3-t0.json")
        );
    }
}
