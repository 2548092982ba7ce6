//! The extrapolation file: the extrapolated snapshots at every `t_k`, in the recording's
//! conventions (`foxglove.PointCloud` on `/tdex/snapshots`, sequence = snapshot index), its
//! writer and its reader.

use super::mcap_file::{Bytes, McapFile};
use super::proto::POINT_CLOUD_DESCRIPTOR;
use super::writer::{
    abandon, close_into_place, log_time, open_partial, write_json_metadata, write_message,
    McapWriter,
};
use super::*;
use std::collections::BTreeMap;
use std::path::Path;

/// Metadata record written first: [`ExtrapolationInfo`] as JSON under `json`.
pub const EXTRAPOLATION_METADATA: &str = "tdex.extrapolation";
/// Metadata record written last: [`ExtrapolationCosts`] as JSON under `json`.
pub const EXTRAPOLATION_COSTS_METADATA: &str = "tdex.extrapolation_costs";

/// How an extrapolation was made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExtrapolationInfo {
    pub format_version: u32,
    pub tool_version: String,
    /// The recording replayed (path as given) and its own info.
    pub recording: String,
    pub recording_info: RecordingInfo,
    pub scheme: Scheme,
    pub periods: u32,
    /// How the roles went from one period to the next: the key `pairing` (one recorded
    /// period) or the key `path` (several), in place of the one field the files held before
    /// several recorded periods existed.
    #[serde(flatten)]
    pub roles: Roles,
    /// The drum's symmetry the replay used; absent (the files before it) for none.
    #[serde(default, skip_serializing_if = "Symmetry::is_none")]
    pub symmetry: Symmetry,
    /// With the axial mirror, each start's mirrored pairing beside its plain one: how far
    /// the trust in the mirror goes. Absent without the mirror (and in the files before it).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub mirror_check: Vec<MirrorCheck>,
    /// How the roles were handed over at the jumps; absent (the files before it) for the
    /// exact pairing.
    #[serde(default, skip_serializing_if = "Boundary::is_exact")]
    pub boundary: Boundary,
    /// With fresh boundary maps, each start's pool of pairings.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fresh_pools: Vec<FreshPool>,
}

/// How far the axial mirror's pairing of `t_end` to the mirrored `t_start` moves the
/// particles, beside the plain pairing of the same snapshots: a bed that is its own mirror
/// image gives about the same mean distance; a bed that leans along the axis a longer one,
/// and the mirror's jumps then move heat along the axis.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MirrorCheck {
    pub end: u32,
    pub start: u32,
    pub plain_mean_diameters: f64,
    pub mirrored_mean_diameters: f64,
}

impl MirrorCheck {
    /// The check of `t_end` paired to `t_start` plainly and to its mirror image, from the
    /// two pairings' summaries.
    pub fn of(
        end: u32,
        start: u32,
        plain: &super::sidecar::PairingSummary,
        mirrored: &super::sidecar::PairingSummary,
    ) -> Self {
        Self {
            end,
            start,
            plain_mean_diameters: plain.mean_distance_diameters,
            mirrored_mean_diameters: mirrored.mean_distance_diameters,
        }
    }

    /// The mirrored pairing's mean distance over the plain one's.
    pub fn ratio(&self) -> f64 {
        self.mirrored_mean_diameters / self.plain_mean_diameters.max(f64::MIN_POSITIVE)
    }
}

/// A symmetry of the drum an extrapolation uses to vary the periods it replays.
///
/// A tdex drum (axis `y` through the origin, end caps at `y = ±L/2` moving alike, gravity
/// `−z`, a mantle heated uniformly if at all) is its own mirror image in its mid-plane
/// `y = 0`, and the mirror keeps the sense of rotation (an angular velocity along `y`
/// is unchanged by `y → −y`). The mirror image of a recorded period is then a period of the
/// same flow as likely as the recorded one: the same contacts between the same particles,
/// at positions `(x, −y, z)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Symmetry {
    /// Every jump enters the recorded start itself: the paper's method.
    #[default]
    None,
    /// Every jump enters the mirror image of its start (`y → −y`), so that the periods
    /// replayed alternate between the recording and its mirror image at every jump: the
    /// pairings are of the end snapshot to the mirrored starts, and a period entered by an
    /// odd number of jumps is written with its positions and velocities mirrored.
    AxialMirror,
}

