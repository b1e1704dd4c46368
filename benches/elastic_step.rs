//! Elastic step throughput (element-steps per second) on the CPU backend, 1 thread and
//! all threads, for about 200k triangles (the standard benchmark block of
//! docs/design-targets.md, 0.05 x 0.10 m of right triangles, E = 30 GPa, nu = 0.25,
//! rho = 2600, bottom fixed in y, top pushed at 0.05 m/s; nodes are shared here because
//! the per-triangle nodes and joints of the full scene arrive with pcdc-cohesive) and
//! about 200k tetrahedra.
//!
//! GPU rows (when an adapter exists, f64 and f32): one iteration is `run(GPU_STEPS)`,
//! which includes one upload and one read-back of the state, so the rate is per
//! element-step with the transfers amortised over GPU_STEPS steps. On lavapipe (Mesa's
//! software Vulkan) these rows prove that the path works, not GPU speed.
//!
//! Mohr–Coulomb rows (`mc_*`): the same blocks with `pcdc_mech::MohrCoulomb` in two
//! states: `elastic` (strengths far above the stresses: the cost of the yield check) and
//! `yielding`: steady plastic flow, in which every element returns to the shear plane
//! in every step (see `sim_mc`: the block starts on the yield surface, in a general
//! principal frame, held by that same stress on all its faces and moving with the
//! homogeneous velocity field of the flow rule, so that each step's strain increment is
//! plastic). The flow is a mechanism and localises in the end (measured 2026-12-08: in
//! 2D 99 % of the triangles still yield in a step after 400 steps, 87 % after 800, 42 %
//! after 1 200; all the tetrahedra after 2 000), so the row restarts it from a snapshot
//! every `CYCLE` steps and runs `SETTLE` steps untimed after each restart; the share of
//! elements that return in the timed steps is printed when the row starts (2026-12-08:
//! 100 % of the triangles and of the tetrahedra in every one of them).
//! Earlier rows timed one step right after restoring a snapshot; the restore (serial,
//! ~20 ms, fresh allocations) made the next steps slower by itself (+6 ns per triangle
//! on one thread with no element yielding) and on a VM left the other vCPU parked
//! (docs/performance.md).
//!
//! Quad4/Hex8 rows (`quad4_*`, `hex8_*`): the same blocks meshed with Quad4 cells
//! (two triangles each, the triangles of the `tri3` row) and Hex8 cells (five or six
//! tetrahedra each) in the mixed discretisation (`pcdc_mech::mixed`: trace pass, element
//! pass, pressure pass); throughput in cell-steps/s, so a Quad4 row divided by the
//! `tri3` row's half gives the cost of the mixed passes.
//!
//! Run: `cargo bench --bench elastic_step`. Throughput is reported by criterion as
//! elements/s (= element-steps/s).

use std::time::{Duration, Instant};

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion, Throughput};
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_mech::mohr_coulomb::{state, MC_STATE};
use pcdc_mech::{
    principal, Boundary, ConstitutiveModel, FaceStress, LinearElastic, Mechanics, MohrCoulomb,
};
use pcdc_mesh::{builders, Dim, Mesh, Range};

/// Steps per measured GPU iteration.
const GPU_STEPS: u64 = 20;

fn sim<D: Dim>(mesh: Mesh<D>, backend: Backend, bottom: &str, top: &str) -> Simulation<D> {
    let rock = LinearElastic::new(30e9, 0.25, 2600.0).unwrap();
    sim_with(mesh, backend, boundary::<D>(bottom, top), rock, [0.0; 6])
}

