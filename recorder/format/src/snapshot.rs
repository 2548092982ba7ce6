//! Particle snapshots as `foxglove.PointCloud`: one point per particle in fixed-id order, with
//! the fields x, y, z, temperature, id, radius, vx, vy, vz (little-endian, f64 but id u32).

use super::proto::foxglove::{
    packed_element_field::NumericType, PackedElementField, PointCloud, Pose, Quaternion, Vector3,
};
use prost::Message;

/// Point layout: (name, byte offset, type).
const FIELDS: [(&str, u32, NumericType); 9] = [
    ("x", 0, NumericType::Float64),
    ("y", 8, NumericType::Float64),
    ("z", 16, NumericType::Float64),
    ("temperature", 24, NumericType::Float64),
    ("id", 32, NumericType::Uint32),
    ("radius", 36, NumericType::Float64),
    ("vx", 44, NumericType::Float64),
    ("vy", 52, NumericType::Float64),
    ("vz", 60, NumericType::Float64),
];
/// Bytes per point.
pub const POINT_STRIDE: usize = 68;
/// Frame of the drum's axes (x across, y along the axis, z up).
pub const FRAME_ID: &str = "drum";

/// The distinct radii of a bed (m), smallest first: one per size class, as the engine gives
/// each class one radius. Radii are told apart by their bits, so that the pairing (which
/// keeps each particle on a role of the same bits) and the comparison (which reports by
/// class) count the same classes; a file's radii are finite and positive
/// ([`Snapshot::decode`]), for which bits and values agree.
pub fn size_classes(radius: &[f64]) -> Vec<f64> {
    let bits: std::collections::BTreeSet<u64> = radius.iter().map(|r| r.to_bits()).collect();
    let mut radii: Vec<f64> = bits.into_iter().map(f64::from_bits).collect();
    radii.sort_by(f64::total_cmp);
    radii
}

/// The particles at one instant, in fixed-id order (`id[k] == k`).
#[derive(Debug, Clone, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Snapshot {
    /// 0 for `t0`, 1 for `t1`, `k` for `t0 + kτ`.
    pub index: u32,
    /// Simulated time (s).
    pub time: f64,
    pub id: Vec<u32>,
    pub pos: Vec<[f64; 3]>,
    pub radius: Vec<f64>,
    pub temp: Vec<f64>,
    pub vel: Vec<[f64; 3]>,
}

impl Snapshot {
    pub fn len(&self) -> usize {
        self.id.len()
    }

    pub fn is_empty(&self) -> bool {
        self.id.is_empty()
    }

    /// The bed's size classes: its distinct radii (m), smallest first ([`size_classes`]).
    pub fn size_classes(&self) -> Vec<f64> {
        size_classes(&self.radius)
    }

    /// Mean particle diameter (m); 0 for an empty snapshot.
    pub fn mean_diameter(&self) -> f64 {
        2.0 * self.radius.iter().sum::<f64>() / self.len().max(1) as f64
    }

    /// The snapshot as an encoded `foxglove.PointCloud`.
    pub fn encode(&self) -> Vec<u8> {
        let mut data = Vec::with_capacity(self.len() * POINT_STRIDE);
        for k in 0..self.len() {
            let p = self.pos[k];
            let v = self.vel[k];
            for x in [p[0], p[1], p[2], self.temp[k]] {
                data.extend_from_slice(&x.to_le_bytes());
            }
            data.extend_from_slice(&self.id[k].to_le_bytes());
            for x in [self.radius[k], v[0], v[1], v[2]] {
                data.extend_from_slice(&x.to_le_bytes());
            }
        }
        let nanos = (self.time * 1e9).round() as i64;
        PointCloud {
            timestamp: Some(prost_types::Timestamp {
                seconds: nanos.div_euclid(1_000_000_000),
                nanos: nanos.rem_euclid(1_000_000_000) as i32,
            }),
            frame_id: FRAME_ID.into(),
            pose: Some(Pose {
                position: Some(Vector3::default()),
                orientation: Some(Quaternion {
                    w: 1.0,
                    ..Default::default()
                }),
            }),
            point_stride: POINT_STRIDE as u32,
            fields: FIELDS
                .iter()
                .map(|&(name, offset, ty)| PackedElementField {
                    name: name.into(),
                    offset,
                    r#type: ty as i32,
                })
                .collect(),
            data,
        }
        .encode_to_vec()
    }

