//! `tdex record --checkpoint-every` / `--resume`: a run killed with SIGKILL after a
//! checkpoint, in any stage, resumes to the recording an uninterrupted run writes, byte for
//! byte; damaged checkpoints and journals are refused with a clear error.

use crate::cli_run::TINY_CASE;
use crate::util::{costs_record_offset, file_names, run_tdex, tdex};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// The tiny case grown to 600 particles in a wider, longer, heated drum turning once a
/// second: 2 000 settling, 1 000 spin-up steps, then the period.
fn case_text() -> String {
    let mut text = TINY_CASE.to_string();
    for (from, to) in [
        ("name = \"tiny\"", "name = \"checkpointed\""),
        ("count = 250", "count = 600"),
        ("radius = 0.05", "radius = 0.06"),
        ("length = 0.06", "length = 0.1"),
        (
            "rotation_period = 2.0",
            "rotation_period = 1.0\nwall_temperature = 350.0",
        ),
    ] {
        assert!(text.contains(from), "{from} not in the tiny case");
        text = text.replacen(from, to, 1);
    }
    text
}

/// τ = 0.6 s (6 000 steps) and two reference periods.
const TABLE: [&str; 4] = ["--tau", "0.6", "--reference", "2"];

fn setup(dir: &Path) -> PathBuf {
    let case = dir.join("case.toml");
    std::fs::write(&case, case_text()).unwrap();
    case
}

pub(crate) fn checkpoint_of(out: &Path) -> PathBuf {
    PathBuf::from(format!("{}.checkpoint", out.display()))
}

fn record_args<'a>(case: &'a Path, out: &'a Path, extra: &[&'a str]) -> Vec<&'a str> {
    let mut args = vec![
        "record",
        case.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
    ];
    args.extend(TABLE);
    args.extend(extra);
    args
}

pub(crate) fn spawn(args: &[&str]) -> Child {
    Command::new(tdex())
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("tdex starts")
}

/// Waits until the checkpoint's first line says the run is at `stage` (e.g. "period step"),
/// then kills the run with SIGKILL. Fails if the run ends first.
pub(crate) fn kill_at(child: Child, checkpoint: &Path, stage: &str) -> String {
    kill_when(child, checkpoint, stage, |line| line.contains(stage))
}

/// The step a checkpoint's first line states (`... step K of ...`).
fn step_of(line: &str) -> u64 {
    let after = line.rsplit_once(" step ").expect("a step").1;
    after.split(' ').next().unwrap().parse().unwrap()
}

/// Kills the run with SIGKILL once the checkpoint's first line satisfies `ready`.
fn kill_when(
    mut child: Child,
    checkpoint: &Path,
    stage: &str,
    ready: impl Fn(&str) -> bool,
) -> String {
    let start = Instant::now();
    loop {
        if let Ok(bytes) = std::fs::read(checkpoint) {
            let line = String::from_utf8_lossy(&bytes[..bytes.len().min(300)])
                .lines()
                .next()
                .unwrap_or("")
                .to_string();
            if ready(&line) {
                child.kill().unwrap(); // SIGKILL
                child.wait().unwrap();
                return line;
            }
        }
        if let Some(status) = child.try_wait().unwrap() {
            let mut err = String::new();
            use std::io::Read;
            child
                .stderr
                .take()
                .unwrap()
                .read_to_string(&mut err)
                .unwrap();
            panic!("the run ended ({status}) before a checkpoint at '{stage}': {err}");
        }
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "no checkpoint at '{stage}' after 300 s"
        );
        std::thread::sleep(Duration::from_millis(2));
    }
}

