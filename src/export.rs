//! `tdex export vtk`: every snapshot of a recording or an extrapolation as a VTK PolyData
//! file, and a `.pvd` series that ParaView opens in one click (a recording's DEM twins get a
//! series each).

use crate::cli::{ExportVtkPlan, UsageError};
use anyhow::Result;
use recorder::export::vtk::{self, ExtraArray};
use std::path::{Path, PathBuf};
use tdex_format::output::OutputSet;
use tdex_format::{ExtrapolationReader, FormatError, RecordingReader, Snapshot};

/// Name of the per-particle difference array of an extrapolation with its reference.
pub const DIFFERENCE: &str = "dem_minus_extrapolated";

pub fn run(plan: &ExportVtkPlan) -> Result<()> {
    for f in write(plan)? {
        println!("{}", f.display());
    }
    Ok(())
}

/// Writes the `.vtp` files, then the `.pvd`, all to temporary files first, renamed into
/// place only when every one is written (the series last): a failure leaves the previous
/// series whole. Returns the files written.
pub fn write(plan: &ExportVtkPlan) -> Result<Vec<PathBuf>> {
    let mut twins = Vec::new();
    let (snapshots, reference) = match open(&plan.file)? {
        Opened::Recording(r) => {
            if plan.reference.is_some() {
                return Err(UsageError(format!(
                    "--reference: {} is a recording; the DEM − extrapolated difference needs \
                     an extrapolation and its recording",
                    plan.file.display()
                ))
                .into());
            }
            twins = r.twin_snapshots()?;
            (r.snapshots()?, Vec::new())
        }
        Opened::Extrapolation(e) => {
            let reference = match &plan.reference {
                Some(path) => {
                    let rec = RecordingReader::open(path)?;
                    if e.info().recording_info != *rec.info() {
                        return Err(UsageError(format!(
                            "--reference {}: {} was not extrapolated from it (it names {})",
                            path.display(),
                            plan.file.display(),
                            e.info().recording
                        ))
                        .into());
                    }
                    rec.snapshots()?
                }
                None => Vec::new(),
            };
            (e.snapshots()?, reference)
        }
    };
    let stem = plan
        .file
        .file_stem()
        .map_or("tdex".into(), |s| s.to_string_lossy().into_owned());
    tdex_format::output::create_dir_all(&plan.output)?;
    let mut set = OutputSet::new();
    let mut series = Vec::new();
    for snap in &snapshots {
        let name = format!("{stem}_{:04}.vtp", snap.index);
        let difference = reference
            .iter()
            .find(|r| r.index == snap.index)
            .map(|dem| dem_minus_extrapolated(dem, snap));
        let extra: Vec<ExtraArray> = difference
            .iter()
            .map(|values| ExtraArray {
                name: DIFFERENCE,
                values,
            })
            .collect();
        let xml = vtk::polydata(snap, &extra);
        set.add(&plan.output.join(&name), xml.as_bytes())?;
        series.push((snap.time, name));
    }
    let pvd = format!("{stem}.pvd");
    set.add(&plan.output.join(pvd), vtk::collection(&series).as_bytes())?;
    for (m, twin) in twins.iter().enumerate() {
        let twin_stem = format!("{stem}_twin{}", m + 1);
        let mut series = Vec::new();
        for snap in twin {
            let name = format!("{twin_stem}_{:04}.vtp", snap.index);
            set.add(
                &plan.output.join(&name),
                vtk::polydata(snap, &[]).as_bytes(),
            )?;
            series.push((snap.time, name));
        }
        let pvd = format!("{twin_stem}.pvd");
        set.add(&plan.output.join(pvd), vtk::collection(&series).as_bytes())?;
    }
    Ok(set.commit()?)
}

enum Opened {
    Recording(RecordingReader),
    Extrapolation(ExtrapolationReader),
}

/// A recording or, failing that, an extrapolation.
fn open(path: &Path) -> Result<Opened> {
    match RecordingReader::open(path) {
        Ok(r) => Ok(Opened::Recording(r)),
        Err(FormatError::NotRecording { .. }) => match ExtrapolationReader::open(path) {
            Ok(e) => Ok(Opened::Extrapolation(e)),
            Err(FormatError::NotRecording { path, .. }) => Err(FormatError::NotRecording {
                path,
                expected: "recording or extrapolation",
                detail: "it has neither tdex metadata record".into(),
            }
            .into()),
            Err(e) => Err(e.into()),
        },
        Err(e) => Err(e.into()),
    }
}

/// Per point of an extrapolated snapshot, the DEM temperature of the particle playing its
/// role (`id`) minus the extrapolated one.
fn dem_minus_extrapolated(dem: &Snapshot, extra: &Snapshot) -> Vec<f64> {
    extra
        .id
        .iter()
        .zip(&extra.temp)
        .map(|(&id, t)| dem.temp[id as usize] - t)
        .collect()
}
