//! Compiles the MCAP schemas in `proto/` with protox (pure Rust, no protoc needed): Rust
//! types through prost-build, and the binary FileDescriptorSets that the recording stores
//! as its protobuf schemas (each with its imports, as MCAP readers expect).

use prost::Message;
use std::path::PathBuf;

fn main() {
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    println!("cargo:rerun-if-changed=proto");
    let compile = |file: &str| {
        protox::compile([file], ["proto"]).unwrap_or_else(|e| panic!("proto/{file}: {e}"))
    };
    let point_cloud = compile("foxglove/PointCloud.proto");
    let collisions = compile("tdex/CollisionBatch.proto");
    std::fs::write(out.join("point_cloud.fds"), point_cloud.encode_to_vec()).unwrap();
    std::fs::write(out.join("collision_batch.fds"), collisions.encode_to_vec()).unwrap();
    let mut all = point_cloud;
    all.file.extend(collisions.file);
    prost_build::Config::new()
        .compile_fds(all)
        .expect("prost-build generates the schema types");
}
