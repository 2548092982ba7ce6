//! VTK XML files for ParaView: a snapshot as PolyData (`.vtp`, ASCII, one vertex per
//! particle) and a time series of them as a collection (`.pvd`).

use std::fmt::Write;
use tdex_format::Snapshot;

/// A per-particle value written besides the snapshot's own fields (one component).
pub struct ExtraArray<'a> {
    pub name: &'a str,
    pub values: &'a [f64],
}

/// The snapshot as a VTK XML PolyData document: points at the particle centres, a vertex
/// per particle (so that ParaView draws them), and the point arrays `temperature`,
/// `radius`, `id`, `velocity` and `extra`. Numbers are written in Rust's shortest
/// round-trip form: the same snapshot gives the same bytes, and they read back exactly.
pub fn polydata(snapshot: &Snapshot, extra: &[ExtraArray]) -> String {
    let n = snapshot.len();
    let mut out = String::with_capacity(n * 200 + 1024);
    out.push_str("<?xml version=\"1.0\"?>\n");
    out.push_str(
        "<VTKFile type=\"PolyData\" version=\"0.1\" byte_order=\"LittleEndian\" \
         header_type=\"UInt64\">\n<PolyData>\n",
    );
    let _ = writeln!(
        out,
        "<Piece NumberOfPoints=\"{n}\" NumberOfVerts=\"{n}\" NumberOfLines=\"0\" \
         NumberOfStrips=\"0\" NumberOfPolys=\"0\">"
    );
    out.push_str("<PointData Scalars=\"temperature\" Vectors=\"velocity\">\n");
    array(&mut out, "Float64", "temperature", 1, snapshot.temp.iter());
    array(&mut out, "Float64", "radius", 1, snapshot.radius.iter());
    array(&mut out, "UInt32", "id", 1, snapshot.id.iter());
    array(
        &mut out,
        "Float64",
        "velocity",
        3,
        snapshot.vel.iter().flatten(),
    );
    for e in extra {
        array(&mut out, "Float64", e.name, 1, e.values.iter());
    }
    out.push_str("</PointData>\n<Points>\n");
    array(
        &mut out,
        "Float64",
        "position",
        3,
        snapshot.pos.iter().flatten(),
    );
    out.push_str("</Points>\n<Verts>\n");
    array(&mut out, "Int64", "connectivity", 1, 0..n as u64);
    array(&mut out, "Int64", "offsets", 1, 1..=n as u64);
    out.push_str("</Verts>\n</Piece>\n</PolyData>\n</VTKFile>\n");
    out
}

/// One `DataArray`, ASCII, a line per tuple.
fn array<T: std::fmt::Display>(
    out: &mut String,
    ty: &str,
    name: &str,
    components: usize,
    values: impl Iterator<Item = T>,
) {
    let _ = writeln!(
        out,
        "<DataArray type=\"{ty}\" Name=\"{name}\" NumberOfComponents=\"{components}\" \
         format=\"ascii\">"
    );
    for (k, v) in values.enumerate() {
        let sep = if (k + 1) % components == 0 { '\n' } else { ' ' };
        let _ = write!(out, "{v}{sep}");
    }
    out.push_str("</DataArray>\n");
}

/// A ParaView collection (`.pvd`) of `(time, file)` datasets: opening it loads the series
/// with its simulated times.
pub fn collection(datasets: &[(f64, String)]) -> String {
    let mut out = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" \
         byte_order=\"LittleEndian\">\n<Collection>\n",
    );
    for (time, file) in datasets {
        let _ = writeln!(
            out,
            "<DataSet timestep=\"{time}\" group=\"\" part=\"0\" file=\"{}\"/>",
            escape(file)
        );
    }
    out.push_str("</Collection>\n</VTKFile>\n");
    out
}

/// `text` as an XML attribute value.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_snapshot_becomes_points_vertices_and_arrays() {
        let snap = Snapshot {
            index: 1,
            time: 2.5,
            id: vec![0, 1],
            pos: vec![[0.1, -0.2, 0.3], [1e-7, 0.0, 2.0]],
            radius: vec![0.005, 0.004],
            temp: vec![30.0, 10.25],
            vel: vec![[0.0, 1.0, 0.0], [-0.5, 0.0, 0.125]],
        };
        let xml = polydata(
            &snap,
            &[ExtraArray {
                name: "d",
                values: &[0.5, -1.0],
            }],
        );
        assert!(xml.contains("NumberOfPoints=\"2\" NumberOfVerts=\"2\""));
        assert!(xml.contains("Name=\"temperature\" NumberOfComponents=\"1\" format=\"ascii\">\n30\n10.25\n</DataArray>"));
        assert!(xml.contains("Name=\"position\" NumberOfComponents=\"3\" format=\"ascii\">\n0.1 -0.2 0.3\n0.0000001 0 2\n</DataArray>"));
        assert!(xml.contains(
            "Name=\"offsets\" NumberOfComponents=\"1\" format=\"ascii\">\n1\n2\n</DataArray>"
        ));
        assert!(xml.contains(
            "Name=\"d\" NumberOfComponents=\"1\" format=\"ascii\">\n0.5\n-1\n</DataArray>"
        ));
        let pvd = collection(&[(2.5, "a&b_0001.vtp".into())]);
        assert!(pvd.contains(
            "<DataSet timestep=\"2.5\" group=\"\" part=\"0\" file=\"a&amp;b_0001.vtp\"/>"
        ));
    }
}
