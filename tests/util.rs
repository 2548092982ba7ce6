//! Shared helpers: small worlds built straight from the engine's stages, and the CLI runner.

use recorder::case::{ConductionSpec, PairCoefficients, RollingModel};
use recorder::contact::PairLaw;
use recorder::counters::Counters;
use recorder::heat::ConductionLaw;
use recorder::neighbor::{CellGrid, NeighborList};
use recorder::particles::ParticleSet;
use recorder::periodic::AxialPeriod;
use recorder::pipeline::{ContactCount, Pipeline, StepParams};
use recorder::wall::WallSet;
use std::path::{Path, PathBuf};
use std::process::Output;

pub const DENSITY: f64 = 2500.0;
pub const YOUNG: f64 = 1.0e7;
pub const POISSON: f64 = 0.3;
pub const CONDUCTIVITY: f64 = 100.0;
pub const HEAT_CAPACITY: f64 = 840.0;

/// A few spheres and walls stepped by the real pipeline.
pub struct World {
    pub params: StepParams,
    pub particles: ParticleSet,
    pub neighbors: NeighborList,
    pub walls: WallSet,
    pub pipeline: Pipeline,
    pub counters: Counters,
}

impl World {
    pub fn new(
        particles: ParticleSet,
        walls: WallSet,
        restitution: f64,
        dt: f64,
        gravity: f64,
    ) -> Self {
        let c = PairCoefficients {
            restitution,
            friction: 0.3,
            rolling_friction: 0.002,
        };
        let law = PairLaw::new(YOUNG, POISSON, &c, RollingModel::Epsd2);
        let params = StepParams {
            dt,
            gravity: [0.0, 0.0, -gravity],
            particle_particle: law,
            particle_wall: law,
            conduction: ConductionLaw::new(
                &ConductionSpec::default(),
                CONDUCTIVITY,
                CONDUCTIVITY,
                HEAT_CAPACITY,
                YOUNG,
            ),
            axial_period: None,
        };
        let rmax = particles.radius.iter().cloned().fold(0.0, f64::max);
        let skin = 0.4 * rmax;
        let grid = CellGrid::new([-0.1; 3], [0.1; 3], 2.0 * rmax + skin);
        let neighbors = NeighborList::new(skin);
        Self {
            params,
            particles,
            neighbors,
            walls,
            pipeline: Pipeline::new(grid),
            counters: Counters::default(),
        }
    }

    /// This world as a section periodic along y, `length` long and centred on the origin
    /// (its grid spans exactly one period along y).
    pub fn periodic(mut self, length: f64) -> Self {
        let cell = self.pipeline.grid.cell_size;
        let half = 0.5 * length;
        self.pipeline = Pipeline::new(CellGrid::periodic_along_y(
            [-0.1, -half, -0.1],
            [0.1, half, 0.1],
            cell,
        ));
        self.params.axial_period = Some(AxialPeriod { length });
        self
    }

    pub fn step(&mut self) -> ContactCount {
        self.pipeline.step(
            &self.params,
            &mut self.particles,
            &mut self.neighbors,
            &self.walls,
            &mut self.counters,
        )
    }
}

pub fn no_walls() -> WallSet {
    WallSet {
        walls: Vec::new(),
        angular_velocity: 0.0,
        mantle_temperature: None,
    }
}

pub fn tdex() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_tdex"))
}

pub fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Runs tdex, asserting success; returns its stdout.
pub fn tdex_ok(args: &[&str]) -> String {
    let o = run_tdex(args);
    assert!(
        o.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8(o.stdout).unwrap()
}

/// The names of the files in `dir` (hidden ones included), sorted.
pub fn file_names(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Every file of `dir` by name, with its bytes.
pub fn files(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().into_owned(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect()
}

/// Whether python3 can `import modules`; if not, the test is skipped with a message, unless
/// TDEX_REQUIRE_PYTHON is set (CI installs `packages` and sets it, so that a test cannot pass
/// by skipping), when it fails.
pub fn python_with(modules: &str, packages: &str) -> bool {
    let ok = std::process::Command::new("python3")
        .args(["-c", &format!("import {modules}")])
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        assert!(
            std::env::var_os("TDEX_REQUIRE_PYTHON").is_none(),
            "python3 with {packages} is required (TDEX_REQUIRE_PYTHON is set)"
        );
        eprintln!("skipped: pip install {packages} to run it");
    }
    ok
}

pub fn run_tdex(args: &[&str]) -> Output {
    std::process::Command::new(tdex())
        .args(args)
        .output()
        .expect("tdex starts")
}

/// Runs `f` on a pool of `threads` workers.
pub fn with_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> R {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(f)
}

/// Byte offset of a recording's `tdex.costs` metadata record (its opcode byte and 8-byte
/// length stand before the name's 4-byte length): the bytes before it do not depend on
/// wall times.
pub fn costs_record_offset(file: &[u8]) -> usize {
    file.windows(10)
        .position(|w| w == b"tdex.costs")
        .expect("a costs record")
        - 13
}

/// Whether `liggghts` can run; CI installs it and sets TDEX_REQUIRE_LIGGGHTS so that the
/// LIGGGHTS test cannot pass by skipping.
pub fn liggghts_available() -> bool {
    let found = std::process::Command::new("sh")
        .args(["-c", "command -v liggghts"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        assert!(
            std::env::var_os("TDEX_REQUIRE_LIGGGHTS").is_none(),
            "liggghts is required (TDEX_REQUIRE_LIGGGHTS is set): apt-get install -y liggghts"
        );
        eprintln!("skipped: apt-get install -y liggghts to run it");
    }
    found
}

/// The extrapolated snapshots of the extrapolation at `path`, by index.
pub fn extrapolated(path: &Path) -> Vec<tdex_format::Snapshot> {
    tdex_format::ExtrapolationReader::open(path)
        .unwrap()
        .snapshots()
        .unwrap()
}
