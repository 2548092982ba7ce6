//! Outputs on a full disk, a read-only disk and an unwritable directory: tdex fails with the path and the reason, leaves no temporary file and keeps the previous file byte for byte.
//!
//! The full disk is a small tmpfs (mounted when the tests run as root) filled up to a few
//! kilobytes, and a file-size limit (`ulimit -f`, which tdex meets as EFBIG because it ignores
//! SIGXFSZ). Whichever cannot be set up is skipped with its reason; when neither can, the
//! test fails unless TDEX_ALLOW_SKIP_FULL_DISK is set, so that it cannot pass untested.

use crate::cli_compare::record_and_extrapolate;
use crate::cli_run::TINY_CASE;
use crate::util::*;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Set it to let the full-disk tests pass where no full disk can be made (no root, no `sh`).
const ALLOW_SKIP: &str = "TDEX_ALLOW_SKIP_FULL_DISK";

/// A tmpfs mounted on a directory, unmounted on drop (also when the test fails).
struct Tmpfs {
    dir: PathBuf,
}

impl Tmpfs {
    fn mount(dir: &Path, kilobytes: u64) -> Result<Self, String> {
        std::fs::create_dir_all(dir).unwrap();
        let o = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={kilobytes}k"), "tmpfs"])
            .arg(dir)
            .output()
            .map_err(|e| format!("cannot run mount: {e}"))?;
        if !o.status.success() {
            return Err(format!(
                "mount -t tmpfs failed: {}",
                String::from_utf8_lossy(&o.stderr).trim()
            ));
        }
        Ok(Self {
            dir: dir.to_path_buf(),
        })
    }

    fn remount_read_only(&self) {
        let o = Command::new("mount")
            .args(["-o", "remount,ro"])
            .arg(&self.dir)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
}

impl Drop for Tmpfs {
    fn drop(&mut self) {
        let unmounted = Command::new("umount")
            .arg(&self.dir)
            .status()
            .is_ok_and(|s| s.success());
        if !unmounted {
            // still busy (a child not reaped yet): detach it now, freed when unused
            let _ = Command::new("umount").arg("-l").arg(&self.dir).status();
        }
    }
}

/// Fills the filesystem holding `dir` with a file `filler`, then frees `free` bytes of it.
fn fill_leaving(dir: &Path, free: u64) {
    let path = dir.join("filler");
    let mut f = std::fs::File::create(&path).unwrap();
    let block = vec![0xA5u8; 4096];
    loop {
        match f.write_all(&block) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::StorageFull => break,
            Err(e) => panic!("filling {}: {e}", dir.display()),
        }
    }
    let len = f.metadata().unwrap().len();
    assert!(len > free, "{}: only {len} bytes were free", dir.display());
    f.set_len(len - free).unwrap();
}

/// A disk that will be full during the command: a nearly full tmpfs, or a file-size limit.
enum Full {
    /// Held for its unmount on drop.
    Tmpfs(#[allow(dead_code)] Tmpfs),
    /// `ulimit -f` in 512-byte blocks (POSIX `sh`).
    Ulimit(u32),
}

struct FullDisk {
    dir: PathBuf,
    full: Full,
}

impl FullDisk {
    /// Runs tdex with its outputs on this disk.
    fn tdex(&self, args: &[&str]) -> Output {
        match &self.full {
            Full::Tmpfs(_) => run_tdex(args),
            Full::Ulimit(blocks) => Command::new("sh")
                .arg("-c")
                .arg(format!("ulimit -f {blocks} && exec \"$0\" \"$@\""))
                .arg(tdex())
                .args(args)
                .output()
                .unwrap(),
        }
    }

    /// What the error must say.
    fn reason(&self) -> &'static str {
        match self.full {
            Full::Tmpfs(_) => "no space left on device",
            Full::Ulimit(_) => "file too large",
        }
    }

    fn name(&self) -> &'static str {
        match self.full {
            Full::Tmpfs(_) => "full tmpfs",
            Full::Ulimit(_) => "ulimit -f",
        }
    }
}

