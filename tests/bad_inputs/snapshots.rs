//! Bad snapshots: damaged, truncated, padded, of another format version, of another
//! scene, or saved after a divergence. Each is restored into a freshly built loaded block
//! and must be an `Err` whose message names the problem, never a panic, and must leave
//! the simulation able to restore the good snapshot afterwards.

use std::panic::{catch_unwind, AssertUnwindSafe};

use pcdc_compute::{Backend, Simulation, Table};
use pcdc_mech::{Boundary, LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Range};

/// A 1 m × 0.5 m elastic block on a fixed base, pressed from the top, under gravity;
/// `x0`: left edge (m), `young`: Young's modulus (Pa), `top`: whether the top is pressed.
fn block(x0: f64, young: f64, top: bool) -> Simulation<Dim2> {
    let mesh = builders::rectangle(x0, 0.0, 1.0, 0.5, 0.1).unwrap();
    let rock = LinearElastic::new(young, 0.25, 1000.0)
        .unwrap()
        .with_damping(0.1)
        .unwrap();
    let mut boundary = Boundary::new().fix(Range::group("bottom"));
    if top {
        let vel = Table::new("top velocity", &[(0.0, 0.0), (1e-3, -0.05)]).unwrap();
        boundary = boundary.velocity(Range::group("top"), [None, Some(vel.into()), None]);
    }
    Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(boundary)
        .gravity([0.0, -9.81, 0.0])
        .build()
        .unwrap()
}

fn standard() -> Simulation<Dim2> {
    block(0.0, 1e9, true)
}

/// The snapshot of the standard block after 100 steps.
fn good_snapshot() -> Vec<u8> {
    let mut sim = standard();
    sim.run(100).unwrap();
    sim.snapshot_bytes().unwrap()
}

/// Flips bit `bit` of byte `at`.
fn flip(mut b: Vec<u8>, at: usize, bit: u8) -> Vec<u8> {
    b[at] ^= 1 << bit;
    b
}

/// A snapshot of another scene (built by `make`) after 10 steps.
fn of(make: fn() -> Simulation<Dim2>) -> Vec<u8> {
    let mut sim = make();
    sim.run(10).unwrap();
    sim.snapshot_bytes().unwrap()
}

/// A snapshot saved right after the run diverged (time step far above the stable one).
fn after_divergence() -> Vec<u8> {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 0.5, 0.1).unwrap();
    let rock = LinearElastic::new(1e9, 0.25, 1000.0)
        .unwrap()
        .with_damping(0.1)
        .unwrap();
    let vel = Table::new("top velocity", &[(0.0, 0.0), (1e-3, -0.05)]).unwrap();
    let mut sim = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(
            Boundary::new()
                .fix(Range::group("bottom"))
                .velocity(Range::group("top"), [None, Some(vel.into()), None]),
        )
        .gravity([0.0, -9.81, 0.0])
        .time_step(1e-3)
        .build()
        .unwrap();
    assert!(sim.run(100_000).is_err(), "the run was meant to diverge");
    sim.snapshot_bytes().unwrap()
}

#[test]
fn bad_snapshots_are_named_errors() {
    let good = good_snapshot();
    let n = good.len();
    let mut legacy = vec![15u8];
    legacy.extend_from_slice(b"pcdc-snapshot-2");
    legacy.extend_from_slice(&[3, 0xb4, 0x01]);
    let mut future = good.clone();
    future[8..12].copy_from_slice(&7u32.to_le_bytes());
    let mut padded = good.clone();
    padded.extend_from_slice(&[0; 16]);
    let mut zero_crc = good.clone();
    zero_crc[12..16].fill(0);
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("empty file", Vec::new(), "truncated"),
        ("half a header", good[..10].to_vec(), "truncated"),
        (
            "a text file",
            b"time,u\n0,0\n1,2\n".repeat(3),
            "not a pcdc snapshot",
        ),
        ("version 2 file", legacy, "version 2"),
        ("future version", future, "version 7"),
        ("truncated payload", good[..n - 100].to_vec(), "truncated"),
        ("padded file", padded, "extra bytes"),
        (
            "bit flip in the state",
            flip(good.clone(), n / 2, 3),
            "checksum",
        ),
        (
            "bit flip in the length",
            flip(good.clone(), 23, 7),
            "truncated",
        ),
        (
            "bit flip in the magic",
            flip(good.clone(), 2, 5),
            "not a pcdc snapshot",
        ),
        ("zeroed checksum", zero_crc, "checksum"),
        (
            "mesh shifted, same counts",
            of(|| block(0.25, 1e9, true)),
            "different mesh",
        ),
        (
            "other Young's modulus",
            of(|| block(0.0, 2e9, true)),
            "physics 'mechanics'",
        ),
        (
            "other boundary",
            of(|| block(0.0, 1e9, false)),
            "physics 'mechanical boundary'",
        ),
        ("saved after a divergence", after_divergence(), "divergence"),
    ];
    for (what, bytes, expect) in cases {
        let mut sim = standard();
        let result = catch_unwind(AssertUnwindSafe(|| sim.restore_bytes(&bytes)))
            .unwrap_or_else(|_| panic!("{what}: restore panicked"));
        let msg = match result {
            Ok(()) => panic!("{what}: accepted"),
            Err(e) => e.to_string(),
        };
        assert!(
            msg.contains(expect),
            "{what}: '{msg}' does not name '{expect}'"
        );
        assert_eq!(sim.state.step, 0, "{what}: the simulation was changed");
        sim.restore_bytes(&good).unwrap();
        assert_eq!(sim.state.step, 100, "{what}");
    }
}

#[test]
fn bad_snapshot_files_are_named_errors() {
    let dir = std::env::temp_dir().join(format!("pcdc-bad-snap-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut sim = standard();
    // A missing file names its path.
    let missing = dir.join("missing.snap");
    let msg = sim.restore(&missing).unwrap_err().to_string();
    assert!(msg.contains("missing.snap"), "{msg}");
    // A snapshot of a 3D scene restored into a 2D one names both dimensions.
    let cube = builders::cuboid([0.0; 3], [0.2; 3], 0.1).unwrap();
    let rock = LinearElastic::new(1e9, 0.25, 1000.0).unwrap();
    let mut sim3 = Simulation::builder(cube, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .build()
        .unwrap();
    sim3.run(5).unwrap();
    let path = dir.join("cube.snap");
    sim3.save(&path).unwrap();
    let msg = sim.restore(&path).unwrap_err().to_string();
    assert!(msg.contains("3d") && msg.contains("2d"), "{msg}");
    std::fs::remove_dir_all(&dir).ok();
}
