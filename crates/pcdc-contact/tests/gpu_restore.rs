//! The whole contact state (candidate lists, counts, reference positions and the pair
//! histories of the friction and damping law) lives in fields, so a snapshot holds it on
//! both backends:
//!
//! - a GPU run restored from its snapshot into a fresh GPU simulation continues bit for
//!   bit the uninterrupted GPU run: every displacement, velocity and field (pair
//!   histories included), with the friction history non-zero at the snapshot;
//! - the same on the CPU;
//! - after sliding contact the history fields of the GPU (f64) match the CPU's within
//!   1e-12 relative (lists and counts exactly);
//! - snapshots cross backends: a CPU snapshot continued on the GPU and a GPU snapshot
//!   continued on the CPU both match the uninterrupted CPU run within the parity bar.
//!
//! The scene: two elastic blocks, the left one moving obliquely and spinning, collide
//! with Coulomb friction and contact damping (as in the parity tests); the snapshot is
//! taken while they slide on each other. Without a GPU adapter the GPU tests skip (and
//! fail with PCDC_REQUIRE_GPU=1).

use pcdc_compute::gpu::gpu_test_backend;
use pcdc_compute::{Backend, Precision, Simulation};
use pcdc_contact::{
    Contact, CONTACT_CANDIDATES, CONTACT_CANDIDATE_COUNT, CONTACT_HISTORY, CONTACT_REFERENCE,
};
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Range};

const E: f64 = 1e9;

/// Two blocks 2 mm apart; the left one moves at (2, 0.5) m/s and spins at 20 rad/s.
fn impact(backend: Backend) -> Simulation<Dim2> {
    impact_with_size(backend, 0.02)
}

/// [`impact`] with element size `h` (m).
fn impact_with_size(backend: Backend, h: f64) -> Simulation<Dim2> {
    let a = builders::rectangle(0.0, 0.0, 0.1, 0.1, h).unwrap();
    let b = builders::rectangle(0.102, 0.03, 0.1, 0.1, h).unwrap();
    let mesh = builders::union(&[&a, &b]).unwrap().0;
    let rock = LinearElastic::new(E, 0.25, 1000.0).unwrap();
    let contact = Contact::new(10.0 * E)
        .friction(30.0, 50.0 * E)
        .damping(2e6, 2.0);
    let mut sim = Simulation::builder(mesh, backend)
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(contact)
        .build()
        .unwrap();
    let x = sim.mesh().coords().to_vec();
    for n in 0..sim.mesh().n_nodes() {
        if x[2 * n] < 0.101 {
            let (rx, ry) = (x[2 * n] - 0.05, x[2 * n + 1] - 0.05);
            sim.state.v[2 * n] = 2.0 - 20.0 * ry;
            sim.state.v[2 * n + 1] = 0.5 + 20.0 * rx;
        }
    }
    sim
}

/// Steps to the snapshot (1 ms: the blocks touch from 0.84 to 1.21 ms, the spinning
/// block's corner sliding) and after it (0.5 ms, through the separation).
fn steps(sim: &Simulation<Dim2>) -> (u64, u64) {
    let n = (1e-3 / sim.dt()).ceil() as u64;
    (n, n / 2)
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Every displacement, velocity and field of `a` and `b` are the same bits.
fn assert_same_state(what: &str, a: &Simulation<Dim2>, b: &Simulation<Dim2>) {
    assert_eq!(a.state.step, b.state.step, "{what}: step");
    assert!(same_bits(&a.state.u, &b.state.u), "{what}: u");
    assert!(same_bits(&a.state.v, &b.state.v), "{what}: v");
    for spec in a.state.fields.specs() {
        let (x, y) = (a.field(&spec.name).unwrap(), b.field(&spec.name).unwrap());
        assert!(same_bits(x, y), "{what}: field {}", spec.name);
    }
}

/// Pairs in contact with a non-zero accumulated slip (history value 0 of each pair).
fn slipping_pairs(sim: &Simulation<Dim2>) -> usize {
    let hist = sim.field(CONTACT_HISTORY).unwrap();
    let count = sim.field(CONTACT_CANDIDATE_COUNT).unwrap();
    let cap = sim.field(CONTACT_CANDIDATES).unwrap().len() / count.len();
    let s = hist.len() / count.len() / cap;
    (0..count.len())
        .map(|e| {
            (0..count[e] as usize)
                .filter(|&k| hist[(e * cap + k) * s] != 0.0)
                .count()
        })
        .sum()
}

/// Runs to the snapshot, saves, continues (A); restores into a fresh simulation on the
/// same backend and continues (B); A and B must be the same bits.
fn restore_continues_bit_for_bit(backend: Backend, what: &str) {
    let mut a = impact(backend.clone());
    let (n, m) = steps(&a);
    a.run(n).unwrap();
    let slipping = slipping_pairs(&a);
    println!("{what}: {slipping} pairs with a non-zero slip at the snapshot (step {n})");
    assert!(slipping > 0, "{what}: no friction history to restore");
    let snap = a.snapshot_bytes().unwrap();
    a.run(m).unwrap();
    let mut b = impact(backend);
    b.restore_bytes(&snap).unwrap();
    b.run(m).unwrap();
    assert_same_state(what, &a, &b);
    // The history mattered: restored without it, the run differs.
    let mut c = impact(b.backend().clone());
    c.restore_bytes(&snap).unwrap();
    let id = c.state.fields.id(CONTACT_HISTORY).unwrap();
    c.state.fields.get_mut(id).fill(0.0);
    c.run(m).unwrap();
    assert!(
        !same_bits(&a.state.u, &c.state.u),
        "{what}: history had no effect"
    );
}

#[test]
fn gpu_contact_restore_continues_bit_for_bit() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    restore_continues_bit_for_bit(gpu, "GPU f64");
}