impl Symmetry {
    pub fn is_none(&self) -> bool {
        *self == Symmetry::None
    }

    /// `to` set to the image of the vectors `from` (positions or velocities) in a period
    /// entered `mirrored` or not: a copy, or with `y` negated, in one pass.
    pub fn copy_image(self, mirrored: bool, from: &[[f64; 3]], to: &mut [[f64; 3]]) {
        if self == Symmetry::AxialMirror && mirrored {
            for (to, &[x, y, z]) in to.iter_mut().zip(from) {
                *to = [x, -y, z];
            }
        } else {
            to.copy_from_slice(from);
        }
    }
}

/// How the roles are handed over at each jump of the replay (docs/method.md §6).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Boundary {
    /// One optimal pairing of the end to each start, the same at every jump: the paper's
    /// method.
    #[default]
    Exact,
    /// A pool of `pool` pairings per start, one drawn at each jump from `seed`, in each of
    /// which every particle's step along the axis over the period just replayed is redrawn,
    /// without replacement, among the particles ending in the same `cell_diameters`-wide cell
    /// of the cross-section.
    FreshSteps {
        pool: u32,
        cell_diameters: f64,
        seed: u64,
    },
    /// A pool of `pool` pairings per start, one drawn at each jump from `seed`, in each of
    /// which the period's coarse axial drift (bins of `bin_diameters` along the axis, cells of
    /// `cell_diameters` across) is moved along the axis by a random offset; the drift of the
    /// bins within `cap_zone_diameters` of an end cap is kept (0, and absent from files
    /// written without it: every bin's is moved).
    FreshDrift {
        pool: u32,
        bin_diameters: f64,
        cell_diameters: f64,
        #[serde(default, skip_serializing_if = "is_zero")]
        cap_zone_diameters: f64,
        seed: u64,
    },
}

/// A cap zone of none is left out of the file, as files written before it have it.
fn is_zero(diameters: &f64) -> bool {
    *diameters == 0.0
}

impl Boundary {
    pub fn is_exact(&self) -> bool {
        *self == Boundary::Exact
    }

    /// The seed fresh maps were drawn from (`None` for the exact map).
    pub fn seed(&self) -> Option<u64> {
        match self {
            Boundary::Exact => None,
            Boundary::FreshSteps { seed, .. } | Boundary::FreshDrift { seed, .. } => Some(*seed),
        }
    }
}

/// The pool of fresh pairings to one start: how far its pairings move the particles, in
/// particle diameters, beside the exact pairing of the same snapshots.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FreshPool {
    pub end: u32,
    pub start: u32,
    pub pairings: u32,
    /// The pool's mean over particles and pairings, and its smallest and largest pairing's.
    pub mean_distance_diameters: f64,
    pub min_mean_distance_diameters: f64,
    pub max_mean_distance_diameters: f64,
}

/// How an extrapolation moved the temperatures to their roles at the period boundaries.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Roles {
    /// One recorded period replayed through the pairing of `t1` (end) to `t0` (start): the
    /// paper's method. Its summary (see `tdex pair --json`) is written with its keys in
    /// alphabetical order, as the files have held it since the first version.
    #[serde(rename = "pairing", serialize_with = "keys_sorted")]
    Pairing(PairingSummary),
    /// Several recorded periods replayed along a recurrence path (docs/method.md §6).
    #[serde(rename = "path")]
    Path(RecurrencePath),
}

impl Roles {
    /// Wall seconds the pairings used took to compute, as stored (`None` when none carries
    /// a time: a reproducible extrapolation, or a path that needed no pairing).
    pub fn pairing_seconds(&self) -> Option<f64> {
        match self {
            Roles::Pairing(p) => p.seconds,
            Roles::Path(path) => path
                .pairings
                .iter()
                .filter_map(|p| p.summary.seconds)
                .reduce(|a, b| a + b),
        }
    }

    /// The first extrapolated period (1-based) entered through a pairing: 1 for the
    /// paper's method; along a recurrence path the first jump (the periods before it are
    /// the recording's own continuation from `t1`, so the snapshots up to it are the
    /// recorded run's); `None` for a path that never jumped.
    pub fn first_jump(&self) -> Option<usize> {
        match self {
            Roles::Pairing(_) => Some(1),
            Roles::Path(path) => path.entered_by_jump().position(|jump| jump).map(|k| k + 1),
        }
    }

