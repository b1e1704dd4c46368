//! Snapshots of a fracturing FDEM scene with contact are never trusted blindly: single-bit
//! flips spread over the whole file and truncations at many lengths are all errors,
//! never panics; snapshots forged with a valid checksum (saved from a simulation whose
//! contact fields were edited) with out-of-range, non-integer, self or unordered
//! candidates, a count above the capacity, an unmirrored list or a history value past a
//! list are errors naming the contact state; a snapshot of another mesh with the same
//! counts, or of another physics composition, is refused by name; and after all that the
//! simulation still restores the real snapshot and continues bit for bit.
//!
//! The scene: an FDEM block (every triangle with its own nodes, cohesive joints between
//! them, declared as bonded pairs) hits a second block hard enough that joints break and
//! their faces become contact faces (as in the GPU parity tests, on the CPU).

use std::panic::{catch_unwind, AssertUnwindSafe};

use pcdc_cohesive::{CohesiveJoints, IntrinsicCzmParams, BROKEN_FACE};
use pcdc_compute::{Backend, ComputeError, Simulation};
use pcdc_contact::{Contact, CONTACT_CANDIDATES, CONTACT_CANDIDATE_COUNT, CONTACT_HISTORY};
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, split_nodes, Dim2, Range};

const E: f64 = 1e9;