/// Mohr–Coulomb: `yielding` or far from yield. Yielding: c = 1 MPa, φ = 30°, ψ = 5°,
/// σ_t = 0.5 MPa; the initial stress on the shear plane (σ1 = N_φ σ3 − 2c√N_φ, σ3 =
/// −8 MPa, σ2 = −10 MPa; in 2D σ2 is σ_zz, so that plane strain allows the flow) on
/// principal axes turned from the mesh's (30° about z in 2D; R_z(10°) R_y(20°) R_x(30°) in
/// 3D), the same stress as traction on every boundary face, and every node moving with
/// the homogeneous velocity v = L (x − x̄), L = 0.5 s⁻¹ R diag(−1, 0, N_ψ) Rᵀ over
/// (σ1, σ2, σ3): a pure plastic strain rate of the flow rule, so that each step's trial
/// lies outside the shear plane and returns to the same stress, everywhere in the block.
fn sim_mc<D: Dim>(
    mesh: Mesh<D>,
    backend: Backend,
    bottom: &str,
    top: &str,
    yielding: bool,
) -> Simulation<D> {
    let e = LinearElastic::new(30e9, 0.25, 2600.0).unwrap();
    if !yielding {
        let rock = MohrCoulomb::new(e, 1e9, 30.0, 5.0, 1e8).unwrap();
        return sim_with(mesh, backend, boundary::<D>(bottom, top), rock, [0.0; 6]);
    }
    let rock = MohrCoulomb::new(e, 1e6, 30.0, 5.0, 0.5e6).unwrap();
    let f = rock.surfaces();
    let (s2, s3) = (-10e6, -8e6);
    let s1 = f.n_phi * s3 - f.kc;
    // Values and flow on the turned axes (σ1, σ3, σ2 in 2D: σ2 on z).
    let (values, flow, deg, faces): ([f64; 3], [f64; 3], [f64; 3], &[&str]) = if D::D == 2 {
        (
            [s1, s3, s2],
            [-1.0, f.n_psi, 0.0],
            [0.0, 0.0, 30.0],
            &["left", "right", "bottom", "top"],
        )
    } else {
        (
            [s1, s2, s3],
            [-1.0, 0.0, f.n_psi],
            [30.0, 20.0, 10.0],
            &["xmin", "xmax", "ymin", "ymax", "zmin", "zmax"],
        )
    };
    let s0 = rotated(values, deg);
    let rate = rotated(flow.map(|x| 0.5 * x), deg);
    let mut traction = s0;
    if D::D == 2 {
        traction[2] = 0.0;
    }
    let mut b = Boundary::new();
    for name in faces {
        b = b.face_stress(Range::group(*name), FaceStress::tensor(traction));
    }
    let mut sim = sim_with(mesh, backend, b, rock, s0);
    let d = D::D;
    let n = sim.mesh().n_nodes();
    let mut centre = [0.0; 3];
    for i in 0..n {
        for (c, x) in centre.iter_mut().zip(sim.mesh().node(i)) {
            *c += x / n as f64;
        }
    }
    let l = [
        [rate[0], rate[3], rate[5]],
        [rate[3], rate[1], rate[4]],
        [rate[5], rate[4], rate[2]],
    ];
    for i in 0..n {
        let x: [f64; 3] = std::array::from_fn(|k| {
            if k < d {
                sim.mesh().node(i)[k] - centre[k]
            } else {
                0.0
            }
        });
        for (v, row) in sim.state.v[i * d..(i + 1) * d].iter_mut().zip(&l) {
            *v = row.iter().zip(&x).map(|(a, b)| a * b).sum();
        }
    }
    sim
}

/// The tensor R diag(`p`) Rᵀ (xx, yy, zz, xy, yz, xz) with R = R_z(γ) R_y(β) R_x(α)
/// for angles `deg` = [α, β, γ] in degrees (in 2D only γ, a turn in the x-y plane).
fn rotated(p: [f64; 3], deg: [f64; 3]) -> [f64; 6] {
    let [a, b, c] = deg.map(f64::to_radians);
    let rx = [
        [1.0, 0.0, 0.0],
        [0.0, a.cos(), -a.sin()],
        [0.0, a.sin(), a.cos()],
    ];
    let ry = [
        [b.cos(), 0.0, b.sin()],
        [0.0, 1.0, 0.0],
        [-b.sin(), 0.0, b.cos()],
    ];
    let rz = [
        [c.cos(), -c.sin(), 0.0],
        [c.sin(), c.cos(), 0.0],
        [0.0, 0.0, 1.0],
    ];
    let mul = |x: [[f64; 3]; 3], y: [[f64; 3]; 3]| -> [[f64; 3]; 3] {
        std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| x[i][k] * y[k][j]).sum()))
    };
    let r = mul(rz, mul(ry, rx));
    // The principal axes are R's columns.
    let axes = std::array::from_fn(|i| [r[0][i], r[1][i], r[2][i]]);
    principal::compose(&p, &axes)
}

/// Bottom held, top pushed at 0.05 m/s along y (2D) or z (3D).
fn boundary<D: Dim>(bottom: &str, top: &str) -> Boundary {
    let y = if D::D == 2 { 1 } else { 2 };
    let mut push = [None, None, None];
    push[y] = Some((-0.05).into());
    let mut hold = [None, None, None];
    hold[y] = Some(0.0.into());
    Boundary::new()
        .velocity(Range::group(bottom), hold)
        .velocity(Range::group(top), push)
}