    /// The recorded periods the extrapolation replayed, `P'` (1 through a pairing).
    pub fn recorded_periods_used(&self) -> u32 {
        match self {
            Roles::Pairing(_) => 1,
            Roles::Path(path) => path.recorded_periods,
        }
    }
}

/// The recurrence path an extrapolation of several recorded periods followed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecurrencePath {
    /// Recorded periods used, `P'` (the first `P'` of the recording's; at least 2).
    pub recorded_periods: u32,
    /// Seed of the jumps' generator (xoshiro256++ seeded with `seed_from_u64`).
    pub seed: u64,
    /// The periods a jump could enter when the user restricted them (`--jump-to`); absent:
    /// every recorded period used.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub jump_targets: Option<Vec<u32>>,
    /// The path left the recording after every `n` periods replayed in a row, from the end
    /// of the period just replayed (`--jump-every`); absent: at the recording's end only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub leave_every: Option<u32>,
    /// The recorded period (1-based) replayed at each extrapolated period `k = 1 … K`.
    pub replayed: Vec<u32>,
    /// The pairing of each jump the path made, by end and start: snapshot `t_end` (`end` =
    /// `P'`, or with `leave_every` the end of the period the jump left) paired to `t_start`
    /// (`start` = `m − 1` for a jump to period `m`).
    pub pairings: Vec<PathPairing>,
}

impl RecurrencePath {
    /// Whether each extrapolated period was entered through a pairing (a jump) rather than
    /// as the recording's own continuation of the period before (`t1` ends period 1).
    fn entered_by_jump(&self) -> impl Iterator<Item = bool> + '_ {
        self.replayed.iter().scan(1u32, |previous, &p| {
            let jump = p != *previous + 1;
            *previous = p;
            Some(jump)
        })
    }

    /// Jumps made (extrapolated periods entered through a pairing).
    pub fn jumps(&self) -> usize {
        self.entered_by_jump().filter(|&jump| jump).count()
    }

    /// Mean length, in periods, of the stretches replayed without a pairing (each starts
    /// at `t1` or at a jump); 0 for no period.
    pub fn mean_run(&self) -> f64 {
        let stretches = self
            .entered_by_jump()
            .enumerate()
            .filter(|&(k, jump)| jump || k == 0)
            .count();
        self.replayed.len() as f64 / stretches.max(1) as f64
    }
}

/// One pairing a recurrence path used.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PathPairing {
    /// Snapshot index of the end (`t_end`) and of the start (`t_start`) it pairs.
    pub end: u32,
    pub start: u32,
    pub summary: PairingSummary,
}

/// Serialises `value` as a JSON object with its keys sorted (serde_json's map without
/// `preserve_order`).
fn keys_sorted<S: serde::Serializer>(
    value: &PairingSummary,
    serializer: S,
) -> Result<S::Ok, S::Error> {
    serde_json::to_value(value)
        .map_err(serde::ser::Error::custom)?
        .serialize(serializer)
}

/// What the extrapolation cost.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExtrapolationCosts {
    pub seconds_pairing: f64,
    pub pairing_reused: bool,
    pub seconds_read_table: f64,
    pub seconds_replay: f64,
    pub seconds_per_period: f64,
    pub rows_per_second: f64,
    pub rows: u64,
}

pub struct ExtrapolationWriter {
    mcap: Option<McapWriter>,
    dest: PathBuf,
    channel: u16,
}

impl ExtrapolationWriter {
    pub fn create(dest: &Path, info: &ExtrapolationInfo) -> Result<Self, FormatError> {
        let mut mcap = open_partial(dest)?;
        let mcap_err = |e| FormatError::writing(dest, e);
        write_json_metadata(&mut mcap, EXTRAPOLATION_METADATA, info).map_err(mcap_err)?;
        let schema = mcap
            .add_schema("foxglove.PointCloud", "protobuf", POINT_CLOUD_DESCRIPTOR)
            .map_err(mcap_err)?;
        let channel = mcap
            .add_channel(schema, SNAPSHOT_TOPIC, "protobuf", &BTreeMap::new())
            .map_err(mcap_err)?;
        Ok(Self {
            mcap: Some(mcap),
            dest: dest.to_path_buf(),
            channel,
        })
    }