/// The scene with the struck block's left edge at `x_struck` (0.061 m) and contact
/// friction `friction` (degrees).
fn fdem(x_struck: f64, friction: f64) -> Simulation<Dim2> {
    let a = builders::rectangle(0.0, 0.0, 0.06, 0.06, 0.01).unwrap();
    let b = builders::rectangle(x_struck, -0.02, 0.04, 0.1, 0.01).unwrap();
    let mesh = builders::union(&[&a, &b]).unwrap().0;
    let split = split_nodes(&mesh, &Range::rect(-1.0, -1.0, 0.0605, 1.0)).unwrap();
    let czm = IntrinsicCzmParams {
        friction_deg: 30.0,
        cohesion: 4e6,
        tensile_strength: 2e6,
        gf1: 0.01,
        gf2: 0.1,
        penalty_open: 10.0 * E,
        penalty_shear: 10.0 * E,
        penalty_overlap: 10.0 * E,
    }
    .build()
    .unwrap();
    let contact = Contact::new(10.0 * E)
        .friction(friction, 10.0 * E)
        .bonded_interfaces(BROKEN_FACE);
    let rock = LinearElastic::new(E, 0.25, 1000.0).unwrap();
    let mut sim = Simulation::builder(split.clone(), Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(CohesiveJoints::new().model(Range::All, czm))
        .physics(contact)
        .build()
        .unwrap();
    let x = sim.mesh().coords().to_vec();
    for n in 0..sim.mesh().n_nodes() {
        if x[2 * n] < 0.0605 {
            sim.state.v[2 * n] = 3.0;
        }
    }
    sim
}

fn scene() -> Simulation<Dim2> {
    fdem(0.061, 20.0)
}

/// Steps to the snapshot (1 ms: joints have broken) and after it.
fn steps(sim: &Simulation<Dim2>) -> u64 {
    (1e-3 / sim.dt()).ceil() as u64
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Restores `bytes` into `sim`, catching panics: `Some(result)`, or `None` on a panic.
fn try_restore(sim: &mut Simulation<Dim2>, bytes: &[u8]) -> Option<Result<(), ComputeError>> {
    catch_unwind(AssertUnwindSafe(|| sim.restore_bytes(bytes))).ok()
}

/// A snapshot forged with a valid checksum: `snap` restored into a fresh scene, its
/// contact fields edited by `edit(count, candidates, history, capacity)` on the first
/// element with at least two candidates (passed as `e`), and saved again.
fn forged(snap: &[u8], edit: impl Fn(usize, &mut [f64], &mut [f64], &mut [f64], usize)) -> Vec<u8> {
    let mut c = scene();
    c.restore_bytes(snap).unwrap();
    let f = &mut c.state.fields;
    let ids = [
        f.id(CONTACT_CANDIDATE_COUNT).unwrap(),
        f.id(CONTACT_CANDIDATES).unwrap(),
        f.id(CONTACT_HISTORY).unwrap(),
    ];
    let cap = f.spec(ids[1]).components;
    let [count, cand, hist] = f.get_many_mut(ids);
    let e = count
        .iter()
        .position(|&n| n >= 2.0)
        .expect("an element with two candidates");
    edit(e, count, cand, hist, cap);
    c.snapshot_bytes().unwrap()
}

#[test]
fn fracturing_snapshot_fuzz() {
    let mut a = scene();
    let n = steps(&a);
    a.run(n).unwrap();
    let broken = a
        .field(BROKEN_FACE)
        .unwrap()
        .iter()
        .filter(|&&f| f != 0.0)
        .count();
    assert!(
        broken > 0,
        "no joint broke: the snapshot would not be of a fracturing scene"
    );
    let snap = a.snapshot_bytes().unwrap();
    a.run(n).unwrap();

    let mut b = scene();
    let ne = b.mesh().n_elements();
    assert!(ne >= 100, "{ne} elements");
    // Single-bit flips: every bit of the 24-byte header, and 400 bits spread over the
    // file by a multiplicative (Knuth) sequence.
    let bits = snap.len() * 8;
    let positions: Vec<usize> = (0..24 * 8)
        .chain((0..400u64).map(|i| ((i * 2_654_435_761) % bits as u64) as usize))
        .collect();
    let (mut errors, mut accepted, mut panics) = (0, 0, 0);
    for &bit in &positions {
        let mut bad = snap.clone();
        bad[bit / 8] ^= 1 << (bit % 8);
        match try_restore(&mut b, &bad) {
            Some(Err(_)) => errors += 1,
            Some(Ok(())) => accepted += 1,
            None => panics += 1,
        }
    }
    // Truncations at 60 lengths spread over the file, and every length of the header.
    let lengths: Vec<usize> = (0..=24)
        .chain((0..60).map(|i| i * snap.len() / 60))
        .collect();
    let (mut t_errors, mut t_other) = (0, 0);
    for &len in &lengths {
        match try_restore(&mut b, &snap[..len]) {
            Some(Err(_)) => t_errors += 1,
            _ => t_other += 1,
        }
    }
    println!(
        "snapshot {} bytes, {ne} elements, {broken} broken faces: {} flips -> {errors} errors, \
         {accepted} accepted, {panics} panics; {} truncations -> {t_errors} errors, {t_other} other",
        snap.len(),
        positions.len(),
        lengths.len()
    );
    assert_eq!((accepted, panics), (0, 0));
    assert_eq!(errors, positions.len());
    assert_eq!((t_errors, t_other), (lengths.len(), 0));

    // Forged with a valid checksum: a candidate out of range, not an integer, the
    // element itself, two candidates out of order, a count above the capacity, a list
    // that its partner does not mirror, and a history value past the list.
    type Edit = fn(usize, &mut [f64], &mut [f64], &mut [f64], usize);
    let edits: [(&str, Edit); 7] = [
        ("out of range", |e, _, c, _, cap| c[e * cap] = 1e9),
        ("out of range", |e, _, c, _, cap| c[e * cap] += 0.5),
        ("itself", |e, _, c, _, cap| c[e * cap] = e as f64),
        ("order", |e, _, c, _, cap| c.swap(e * cap, e * cap + 1)),
        ("count", |e, n, _, _, cap| n[e] = cap as f64 + 1.0),
        ("does not list", |e, n, c, h, cap| {
            // Drop the element's last candidate (and its history) from its list only.
            let (m, s) = (n[e] as usize, h.len() / n.len() / cap);
            c[e * cap + m - 1] = 0.0;
            h[(e * cap + m - 1) * s..(e * cap + m) * s].fill(0.0);
            n[e] -= 1.0;
        }),
        ("past its", |e, n, _, h, cap| {
            let s = h.len() / n.len() / cap;
            h[(e * cap + n[e] as usize) * s] = 1.0;
        }),
    ];
    for (what, edit) in edits {
        let bad = forged(&snap, edit);
        let e = try_restore(&mut b, &bad)
            .unwrap_or_else(|| panic!("{what}: panic"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("contact state") && e.contains(what),
            "{what}: {e}"
        );
    }

    // The simulation is untouched by every refused snapshot: restoring the real one and
    // continuing equals the uninterrupted run bit for bit.
    b.restore_bytes(&snap).unwrap();
    b.run(n).unwrap();
    assert!(same_bits(&a.state.u, &b.state.u));
    assert!(same_bits(&a.state.v, &b.state.v));
}

#[test]
fn foreign_fracturing_snapshots_are_refused() {
    let mut a = scene();
    a.run(50).unwrap();
    let snap = a.snapshot_bytes().unwrap();
    // The struck block 1 mm further right: same counts, other coordinates.
    let mut shifted = fdem(0.062, 20.0);
    assert_eq!(shifted.mesh().n_nodes(), a.mesh().n_nodes());
    let e = shifted.restore_bytes(&snap).unwrap_err().to_string();
    assert!(e.contains("different mesh"), "{e}");
    // Another friction angle.
    let mut other = fdem(0.061, 30.0);
    let e = other.restore_bytes(&snap).unwrap_err().to_string();
    assert!(e.contains("physics 'contact'"), "{e}");
    // Another composition: no contact.
    let mesh = a.mesh().clone();
    let rock = LinearElastic::new(E, 0.25, 1000.0).unwrap();
    let mut plain = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .build()
        .unwrap();
    let e = plain.restore_bytes(&snap).unwrap_err().to_string();
    assert!(e.contains("composes the physics"), "{e}");
}