    /// Decodes a point cloud written by [`Snapshot::encode`]; the error says what is wrong,
    /// among which a radius that is not finite and positive (every contact law, capacity and
    /// size class divides by or sorts on it).
    pub fn decode(index: u32, bytes: &[u8]) -> Result<Self, String> {
        let cloud = PointCloud::decode(bytes).map_err(|e| format!("snapshot {index}: {e}"))?;
        let layout: Vec<(&str, u32, i32)> = cloud
            .fields
            .iter()
            .map(|f| (f.name.as_str(), f.offset, f.r#type))
            .collect();
        let expected: Vec<(&str, u32, i32)> =
            FIELDS.iter().map(|&(n, o, t)| (n, o, t as i32)).collect();
        if layout != expected || cloud.point_stride as usize != POINT_STRIDE {
            return Err(format!(
                "snapshot {index}: point layout {layout:?} with stride {} is not tdex's",
                cloud.point_stride
            ));
        }
        if cloud.data.len() % POINT_STRIDE != 0 {
            return Err(format!(
                "snapshot {index}: {} data bytes is not a whole number of {POINT_STRIDE}-byte points",
                cloud.data.len()
            ));
        }
        let f64_at = |p: &[u8], o: usize| f64::from_le_bytes(p[o..o + 8].try_into().unwrap());
        let mut snap = Snapshot {
            index,
            time: cloud
                .timestamp
                .map_or(0.0, |t| t.seconds as f64 + t.nanos as f64 * 1e-9),
            ..Default::default()
        };
        for p in cloud.data.chunks_exact(POINT_STRIDE) {
            snap.pos.push([f64_at(p, 0), f64_at(p, 8), f64_at(p, 16)]);
            snap.temp.push(f64_at(p, 24));
            snap.id
                .push(u32::from_le_bytes(p[32..36].try_into().unwrap()));
            snap.radius.push(f64_at(p, 36));
            snap.vel.push([f64_at(p, 44), f64_at(p, 52), f64_at(p, 60)]);
        }
        if let Some(k) = snap
            .radius
            .iter()
            .position(|r| !(r.is_finite() && *r > 0.0))
        {
            return Err(format!(
                "snapshot {index}: particle {k} (id {}) has radius {} m; a radius is finite and \
                 positive",
                snap.id[k], snap.radius[k]
            ));
        }
        Ok(snap)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bed(radius: Vec<f64>) -> Snapshot {
        let n = radius.len();
        Snapshot {
            index: 1,
            time: 0.5,
            id: (0..n as u32).collect(),
            pos: vec![[0.0, 0.01, 0.02]; n],
            radius,
            temp: vec![300.0; n],
            vel: vec![[0.0; 3]; n],
        }
    }

    #[test]
    fn size_classes_are_told_apart_by_bits_and_ordered_by_radius() {
        assert_eq!(size_classes(&[2.0, 1.0, 2.0, 0.5]), [0.5, 1.0, 2.0]);
        assert_eq!(size_classes(&[]), Vec::<f64>::new());
        // 0.1 + 0.2 is not 0.3 bit for bit: two classes
        assert_eq!(size_classes(&[0.3, 0.1 + 0.2]).len(), 2);
        assert_eq!(
            bed(vec![0.002, 0.001, 0.002]).size_classes(),
            [0.001, 0.002]
        );
    }

    #[test]
    fn a_radius_that_is_not_finite_and_positive_is_refused_on_reading() {
        let good = bed(vec![0.002, 0.001]);
        assert_eq!(Snapshot::decode(1, &good.encode()).unwrap(), good);
        for r in [0.0, -0.001, f64::NAN, f64::INFINITY] {
            let e = Snapshot::decode(1, &bed(vec![0.002, r]).encode()).unwrap_err();
            assert!(
                e.starts_with("snapshot 1: particle 1 (id 1) has radius")
                    && e.ends_with("a radius is finite and positive"),
                "{e}"
            );
        }
    }
}