/// Resumes the run of checkpoint `ck_arg` to its end and asserts that the recording `b` it
/// writes is `a`, the uninterrupted run's, byte for byte (`stops`: where it was killed).
pub(crate) fn resume_to_the_end(ck_arg: &str, a: &Path, b: &Path, stops: &[String]) {
    let o = run_tdex(&["record", "--resume", ck_arg]);
    assert!(
        o.status.success(),
        "stops: {stops:#?}\n{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let (a_bytes, b_bytes) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    assert_eq!(a_bytes.len(), b_bytes.len(), "stops: {stops:#?}");
    assert!(
        a_bytes == b_bytes,
        "the resumed recording differs; stops: {stops:#?}"
    );
}

#[test]
fn a_recording_killed_in_every_stage_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    let o = run_tdex(&record_args(
        &case,
        &a,
        &["--reproducible", "--threads", "2"],
    ));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let ck = checkpoint_of(&b);
    let ck_arg = ck.to_str().unwrap().to_string();
    let every = ["--checkpoint-every", "0.02"];
    let first = spawn(&record_args(
        &case,
        &b,
        &["--reproducible", "--threads", "2", every[0], every[1]],
    ));
    let mut stops = vec![kill_at(first, &ck, "settle step")];
    for (stage, threads) in [("period step", "1"), ("reference period 2 of 2", "2")] {
        assert!(!b.exists(), "a killed run left {}", b.display());
        let resumed = spawn(&["record", "--resume", &ck_arg, "--threads", threads]);
        stops.push(kill_at(resumed, &ck, stage));
    }
    assert!(!b.exists(), "a killed run left {}", b.display());
    resume_to_the_end(&ck_arg, &a, &b, &stops);
    // the checkpoint, its journal and the killed runs' partial files are gone
    assert_eq!(file_names(dir.path()), ["a.mcap", "b.mcap", "case.toml"]);
}

#[test]
fn a_resumed_recording_with_costs_equals_an_uninterrupted_one_up_to_its_costs() {
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    let o = run_tdex(&record_args(&case, &a, &[]));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let ck = checkpoint_of(&b);
    let run = spawn(&record_args(&case, &b, &["--checkpoint-every", "0.02"]));
    kill_at(run, &ck, "period step");
    let o = run_tdex(&["record", "--resume", ck.to_str().unwrap(), "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(report["costs_recorded"], true);
    assert!(report["seconds_period"].as_f64().unwrap() > 0.0);

    let (a, b) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    let (ca, cb) = (costs_record_offset(&a), costs_record_offset(&b));
    assert_eq!(ca, cb, "the costs record starts at different offsets");
    assert!(
        a[..ca] == b[..cb],
        "recordings differ before the costs record"
    );
}

#[test]
fn damaged_checkpoints_and_journals_are_refused_with_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let out = dir.path().join("c.mcap");
    let ck = checkpoint_of(&out);
    let run = spawn(&record_args(&case, &out, &["--checkpoint-every", "0.02"]));
    // far enough into the period that rows have been released to the journal
    kill_when(run, &ck, "period step ≥ 1000", |l| {
        l.contains("period step") && step_of(l) >= 1000
    });
    let good = std::fs::read(&ck).unwrap();
    let journal = PathBuf::from(format!("{}.rows", ck.display()));
    let good_journal = std::fs::read(&journal).unwrap();
    assert!(!good_journal.is_empty());

    let refused = |expect: &str| {
        let o = run_tdex(&["record", "--resume", ck.to_str().unwrap()]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{expect}: {err}");
        assert!(err.contains(expect), "expected '{expect}' in: {err}");
        assert!(!out.exists());
    };
    let header_end = good.iter().position(|&b| b == b'\n').unwrap() + 1;
    let mut flipped = good.clone();
    flipped[header_end + 12 + 1000] ^= 0x10;
    std::fs::write(&ck, &flipped).unwrap();
    refused("damaged checkpoint: CRC-32");
    std::fs::write(&ck, &good[..good.len() - 100]).unwrap();
    refused("cut short");
    std::fs::write(&ck, b"name = \"not a checkpoint\"\n").unwrap();
    refused("not a tdex checkpoint");
    let version = format!(
        "checkpoint v{}",
        recorder::record::checkpoint::CHECKPOINT_VERSION
    );
    std::fs::write(
        &ck,
        good.replacen_bytes(version.as_bytes(), b"checkpoint v9"),
    )
    .unwrap();
    refused("checkpoint format v9");

    std::fs::write(&ck, &good).unwrap();
    std::fs::write(&journal, &good_journal[..good_journal.len() / 2]).unwrap();
    refused("the row journal holds");
    let mut damaged = good_journal.clone();
    damaged[10] ^= 1;
    std::fs::write(&journal, &damaged).unwrap();
    refused("do not match the checkpoint");

    // flags that belong to the recording cannot change on resume; the interval must be > 0
    let o = run_tdex(&["record", "--resume", ck.to_str().unwrap(), "--n", "5"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("cannot be used with"));
    let o = run_tdex(&record_args(&case, &out, &["--checkpoint-every", "0"]));
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("--checkpoint-every = 0 is not allowed"));

    // the intact pair still resumes
    std::fs::write(&journal, &good_journal).unwrap();
    let o = run_tdex(&["record", "--resume", ck.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.exists() && !ck.exists() && !journal.exists());
}

trait ReplaceBytes {
    fn replacen_bytes(&self, from: &[u8], to: &[u8]) -> Vec<u8>;
}

impl ReplaceBytes for Vec<u8> {
    /// The bytes with the first occurrence of `from` replaced by `to` (same length).
    fn replacen_bytes(&self, from: &[u8], to: &[u8]) -> Vec<u8> {
        let at = self.windows(from.len()).position(|w| w == from).unwrap();
        let mut out = self.clone();
        out[at..at + to.len()].copy_from_slice(to);
        out
    }
}

/// A checkpoint whose body was changed and whose CRC was made to match again (what a
/// hand-edited or maliciously written file looks like) is refused or resumed, never a
/// panic: 3 000 single-bit flips over the body, each read, checked against its case,
/// and, when accepted, stepped and sampled.
#[test]
fn checkpoints_with_a_valid_crc_but_altered_state_never_panic() {
    use recorder::record::{Checkpoint, Stage};
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let out = dir.path().join("m.mcap");
    let ck = checkpoint_of(&out);
    let run = spawn(&record_args(&case, &out, &["--checkpoint-every", "0.02"]));
    kill_when(run, &ck, "period step ≥ 600", |l| {
        l.contains("period step") && step_of(l) >= 600
    });
    let good = std::fs::read(&ck).unwrap();
    let body_at = good.iter().position(|&b| b == b'\n').unwrap() + 1 + 12;
    let body_len = good.len() - body_at;
    let altered = dir.path().join("altered.checkpoint");
    let (mut seed, mut refused, mut resumed) = (0x9e37_79b9_7f4a_7c15u64, 0, 0);
    for _ in 0..3000 {
        // xorshift: a fixed sequence of positions, so a failure can be replayed
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        let (byte, bit) = ((seed >> 8) as usize % body_len, seed % 8);
        let mut bytes = good.clone();
        bytes[body_at + byte] ^= 1 << bit;
        let crc = crc32fast::hash(&bytes[body_at..]);
        bytes[body_at - 4..body_at].copy_from_slice(&crc.to_le_bytes());
        std::fs::write(&altered, &bytes).unwrap();
        let outcome = std::panic::catch_unwind(|| -> Result<(), String> {
            let c = Checkpoint::read(&altered).map_err(|e| e.to_string())?;
            let case = c.case(&altered).map_err(|e| e.to_string())?;
            let restored = c.restore(&case, &altered).map_err(|e| e.to_string())?;
            let (mut sim, stage, output) = (restored.sim, restored.stage, restored.output);
            for _ in 0..20 {
                sim.step();
            }
            if let (Stage::Period { done, .. }, Some(out)) = (stage, output) {
                let mut sampler = out.sampler.into_owned();
                let every = sampler.every as u64;
                for k in 0..3 {
                    sampler.sample(done + k * every, sim.touching_pairs().collect::<Vec<_>>());
                    sampler.drain_ready();
                }
                sampler.finish();
            }
            Ok(())
        });
        match outcome {
            Ok(Ok(())) => resumed += 1,
            Ok(Err(message)) => {
                assert!(message.contains("altered.checkpoint"), "{message}");
                refused += 1;
            }
            Err(_) => panic!("flipping bit {bit} of body byte {byte} makes the reader panic"),
        }
    }
    eprintln!(
        "altered checkpoints: {refused} refused, {resumed} accepted (values changed within range)"
    );
    assert!(refused > 0);
}

#[test]
fn a_recording_with_twins_killed_in_its_reference_and_twin_stages_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    let twins = ["--twins", "2", "--reproducible", "--threads", "2"];
    let o = run_tdex(&record_args(&case, &a, &twins));
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));

    let ck = checkpoint_of(&b);
    let ck_arg = ck.to_str().unwrap().to_string();
    let mut args = record_args(&case, &b, &twins);
    args.extend(["--checkpoint-every", "0.02"]);
    // the header names the stage after the case: ", reference period 2 of 2 step" is the
    // run's own, ", twin 1 of 2 reference period ..." a twin's
    let mut stops = vec![kill_at(spawn(&args), &ck, ", reference period 2 of 2")];
    for stage in [
        ", twin 1 of 2 reference period 2",
        ", twin 2 of 2 reference period 1",
    ] {
        assert!(!b.exists(), "a killed run left {}", b.display());
        let resumed = spawn(&["record", "--resume", &ck_arg, "--threads", "1"]);
        stops.push(kill_at(resumed, &ck, stage));
    }
    resume_to_the_end(&ck_arg, &a, &b, &stops);
    // both twins are stored, differ from the DEM and from each other
    let rec = tdex_format::RecordingReader::open(&a).unwrap();
    let twins = rec.twin_snapshots().unwrap();
    let dem = rec.snapshots().unwrap();
    assert_eq!(twins.len(), 2);
    for (m, twin) in twins.iter().enumerate() {
        assert_eq!(twin.iter().map(|s| s.index).collect::<Vec<_>>(), [2, 3]);
        assert_ne!(twin[0].pos, dem[2].pos, "twin {} is the DEM", m + 1);
    }
    assert_ne!(
        twins[0][0].pos, twins[1][0].pos,
        "the two twins are one run"
    );
    assert_eq!(file_names(dir.path()), ["a.mcap", "b.mcap", "case.toml"]);
}

/// Twins that part at t2 (`--twins-from 2`, two recorded periods): killed in the recorded
/// period before the state at t2 is kept, in the run's reference period and in each twin's,
/// the run resumes to the same bytes; each twin holds the run's own t2 and parts after it.
#[test]
fn twins_parting_at_t2_resume_to_the_same_bytes_and_hold_the_runs_t2() {
    let dir = tempfile::tempdir().unwrap();
    let case = setup(dir.path());
    let (a, b) = (dir.path().join("a.mcap"), dir.path().join("b.mcap"));
    let flags = [
        "--recorded-periods",
        "2",
        "--twins",
        "2",
        "--twins-from",
        "2",
        "--reproducible",
        "--threads",
        "2",
    ];
    let o = run_tdex(&record_args(&case, &a, &flags));
    let log = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{log}");
    // stderr is a pipe here, as in a background run: plain progress lines, each twin's
    // starting where it parts (t2 of a phase that counts the reference periods from t1)
    for line in [
        "] settle: 2000 steps",
        "] settle: done, 2000 steps in ",
        "] record: 12000 steps",
        "] reference: done, 12000 steps in ",
        "] twin 1: 12000 steps, from 50 %",
        "] twin 2: done, 12000 steps in ",
    ] {
        assert!(log.contains(line), "{line} not in:\n{log}");
    }

    let ck = checkpoint_of(&b);
    let ck_arg = ck.to_str().unwrap().to_string();
    let mut args = record_args(&case, &b, &flags);
    args.extend(["--checkpoint-every", "0.02"]);
    let mut stops = vec![kill_at(spawn(&args), &ck, ", recorded period 2 of 2")];
    let mut stands = vec![inspect_checkpoint(&ck)];
    for stage in [
        ", reference period 2 of 2",
        ", twin 1 of 2 reference period 2",
        ", twin 2 of 2 reference period 2",
    ] {
        assert!(!b.exists(), "a killed run left {}", b.display());
        let resumed = spawn(&["record", "--resume", &ck_arg, "--threads", "1"]);
        stops.push(kill_at(resumed, &ck, stage));
        stands.push(inspect_checkpoint(&ck));
    }
    // `tdex inspect` on the checkpoint: settle 2 000 + spin-up 1 000 steps, the run to t3
    // (3 periods of 6 000 steps), each twin from t2 to t3 (one period)
    let total = 3000 + 3 * 6000 + 2 * 6000;
    let done: Vec<u64> = stands
        .iter()
        .map(|s| s["steps_done"].as_u64().unwrap())
        .collect();
    for s in &stands {
        assert_eq!(s["steps_total"], total, "{s}");
        assert_eq!(s["twins_from"], 2, "{s}");
    }
    assert!(done.windows(2).all(|w| w[0] < w[1]), "{done:?}");
    assert!((3000 + 6000..3000 + 12000).contains(&done[0]), "{done:?}");
    assert!((3000 + 12000..3000 + 18000).contains(&done[1]), "{done:?}");
    assert!((3000 + 18000..3000 + 24000).contains(&done[2]), "{done:?}");
    assert!((3000 + 24000..total).contains(&done[3]), "{done:?}");
    // the time left goes at the pace of the part the run stands in, whose steps start after
    // the settling and spin-up (3 000), the recorded periods (+ 12 000) and the run's
    // reference period (+ 6 000)
    for (s, (part, starts_at)) in stands.iter().zip([
        ("recorded", 3000),
        ("reference", 15000),
        ("twins", 21000),
        ("twins", 21000),
    ]) {
        assert_eq!(s["part"], part, "{s}");
        let in_part = s["steps_done_in_part"].as_u64().unwrap();
        assert_eq!(
            in_part,
            s["steps_done"].as_u64().unwrap() - starts_at,
            "{s}"
        );
        if in_part > 0 {
            assert_eq!(s["left"]["pace_of"], "the_part", "{s}");
            let (wall, left) = (
                s["part_wall_seconds"].as_f64().unwrap(),
                s["left"]["seconds"].as_f64().unwrap(),
            );
            let steps_left = total - s["steps_done"].as_u64().unwrap();
            let expected = wall / in_part as f64 * steps_left as f64;
            assert!((left - expected).abs() <= 1e-9 * expected, "{s}");
        }
    }
    resume_to_the_end(&ck_arg, &a, &b, &stops);
    let rec = tdex_format::RecordingReader::open(&a).unwrap();
    assert_eq!(rec.info().twins_from, 2);
    let twins = rec.twin_snapshots().unwrap();
    let dem = rec.snapshots().unwrap();
    assert_eq!(twins.len(), 2);
    for (m, twin) in twins.iter().enumerate() {
        assert_eq!(twin.iter().map(|s| s.index).collect::<Vec<_>>(), [2, 3]);
        assert_eq!(twin[0].pos, dem[2].pos, "twin {} before it parts", m + 1);
        assert_eq!(twin[0].temp, dem[2].temp, "twin {} before it parts", m + 1);
        assert_ne!(twin[1].pos, dem[3].pos, "twin {} is the DEM", m + 1);
    }
    assert_ne!(
        twins[0][1].pos, twins[1][1].pos,
        "the two twins are one run"
    );
}

/// `tdex inspect --json` on a checkpoint; the human summary is checked to say how to go on.
fn inspect_checkpoint(ck: &Path) -> serde_json::Value {
    let ck = ck.to_str().unwrap();
    let o = run_tdex(&["inspect", ck]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = String::from_utf8_lossy(&o.stdout);
    assert!(
        text.contains(&format!("continue with tdex record --resume {ck}")),
        "{text}"
    );
    let left = text.lines().find(|l| l.starts_with("left ")).unwrap();
    assert!(
        left.contains(" at the pace of the ") && left.ends_with(" steps a minute)")
            || left.ends_with(" at the pace so far"),
        "{text}"
    );
    let o = run_tdex(&["inspect", ck, "--json"]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    serde_json::from_slice(&o.stdout).unwrap()
}