fn sim_with<D: Dim>(
    mesh: Mesh<D>,
    backend: Backend,
    boundary: Boundary,
    rock: impl ConstitutiveModel + 'static,
    s0: [f64; 6],
) -> Simulation<D> {
    Simulation::builder(mesh, backend)
        .physics(
            Mechanics::new()
                .material(Range::All, rock)
                .initial_stress(Range::All, s0),
        )
        .physics(boundary)
        .build()
        .unwrap()
}

/// Steps of steady plastic flow between restarts of a yielding row.
const CYCLE: usize = 200;
/// Untimed steps after each restart.
const SETTLE: usize = 5;

/// The share (%) of elements that returned to the surface in the last step.
fn yielding_share<D: Dim>(sim: &Simulation<D>) -> f64 {
    let st = sim.field("model_state").unwrap();
    let yielding = st
        .chunks_exact(MC_STATE)
        .filter(|s| s[state::SHEAR_NOW] != 0.0 || s[state::TENSION_NOW] != 0.0)
        .count();
    100.0 * yielding as f64 / (st.len() / MC_STATE) as f64
}

/// A Mohr–Coulomb row: steps run on after 20, or for `yielding` the steps of the steady
/// plastic flow (restarted every [`CYCLE`] steps, [`SETTLE`] untimed after a restart).
fn bench_mc<D: Dim>(
    g: &mut BenchmarkGroup<'_, WallTime>,
    name: &str,
    mut sim: Simulation<D>,
    yielding: bool,
) {
    g.throughput(Throughput::Elements(sim.mesh().n_elements() as u64));
    if !yielding {
        sim.run(20).unwrap();
        g.bench_function(name, |b| b.iter(|| sim.step().unwrap()));
        return;
    }
    let start = sim.snapshot_bytes().unwrap();
    // The share of elements that return in the steps the row times, to see that it
    // times what it says.
    sim.run(SETTLE as u64).unwrap();
    let (mut least, mut sum) = (f64::MAX, 0.0);
    for _ in SETTLE..CYCLE {
        sim.step().unwrap();
        let share = yielding_share(&sim);
        least = least.min(share);
        sum += share;
    }
    eprintln!(
        "{name}: {:.2} % of the elements return in a timed step on average, {least:.2} % at least",
        sum / (CYCLE - SETTLE) as f64
    );
    let mut since = CYCLE;
    g.bench_function(name, |b| {
        b.iter_custom(|iters| {
            let mut timed = Duration::ZERO;
            for _ in 0..iters {
                if since == CYCLE {
                    sim.restore_bytes(&start).unwrap();
                    sim.run(SETTLE as u64).unwrap();
                    since = SETTLE;
                }
                let t0 = Instant::now();
                sim.step().unwrap();
                timed += t0.elapsed();
                since += 1;
            }
            timed
        })
    });
}

