#!/usr/bin/env python3
"""Reads the files of `tdex export vtk` with VTK's own reader (the `vtk` package from PyPI)
and checks them against the values tdex read from the MCAP file.

usage: read_vtk.py SERIES.pvd EXPECTED.json
EXPECTED.json: {"points": N, "snapshots": [{"file", "time", "temperature": [...],
"id": [...], "difference": [...] or null}, ...]} in the order of the series.
The .pvd is parsed as XML (VTK has no .pvd reader outside ParaView); every .vtp it names
is read by vtkXMLPolyDataReader. Exits non-zero on any mismatch.
"""
import json
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

from vtkmodules.util.numpy_support import vtk_to_numpy
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader


def main(pvd, expected_json):
    expected = json.loads(Path(expected_json).read_text())
    root = ET.parse(pvd).getroot()
    assert root.get("type") == "Collection", root.get("type")
    datasets = root.find("Collection").findall("DataSet")
    assert len(datasets) == len(expected["snapshots"]), (len(datasets), len(expected["snapshots"]))
    for ds, exp in zip(datasets, expected["snapshots"]):
        assert ds.get("file") == exp["file"], (ds.get("file"), exp["file"])
        assert math.isclose(float(ds.get("timestep")), exp["time"], rel_tol=1e-15), ds.get("timestep")
        reader = vtkXMLPolyDataReader()
        reader.SetFileName(str(Path(pvd).parent / ds.get("file")))
        reader.Update()
        poly = reader.GetOutput()
        n = expected["points"]
        assert poly.GetNumberOfPoints() == n, (exp["file"], poly.GetNumberOfPoints(), n)
        assert poly.GetNumberOfVerts() == n, (exp["file"], poly.GetNumberOfVerts(), n)
        data = poly.GetPointData()
        temperature = vtk_to_numpy(data.GetArray("temperature"))
        # written in shortest round-trip form: exactly the recorded values
        assert list(temperature) == exp["temperature"], exp["file"]
        assert list(vtk_to_numpy(data.GetArray("id"))) == exp["id"], exp["file"]
        assert data.GetArray("velocity").GetNumberOfComponents() == 3
        assert data.GetArray("radius").GetNumberOfTuples() == n
        diff = data.GetArray("dem_minus_extrapolated")
        if exp["difference"] is None:
            assert diff is None, exp["file"]
        else:
            assert list(vtk_to_numpy(diff)) == exp["difference"], exp["file"]
        print(f"{exp['file']}: {n} points, temperature {min(temperature):.4f}..{max(temperature):.4f} K"
              + ("" if diff is None else ", with the DEM difference"))
    print(f"{len(datasets)} datasets read back by VTK {__import__('vtkmodules').__version__}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