    pub fn write_snapshot(&mut self, snapshot: &Snapshot) -> Result<(), FormatError> {
        let mcap = self.mcap.as_mut().expect("not finished");
        let result = write_message(
            mcap,
            self.channel,
            snapshot.index,
            log_time(snapshot.time),
            &snapshot.encode(),
        );
        result.map_err(|e| FormatError::writing(&self.dest, e))
    }

    /// Closes the file into place; `costs` is `None` for a reproducible extrapolation
    /// (`tdex extrapolate --reproducible`), whose bytes then depend on nothing but its inputs.
    pub fn finish(mut self, costs: Option<&ExtrapolationCosts>) -> Result<(), FormatError> {
        let mut mcap = self.mcap.take().expect("finished once");
        if let Some(costs) = costs {
            if let Err(e) = write_json_metadata(&mut mcap, EXTRAPOLATION_COSTS_METADATA, costs) {
                abandon(mcap);
                return Err(FormatError::writing(&self.dest, e));
            }
        }
        close_into_place(mcap, &self.dest)
    }
}

impl Drop for ExtrapolationWriter {
    /// An unfinished file is removed, never left looking complete.
    fn drop(&mut self) {
        if let Some(mcap) = self.mcap.take() {
            abandon(mcap);
        }
    }
}

/// An open extrapolation file.
pub struct ExtrapolationReader {
    file: McapFile,
    info: ExtrapolationInfo,
    costs: Option<ExtrapolationCosts>,
    snapshot_channel: u16,
}

impl std::fmt::Debug for ExtrapolationReader {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ExtrapolationReader")
            .field("path", &self.file.path)
            .finish_non_exhaustive()
    }
}

impl ExtrapolationReader {
    /// Opens `path` and checks that it is a complete tdex extrapolation of a known version.
    pub fn open(path: &Path) -> Result<Self, FormatError> {
        Self::checked(McapFile::open(path, "extrapolation")?)
    }

    /// [`ExtrapolationReader::open`] on the file's bytes already in memory; `path` names the
    /// file in messages.
    pub fn from_bytes(path: &Path, bytes: Vec<u8>) -> Result<Self, FormatError> {
        Self::checked(McapFile::from_bytes(
            path,
            Bytes::Owned(bytes),
            "extrapolation",
        )?)
    }

    fn checked(file: McapFile) -> Result<Self, FormatError> {
        let info: ExtrapolationInfo = file.metadata(EXTRAPOLATION_METADATA)?.ok_or_else(|| {
            file.not_ours(format!(
                "it has no '{EXTRAPOLATION_METADATA}' metadata record"
            ))
        })?;
        if info.format_version != FORMAT_VERSION {
            return Err(file.not_ours(format!(
                "format version {} (this tdex reads version {FORMAT_VERSION})",
                info.format_version
            )));
        }
        info.recording_info.check().map_err(|e| {
            file.corrupt(format!(
                "metadata '{EXTRAPOLATION_METADATA}': recording_info: {e}"
            ))
        })?;
        let costs = file.metadata(EXTRAPOLATION_COSTS_METADATA)?;
        let snapshot_channel = file.channel(SNAPSHOT_TOPIC, "foxglove.PointCloud")?;
        Ok(Self {
            file,
            info,
            costs,
            snapshot_channel,
        })
    }

    pub fn path(&self) -> &Path {
        &self.file.path
    }

    pub fn info(&self) -> &ExtrapolationInfo {
        &self.info
    }

    /// What the extrapolation cost (absent in a reproducible extrapolation).
    pub fn costs(&self) -> Option<&ExtrapolationCosts> {
        self.costs.as_ref()
    }

    /// All snapshots by index (1: the DEM state at `t1`, `k`: extrapolated `t_k`). Point
    /// `j` is role `j` (at the position of particle `j` at `t1`); its `id` is the physical
    /// particle playing the role at that instant, so `id` is a permutation of `0..N`. Holds
    /// every snapshot in memory: [`ExtrapolationReader::snapshots_in_order`] streams them.
    pub fn snapshots(&self) -> Result<Vec<Snapshot>, FormatError> {
        let mut snaps = Vec::new();
        for m in self.file.messages_at(self.snapshot_channel, None) {
            let (index, data) = m?;
            snaps.push(self.decode_checked(index, &data)?);
        }
        snaps.sort_by_key(|s| s.index);
        if let Some(w) = snaps.windows(2).find(|w| w[0].index == w[1].index) {
            return Err(self
                .file
                .corrupt(format!("snapshot {} stored twice", w[0].index)));
        }
        Ok(snaps)
    }