/// The full disks this machine can make under `root`: `prepare` puts the previous outputs
/// in the directory first (before it is filled). Fails when there is none (unless
/// TDEX_ALLOW_SKIP_FULL_DISK is set).
fn full_disks(root: &Path, tmpfs_kb: u64, free: u64, prepare: impl Fn(&Path)) -> Vec<FullDisk> {
    let mut disks = Vec::new();
    let mut skipped = Vec::new();
    let dir = root.join("tmpfs");
    match Tmpfs::mount(&dir, tmpfs_kb) {
        Ok(t) => {
            prepare(&dir);
            fill_leaving(&dir, free);
            disks.push(FullDisk {
                dir,
                full: Full::Tmpfs(t),
            });
        }
        Err(e) => skipped.push(format!("full tmpfs: {e}")),
    }
    let dir = root.join("ulimit");
    let blocks = (free / 512).max(1) as u32;
    let sh_ok = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -f {blocks}"))
        .status()
        .is_ok_and(|s| s.success());
    if sh_ok {
        std::fs::create_dir_all(&dir).unwrap();
        prepare(&dir);
        disks.push(FullDisk {
            dir,
            full: Full::Ulimit(blocks),
        });
    } else {
        skipped.push("ulimit -f: sh cannot set a file-size limit".into());
    }
    for s in &skipped {
        eprintln!("skipped: {s}");
    }
    if disks.is_empty() {
        assert!(
            std::env::var_os(ALLOW_SKIP).is_some(),
            "no full disk could be made ({}); set {ALLOW_SKIP}=1 to skip these tests",
            skipped.join("; ")
        );
    }
    disks
}

/// Every file of `dir` but the filler, with its bytes.
fn outputs(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    let mut all = files(dir);
    all.remove("filler");
    all
}

/// tdex failed (exit code 1, not a signal or a panic) naming `dest` and `reason`, and said
/// whether a previous file was kept.
fn assert_failed(what: &str, o: &Output, dest: &Path, reason: &str, previous: bool) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{what}: {:?}: {err}", o.status);
    assert!(!err.contains("panicked"), "{what}: {err}");
    assert!(
        err.contains(&*dest.to_string_lossy()),
        "{what}: the error must name {}: {err}",
        dest.display()
    );
    assert!(
        err.contains(reason),
        "{what}: the error must say '{reason}': {err}"
    );
    let kept = if previous {
        "was left as it was"
    } else {
        "no file was left at that path"
    };
    assert!(
        err.contains(kept),
        "{what}: the error must say '{kept}': {err}"
    );
    eprintln!("{what}: {}", err.trim());
}

#[test]
fn record_on_a_full_disk_says_why_and_keeps_the_previous_recording() {
    let root = tempfile::tempdir().unwrap();
    let case = root.path().join("tiny.toml");
    std::fs::write(&case, TINY_CASE).unwrap();
    let previous = root.path().join("previous.mcap");
    let record = |out: &Path, run: &dyn Fn(&[&str]) -> Output| {
        run(&[
            "record",
            case.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--tau",
            "0.1",
            "--reference",
            "3",
        ])
    };
    let o = record(&previous, &run_tdex);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let old = std::fs::read(&previous).unwrap();
    // the recording (~100 KB) does not fit the 32 KB left
    assert!(
        old.len() > 64 << 10,
        "the recording is only {} bytes",
        old.len()
    );

    let disks = full_disks(root.path(), 256, 32 << 10, |dir| {
        std::fs::copy(&previous, dir.join("run.mcap")).unwrap();
    });
    for disk in &disks {
        let what = format!("record, {}", disk.name());
        let dest = disk.dir.join("run.mcap");
        let o = record(&dest, &|a| disk.tdex(a));
        assert_failed(&what, &o, &dest, disk.reason(), true);
        assert!(
            std::fs::read(&dest).unwrap() == old,
            "{what}: the previous recording changed"
        );
        // no previous file: none afterwards either
        let fresh = disk.dir.join("fresh.mcap");
        let o = record(&fresh, &|a| disk.tdex(a));
        assert_failed(&what, &o, &fresh, disk.reason(), false);
        let left = file_names(&disk.dir);
        let expected: &[&str] = match disk.full {
            Full::Tmpfs(_) => &["filler", "run.mcap"],
            Full::Ulimit(_) => &["run.mcap"],
        };
        assert_eq!(left, expected, "{what}: temporary or partial files left");
    }
}

