//! `tdex export vtk`: a recording and an extrapolation (with its DEM reference) as `.vtp`
//! files and a `.pvd` series, read back by VTK's own reader (`tests/python/read_vtk.py`);
//! the same file gives the same bytes; wrong inputs are refused.

use crate::cli_compare::record_and_extrapolate;
use crate::util::*;
use serde_json::json;
use std::path::Path;
use tdex_format::{ExtrapolationReader, RecordingReader, Snapshot};

fn export(file: &Path, out: &Path, reference: Option<&Path>) -> std::process::Output {
    let mut args = vec![
        "export".to_string(),
        "vtk".into(),
        file.display().to_string(),
        "-o".into(),
        out.display().to_string(),
    ];
    if let Some(r) = reference {
        args.extend(["--reference".into(), r.display().to_string()]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    run_tdex(&args)
}

fn export_ok(file: &Path, out: &Path, reference: Option<&Path>) {
    let o = export(file, out, reference);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// What the Python reader must find in each dataset of the series.
fn expected(stem: &str, snaps: &[Snapshot], dem: Option<&[Snapshot]>) -> serde_json::Value {
    let snapshots: Vec<_> = snaps
        .iter()
        .map(|s| {
            let difference = dem
                .and_then(|d| d.iter().find(|r| r.index == s.index))
                .map(|d| {
                    s.id.iter()
                        .zip(&s.temp)
                        .map(|(&id, t)| d.temp[id as usize] - t)
                        .collect::<Vec<f64>>()
                });
            json!({
                "file": format!("{stem}_{:04}.vtp", s.index),
                "time": s.time,
                "temperature": s.temp,
                "id": s.id,
                "difference": difference,
            })
        })
        .collect();
    json!({ "points": snaps[0].len(), "snapshots": snapshots })
}

#[test]
fn vtk_files_read_back_with_vtk_and_are_reproducible() {
    let dir = tempfile::tempdir().unwrap();
    let (run, extra) = record_and_extrapolate(dir.path(), 2, 2);
    let (rec_dir, extra_dir) = (dir.path().join("vtk_run"), dir.path().join("vtk_extra"));
    export_ok(&run, &rec_dir, None);
    export_ok(&extra, &extra_dir, Some(&run));

    let recording = RecordingReader::open(&run).unwrap().snapshots().unwrap();
    let extrapolated = ExtrapolationReader::open(&extra)
        .unwrap()
        .snapshots()
        .unwrap();
    let written = files(&rec_dir);
    assert_eq!(
        written.keys().cloned().collect::<Vec<_>>(),
        [
            "run.pvd",
            "run_0000.vtp",
            "run_0001.vtp",
            "run_0002.vtp",
            "run_0003.vtp"
        ]
    );
    let extra_files = files(&extra_dir);
    assert_eq!(
        extra_files.keys().cloned().collect::<Vec<_>>(),
        [
            "extra.pvd",
            "extra_0001.vtp",
            "extra_0002.vtp",
            "extra_0003.vtp"
        ]
    );
    for (name, bytes) in written.iter().chain(&extra_files) {
        let text = std::str::from_utf8(bytes).unwrap();
        roxmltree::Document::parse(text).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    // same input, same bytes
    let again = dir.path().join("again");
    export_ok(&extra, &again, Some(&run));
    assert!(files(&again) == extra_files, "a second export differs");

    if !python_with("vtkmodules.vtkIOXML, numpy", "vtk") {
        return;
    }
    for (pvd, expect) in [
        (rec_dir.join("run.pvd"), expected("run", &recording, None)),
        (
            extra_dir.join("extra.pvd"),
            expected("extra", &extrapolated, Some(&recording)),
        ),
    ] {
        let json_path = dir.path().join("expected.json");
        std::fs::write(&json_path, serde_json::to_vec(&expect).unwrap()).unwrap();
        let o = std::process::Command::new("python3")
            .arg(repo().join("tests/python/read_vtk.py"))
            .args([&pvd, &json_path])
            .output()
            .unwrap();
        assert!(
            o.status.success(),
            "read_vtk.py {}: {}{}",
            pvd.display(),
            String::from_utf8_lossy(&o.stdout),
            String::from_utf8_lossy(&o.stderr)
        );
        eprint!("{}", String::from_utf8_lossy(&o.stdout));
    }
}

#[test]
fn export_refuses_wrong_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let (run, extra) = record_and_extrapolate(dir.path(), 1, 1);
    let out = dir.path().join("vtk");
    for (file, reference, expect) in [
        (&run, Some(&run), "is a recording"),
        (&extra, Some(&extra), "not a tdex recording"),
        (&dir.path().join("none.mcap"), None, "cannot open"),
    ] {
        let o = export(file, &out, reference.map(|p| p.as_path()));
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{err}");
        assert!(err.contains(expect), "{expect}: {err}");
    }
    let case = dir.path().join("case.toml");
    let o = export(&run, &case, None);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("is a file"));
}