    /// The snapshots one at a time in file order, which `tdex extrapolate` writes by index;
    /// memory holds one chunk and one snapshot, whatever the number of periods. A snapshot
    /// whose index does not follow the one before it is reported as damage.
    pub fn snapshots_in_order(&self) -> impl Iterator<Item = Result<Snapshot, FormatError>> + '_ {
        let mut last: Option<u32> = None;
        self.file
            .messages_at(self.snapshot_channel, None)
            .map(move |m| {
                let (index, data) = m?;
                if last.is_some_and(|l| index <= l) {
                    return Err(self.file.corrupt(format!(
                        "snapshot {index} stored after snapshot {} (snapshots are stored by \
                         increasing index)",
                        last.unwrap_or_default()
                    )));
                }
                last = Some(index);
                self.decode_checked(index, &data)
            })
    }

    /// Snapshots stored (from the file's statistics, nothing decoded).
    pub fn snapshot_count(&self) -> usize {
        self.file
            .summary
            .stats
            .as_ref()
            .and_then(|st| st.channel_message_counts.get(&self.snapshot_channel))
            .map_or(0, |&n| n as usize)
    }

    /// Decodes a stored snapshot and checks it holds every particle once.
    fn decode_checked(&self, index: u32, data: &[u8]) -> Result<Snapshot, FormatError> {
        let n = self.info.recording_info.particles as usize;
        let snap = Snapshot::decode(index, data).map_err(|e| self.file.corrupt(e))?;
        if snap.len() != n {
            return Err(self.file.corrupt(format!(
                "snapshot {index}: {} points for {n} particles",
                snap.len()
            )));
        }
        let mut seen = vec![false; n];
        for (j, &id) in snap.id.iter().enumerate() {
            if id as usize >= n || std::mem::replace(&mut seen[id as usize], true) {
                return Err(self.file.corrupt(format!(
                    "snapshot {index}: point {j} has id {id}, a repeat or out of 0..{n} \
                     (ids must be a permutation)"
                )));
            }
        }
        Ok(snap)
    }
}

#[cfg(test)]
mod tests {
    use super::{RecurrencePath, Roles, Symmetry};

    /// The snapshots before the first jump are the recorded run's own: the path leaves the
    /// recording at its first period entered through a pairing.
    #[test]
    fn a_path_leaves_the_recording_at_its_first_jump() {
        let path = |replayed: Vec<u32>| {
            Roles::Path(RecurrencePath {
                recorded_periods: 3,
                seed: 0,
                jump_targets: None,
                leave_every: None,
                replayed,
                pairings: Vec::new(),
            })
        };
        // from t1, periods 2 and 3 follow the recording; the fourth period jumps
        assert_eq!(path(vec![2, 3, 1, 2]).first_jump(), Some(3));
        assert_eq!(path(vec![2, 2, 3]).first_jump(), Some(2));
        // period 1 again right after t1 is a jump (through the pairing of t1 to t0)
        assert_eq!(path(vec![1, 2, 3]).first_jump(), Some(1));
        assert_eq!(path(vec![2, 3]).first_jump(), None);
    }

    #[test]
    fn the_mirror_image_negates_y_and_nothing_else() {
        let from = [[1.0, 2.0, 3.0], [-4.0, -5.0, 6.0]];
        let mut to = [[0.0; 3]; 2];
        Symmetry::AxialMirror.copy_image(true, &from, &mut to);
        assert_eq!(to, [[1.0, -2.0, 3.0], [-4.0, 5.0, 6.0]]);
        // a period entered without the mirror, or no symmetry at all: a copy
        for (symmetry, mirrored) in [(Symmetry::AxialMirror, false), (Symmetry::None, true)] {
            symmetry.copy_image(mirrored, &from, &mut to);
            assert_eq!(to, from);
        }
    }
}