#[test]
fn extrapolate_and_report_on_a_full_disk_keep_the_previous_files() {
    let root = tempfile::tempdir().unwrap();
    let (run, extra) = record_and_extrapolate(root.path(), 2, 2);
    let previous_report = root.path().join("report");
    tdex_ok(&[
        "report",
        run.to_str().unwrap(),
        extra.to_str().unwrap(),
        "-o",
        previous_report.to_str().unwrap(),
        "--cells",
        "20",
    ]);
    let report_files = files(&previous_report);
    assert!(report_files.contains_key("report.html"));
    let old_extra = std::fs::read(&extra).unwrap();

    let disks = full_disks(root.path(), 1024, 4 << 10, |dir| {
        std::fs::copy(&extra, dir.join("extra.mcap")).unwrap();
        std::fs::create_dir(dir.join("report")).unwrap();
        for (name, bytes) in &report_files {
            std::fs::write(dir.join("report").join(name), bytes).unwrap();
        }
    });
    for disk in &disks {
        let what = format!("extrapolate, {}", disk.name());
        let dest = disk.dir.join("extra.mcap");
        let o = disk.tdex(&[
            "extrapolate",
            run.to_str().unwrap(),
            "--periods",
            "20",
            "-o",
            dest.to_str().unwrap(),
        ]);
        assert_failed(&what, &o, &dest, disk.reason(), true);
        assert!(
            std::fs::read(&dest).unwrap() == old_extra,
            "{what}: the previous extrapolation changed"
        );

        let what = format!("report, {}", disk.name());
        let dir = disk.dir.join("report");
        let o = disk.tdex(&[
            "report",
            run.to_str().unwrap(),
            extra.to_str().unwrap(),
            "-o",
            dir.to_str().unwrap(),
            "--cells",
            "30",
        ]);
        // the first file of the report that did not fit is named
        let err = String::from_utf8_lossy(&o.stderr).into_owned();
        let named = report_files
            .keys()
            .map(|n| dir.join(n))
            .find(|p| err.contains(&*p.to_string_lossy()))
            .unwrap_or_else(|| panic!("{what}: no report file named: {err}"));
        assert_failed(&what, &o, &named, disk.reason(), true);
        assert!(
            outputs(&dir) == report_files,
            "{what}: the previous report changed"
        );
        let mut left = file_names(&disk.dir);
        left.retain(|n| n != "filler");
        assert_eq!(left, ["extra.mcap", "report"], "{what}: files left");
    }
}

#[test]
fn record_into_a_read_only_disk_or_an_unwritable_directory_says_why() {
    let root = tempfile::tempdir().unwrap();
    let case = root.path().join("tiny.toml");
    std::fs::write(&case, TINY_CASE).unwrap();
    let record = |out: &Path, run_as: &[&str]| -> Output {
        let args = [
            "record",
            case.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
            "--tau",
            "0.1",
        ];
        if run_as.is_empty() {
            run_tdex(&args)
        } else {
            Command::new(run_as[0])
                .args(&run_as[1..])
                .arg(tdex())
                .args(args)
                .output()
                .unwrap()
        }
    };
    let previous = b"a previous recording".to_vec();

    // a read-only filesystem: refused even for root
    let dir = root.path().join("ro");
    match Tmpfs::mount(&dir, 256) {
        Ok(t) => {
            std::fs::write(dir.join("run.mcap"), &previous).unwrap();
            t.remount_read_only();
            let dest = dir.join("run.mcap");
            let o = record(&dest, &[]);
            assert_failed("read-only", &o, &dest, "read-only file system", true);
            assert_eq!(std::fs::read(&dest).unwrap(), previous);
            assert_eq!(file_names(&dir), ["run.mcap"]);
        }
        Err(e) => eprintln!("skipped (read-only disk): {e}"),
    }

    // a directory the user cannot write: as root, run tdex as `nobody` (root writes anywhere)
    let dir = root.path().join("locked");
    std::fs::create_dir(&dir).unwrap();
    std::fs::write(dir.join("run.mcap"), &previous).unwrap();
    let dest = dir.join("run.mcap");
    let is_root = Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.trim_ascii() == b"0");
    let as_nobody: &[&str] = &[
        "setpriv",
        "--reuid=65534",
        "--regid=65534",
        "--clear-groups",
    ];
    use std::os::unix::fs::PermissionsExt;
    let chmod = |p: &Path, mode| {
        std::fs::set_permissions(p, std::fs::Permissions::from_mode(mode)).unwrap()
    };
    let runner: Option<&[&str]> = if is_root {
        // nobody reads the case and enters the directories, but cannot write `dir`
        chmod(root.path(), 0o755);
        chmod(&dir, 0o555);
        let probe = Command::new(as_nobody[0])
            .args(&as_nobody[1..])
            .arg(tdex())
            .arg("--version")
            .output();
        probe.is_ok_and(|o| o.status.success()).then_some(as_nobody)
    } else {
        chmod(&dir, 0o555);
        Some(&[])
    };
    match runner {
        Some(run_as) => {
            let o = record(&dest, run_as);
            assert_failed(
                "permission",
                &o,
                &dest,
                "permission denied: cannot write in",
                true,
            );
            assert_eq!(std::fs::read(&dest).unwrap(), previous);
            assert_eq!(file_names(&dir), ["run.mcap"]);
        }
        None => eprintln!("skipped (unwritable directory): setpriv cannot run tdex as nobody"),
    }
    chmod(&dir, 0o755);
}