#[test]
fn cpu_contact_restore_continues_bit_for_bit() {
    restore_continues_bit_for_bit(Backend::cpu(2).unwrap(), "CPU");
}

/// max |a - b| / max |a| over the entries `k` with `k % stride == s` (one history value
/// kind: slip or stress).
fn rel_diff(a: &[f64], b: &[f64], stride: usize, s: usize) -> f64 {
    let (mut d, mut m) = (0.0f64, 0.0f64);
    for k in (s..a.len()).step_by(stride) {
        d = d.max((a[k] - b[k]).abs());
        m = m.max(a[k].abs());
    }
    if m == 0.0 {
        d
    } else {
        d / m
    }
}

#[test]
fn gpu_history_fields_match_cpu_f64() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let mut cpu = impact(Backend::cpu(1).unwrap());
    let mut dev = impact(gpu);
    let (n, _) = steps(&cpu);
    cpu.run(n).unwrap();
    dev.run(n).unwrap();
    assert!(slipping_pairs(&cpu) > 0);
    for exact in [CONTACT_CANDIDATE_COUNT, CONTACT_CANDIDATES] {
        assert!(
            same_bits(cpu.field(exact).unwrap(), dev.field(exact).unwrap()),
            "{exact}"
        );
    }
    let (hc, hg) = (
        cpu.field(CONTACT_HISTORY).unwrap(),
        dev.field(CONTACT_HISTORY).unwrap(),
    );
    let ne = cpu.mesh().n_elements();
    let cap = cpu.field(CONTACT_CANDIDATES).unwrap().len() / ne;
    let stride = hc.len() / ne / cap;
    for s in 0..stride {
        let d = rel_diff(hc, hg, stride, s);
        println!("history value {s}: max |gpu - cpu| / max |cpu| = {d:.2e}");
        assert!(d <= 1e-12, "history value {s}: {d:e}");
    }
    let d = rel_diff(
        cpu.field(CONTACT_REFERENCE).unwrap(),
        dev.field(CONTACT_REFERENCE).unwrap(),
        1,
        0,
    );
    assert!(d <= 1e-12, "reference positions: {d:e}");
}

#[test]
fn snapshots_cross_backends() {
    let Some(gpu) = gpu_test_backend(Some(Precision::F64)) else {
        return;
    };
    let cpu = Backend::cpu(1).unwrap();
    let mut reference = impact(cpu.clone());
    let (n, m) = steps(&reference);
    reference.run(n).unwrap();
    let cpu_snap = reference.snapshot_bytes().unwrap();
    reference.run(m).unwrap();
    let mut on_gpu = impact(gpu.clone());
    on_gpu.run(n).unwrap();
    let gpu_snap = on_gpu.snapshot_bytes().unwrap();
    let bar = |a: &[f64], b: &[f64]| {
        let m = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        a.iter()
            .zip(b)
            .fold(0.0f64, |d, (x, y)| d.max((x - y).abs()))
            / m
    };
    for (what, snap, backend) in [
        ("CPU snapshot on the GPU", &cpu_snap, gpu),
        ("GPU snapshot on the CPU", &gpu_snap, cpu),
    ] {
        let mut sim = impact(backend);
        sim.restore_bytes(snap).unwrap();
        sim.run(m).unwrap();
        let (du, dv) = (
            bar(&reference.state.u, &sim.state.u),
            bar(&reference.state.v, &sim.state.v),
        );
        println!("{what}: max|du|/max|u| = {du:.2e}, max|dv|/max|v| = {dv:.2e}");
        assert!(du <= 1e-12 && dv <= 1e-11, "{what}: du {du:e}, dv {dv:e}");
    }
}

/// The CPU evaluates each pair once, from its lower-index element, and copies a changed
/// history into the other element's row: after sliding contact every pair's two copies
/// are the same bits (the GPU keeps both by evaluating from both sides), and 1 and 2
/// threads give the same state (on a mesh of several blocks of the pair pass).
#[test]
fn cpu_pair_histories_agree_and_threads_match() {
    let mut one = impact_with_size(Backend::cpu(1).unwrap(), 0.005);
    let mut two = impact_with_size(Backend::cpu(2).unwrap(), 0.005);
    assert!(one.mesh().n_elements() > 1000);
    let (n, _) = steps(&one);
    one.run(n).unwrap();
    two.run(n).unwrap();
    assert_same_state("1 vs 2 threads", &one, &two);
    let hist = one.field(CONTACT_HISTORY).unwrap();
    let count = one.field(CONTACT_CANDIDATE_COUNT).unwrap();
    let cand = one.field(CONTACT_CANDIDATES).unwrap();
    let ne = count.len();
    let cap = cand.len() / ne;
    let s = hist.len() / ne / cap;
    let row = |e: usize| &cand[e * cap..e * cap + count[e] as usize];
    let (mut pairs, mut nonzero) = (0, 0);
    for e in 0..ne {
        for (k, &f) in row(e).iter().enumerate() {
            let f = f as usize;
            let j = row(f)
                .iter()
                .position(|&x| x as usize == e)
                .expect("candidate lists are symmetric");
            let (a, b) = (
                &hist[(e * cap + k) * s..(e * cap + k + 1) * s],
                &hist[(f * cap + j) * s..(f * cap + j + 1) * s],
            );
            assert!(same_bits(a, b), "pair ({e}, {f}): {a:?} vs {b:?}");
            pairs += 1;
            nonzero += a.iter().any(|&x| x != 0.0) as usize;
        }
    }
    assert!(nonzero > 0, "no history to compare among {pairs} entries");
}
