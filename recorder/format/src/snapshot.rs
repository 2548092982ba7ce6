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

    /// Decodes a point cloud written by [`Snapshot::encode`]; the error says what is wrong.
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
        Ok(snap)
    }
}