fn bench(c: &mut Criterion) {
    let all = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    let mut threads = vec![1];
    if all > 1 {
        threads.push(all);
    }
    let mut g = c.benchmark_group("elastic_step");
    g.sample_size(10);
    g.measurement_time(std::time::Duration::from_secs(8));
    // 2D: 0.05 x 0.10 m, h = 0.05/224 -> 224 x 448 cells x 2 = 200 704 triangles.
    let tri = builders::rectangle(0.0, 0.0, 0.05, 0.10, 0.05 / 224.0).unwrap();
    // 3D: cubes of 0.05/26 m, 6 tetrahedra each: 206 856 tetrahedra.
    let tet = builders::cuboid([0.0; 3], [0.05, 0.05, 0.0962], 0.05 / 26.0).unwrap();
    // The same blocks in Quad4 (100 352 cells) and Hex8 (33 800 cells).
    let quad = builders::rectangle_quads(0.0, 0.0, 0.05, 0.10, 0.05 / 224.0).unwrap();
    let hex = builders::cuboid_hexes([0.0; 3], [0.05, 0.05, 0.0962], 0.05 / 26.0).unwrap();
    for &t in &threads {
        let mut s = sim(quad.clone(), Backend::cpu(t).unwrap(), "bottom", "top");
        g.throughput(Throughput::Elements(s.mesh().n_cells() as u64));
        g.bench_function(
            format!("quad4_{}k_cells_threads_{t}", s.mesh().n_cells() / 1000),
            |b| b.iter(|| s.step().unwrap()),
        );
        let mut s = sim(hex.clone(), Backend::cpu(t).unwrap(), "zmin", "zmax");
        g.throughput(Throughput::Elements(s.mesh().n_cells() as u64));
        g.bench_function(
            format!("hex8_{}k_cells_threads_{t}", s.mesh().n_cells() / 1000),
            |b| b.iter(|| s.step().unwrap()),
        );
        let mut s2 = sim(tri.clone(), Backend::cpu(t).unwrap(), "bottom", "top");
        g.throughput(Throughput::Elements(s2.mesh().n_elements() as u64));
        g.bench_function(
            format!("tri3_{}k_threads_{t}", s2.mesh().n_elements() / 1000),
            |b| b.iter(|| s2.step().unwrap()),
        );
        let mut s3 = sim(tet.clone(), Backend::cpu(t).unwrap(), "zmin", "zmax");
        g.throughput(Throughput::Elements(s3.mesh().n_elements() as u64));
        g.bench_function(
            format!("tet4_{}k_threads_{t}", s3.mesh().n_elements() / 1000),
            |b| b.iter(|| s3.step().unwrap()),
        );
        for yielding in [false, true] {
            let state = if yielding { "yielding" } else { "elastic" };
            let m2 = sim_mc(
                tri.clone(),
                Backend::cpu(t).unwrap(),
                "bottom",
                "top",
                yielding,
            );
            let name = format!(
                "mc_tri3_{}k_{state}_threads_{t}",
                m2.mesh().n_elements() / 1000
            );
            bench_mc(&mut g, &name, m2, yielding);
            let m3 = sim_mc(
                tet.clone(),
                Backend::cpu(t).unwrap(),
                "zmin",
                "zmax",
                yielding,
            );
            let name = format!(
                "mc_tet4_{}k_{state}_threads_{t}",
                m3.mesh().n_elements() / 1000
            );
            bench_mc(&mut g, &name, m3, yielding);
        }
    }
    for p in [Precision::F64, Precision::F32] {
        let gpu = match Backend::gpu(Some(p)) {
            Ok(b) => b,
            Err(e) => {
                eprintln!("no GPU rows in {}: {e}", p.name());
                continue;
            }
        };
        let name = if gpu.as_gpu().expect("a GPU backend").is_software() {
            "lavapipe"
        } else {
            "gpu"
        };
        g.throughput(Throughput::Elements(tri.n_elements() as u64 * GPU_STEPS));
        let mut s2 = sim(tri.clone(), gpu.clone(), "bottom", "top");
        let per = |b: Option<u64>, n: usize| b.unwrap_or(0) as f64 / n as f64;
        eprintln!(
            "{} {}: {:.0} bytes per element-step (Tri3), adapter {}",
            name,
            p.name(),
            per(s2.gpu_bytes_per_step(), tri.n_elements()),
            gpu.as_gpu().expect("a GPU backend").adapter_name()
        );
        g.bench_function(
            format!("tri3_{}k_{name}_{}", tri.n_elements() / 1000, p.name()),
            |b| b.iter(|| s2.run(GPU_STEPS).unwrap()),
        );
        g.throughput(Throughput::Elements(tet.n_elements() as u64 * GPU_STEPS));
        let mut s3 = sim(tet.clone(), gpu.clone(), "zmin", "zmax");
        eprintln!(
            "{} {}: {:.0} bytes per element-step (Tet4)",
            name,
            p.name(),
            per(s3.gpu_bytes_per_step(), tet.n_elements())
        );
        g.bench_function(
            format!("tet4_{}k_{name}_{}", tet.n_elements() / 1000, p.name()),
            |b| b.iter(|| s3.run(GPU_STEPS).unwrap()),
        );
        g.throughput(Throughput::Elements(quad.n_cells() as u64 * GPU_STEPS));
        let mut q = sim(quad.clone(), gpu.clone(), "bottom", "top");
        g.bench_function(
            format!("quad4_{}k_cells_{name}_{}", quad.n_cells() / 1000, p.name()),
            |b| b.iter(|| q.run(GPU_STEPS).unwrap()),
        );
        g.throughput(Throughput::Elements(hex.n_cells() as u64 * GPU_STEPS));
        let mut h = sim(hex.clone(), gpu.clone(), "zmin", "zmax");
        g.bench_function(
            format!("hex8_{}k_cells_{name}_{}", hex.n_cells() / 1000, p.name()),
            |b| b.iter(|| h.run(GPU_STEPS).unwrap()),
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
