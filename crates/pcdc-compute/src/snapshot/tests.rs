//! Snapshot header, checksum, fingerprints and value checks on a small scene of node
//! springs (every bit flip and every truncation of its snapshot is an error), plus
//! forged snapshots whose checksum is valid but whose content is not.

use pcdc_mesh::{builders, Dim2, Mesh};

use super::*;
use crate::{
    Backend, Components, FieldKey, FieldUse, ForceContext, InitContext, Kinematics, Physics, Place,
    StableStep,
};

const SPRING_ENERGY: FieldKey =
    FieldKey::new("spring_energy", Place::Element, Components::Fixed(1));

/// Every node is tied to its rest position by a spring `k` and carries a mass `rho`;
/// keeps a counter outside the fields (its `save_state`) that refuses a state of the
/// wrong length.
struct Springs {
    k: f64,
    rho: f64,
    hook: bool,
    counter: u64,
    /// Whether this instance owns the energy field (a second instance writes it).
    owner: bool,
}

impl Springs {
    fn new(k: f64, rho: f64) -> Self {
        Springs {
            k,
            rho,
            hook: true,
            counter: 0,
            owner: true,
        }
    }
}

impl Physics<Dim2> for Springs {
    fn name(&self) -> &str {
        "springs"
    }
    fn fields(&self, _mesh: &Mesh<Dim2>) -> Vec<FieldUse> {
        if self.owner {
            vec![SPRING_ENERGY.own::<Dim2>()]
        } else {
            vec![SPRING_ENERGY.write::<Dim2>()]
        }
    }
    fn init(&mut self, ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
        let nodes: Vec<u32> = (0..ctx.mesh.n_nodes() as u32).collect();
        ctx.register_slots(&nodes)?;
        Ok(())
    }
    fn add_mass(
        &self,
        _mesh: &Mesh<Dim2>,
        _fields: &crate::FieldStore,
        mass: &mut [f64],
        _scale: Option<f64>,
    ) {
        mass.iter_mut().for_each(|m| *m += self.rho);
    }
    fn stable_step(
        &self,
        kin: &Kinematics<'_, Dim2>,
        _fields: &crate::FieldStore,
    ) -> Option<StableStep> {
        Some(StableStep {
            dt: 2.0 * (kin.mass[0] / self.k).sqrt(),
            entity: crate::Entity::new(crate::EntityKind::Node, 0),
            physics: "springs".into(),
        })
    }
    fn compute_forces(&mut self, ctx: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
        for (s, u) in ctx.slots.iter_mut().zip(ctx.kin.u) {
            *s = -self.k * u;
        }
        Ok(())
    }
    fn save_state(&self) -> Result<Vec<u8>, ComputeError> {
        Ok(self.counter.to_le_bytes().to_vec())
    }
    fn restore_state(&mut self, bytes: &[u8]) -> Result<(), ComputeError> {
        let b: [u8; 8] = bytes
            .try_into()
            .map_err(|_| corrupt("springs state is not 8 bytes"))?;
        self.counter = u64::from_le_bytes(b);
        Ok(())
    }
    fn fingerprint(&self) -> u64 {
        if self.hook {
            Fingerprint::new().f64(self.k).f64(self.rho).finish()
        } else {
            0
        }
    }
}

fn cpu() -> Backend {
    Backend::cpu(1).unwrap()
}

fn scene_with(mesh: Mesh<Dim2>, springs: Springs) -> Simulation<Dim2> {
    let mut sim = Simulation::builder(mesh, cpu())
        .physics(springs)
        .build()
        .unwrap();
    for (i, v) in sim.state.v.iter_mut().enumerate() {
        *v = 0.01 * (i as f64 * 0.618).fract();
    }
    sim
}

fn scene() -> Simulation<Dim2> {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    scene_with(mesh, Springs::new(1e3, 1.0))
}

fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// Decodes a snapshot (its checksum must be right).
fn decode(bytes: &[u8]) -> Payload {
    postcard::from_bytes(open(bytes).unwrap()).unwrap()
}

/// Re-encodes a (modified) payload with a valid header and checksum.
fn forge(p: &Payload) -> Vec<u8> {
    let r = PayloadRef {
        dim: &p.dim,
        n_nodes: p.n_nodes,
        n_elements: p.n_elements,
        mesh: p.mesh,
        physics: p.physics.clone(),
        physics_params: p.physics_params.clone(),
        layout: p.layout,
        dt: p.dt,
        state: &p.state,
        physics_state: p.physics_state.clone(),
    };
    seal(&postcard::to_stdvec(&r).unwrap())
}

#[test]
fn header_layout_is_as_documented() {
    let mut sim = scene();
    sim.run(5).unwrap();
    let b = sim.snapshot_bytes().unwrap();
    assert_eq!(&b[..8], b"PCDCSNAP");
    assert_eq!(le_u32(&b, 8), SNAPSHOT_VERSION);
    assert_eq!(le_u32(&b, 12), crc32fast::hash(&b[16..]));
    let len = u64::from_le_bytes(b[16..24].try_into().unwrap());
    assert_eq!(len as usize, b.len() - SNAPSHOT_HEADER_LEN);
}

#[test]
fn restore_continues_bit_for_bit() {
    let mut a = scene();
    a.run(20).unwrap();
    let snap = a.snapshot_bytes().unwrap();
    a.run(20).unwrap();
    let mut b = scene();
    b.restore_bytes(&snap).unwrap();
    assert_eq!(b.state.step, 20);
    b.run(20).unwrap();
    assert!(same_bits(&a.state.u, &b.state.u));
    assert!(same_bits(&a.state.v, &b.state.v));
    assert_eq!(a.state.time.to_bits(), b.state.time.to_bits());
}

/// Every single-bit flip and every truncation of the whole file is an error, and the
/// simulation it was restored into is untouched.
#[test]
fn every_bit_flip_and_truncation_is_an_error() {
    let mut a = scene();
    a.run(7).unwrap();
    let snap = a.snapshot_bytes().unwrap();
    let mut b = scene();
    b.run(3).unwrap();
    let (u0, v0, step0) = (b.state.u.clone(), b.state.v.clone(), b.state.step);
    let mut flips = 0;
    for bit in 0..snap.len() * 8 {
        let mut bad = snap.clone();
        bad[bit / 8] ^= 1 << (bit % 8);
        assert!(b.restore_bytes(&bad).is_err(), "flip of bit {bit} accepted");
        flips += 1;
    }
    for len in 0..snap.len() {
        assert!(
            b.restore_bytes(&snap[..len]).is_err(),
            "truncation to {len}"
        );
    }
    let mut longer = snap.clone();
    longer.push(0);
    assert!(b.restore_bytes(&longer).is_err());
    assert!(flips > 1000, "{flips}");
    assert!(same_bits(&b.state.u, &u0) && same_bits(&b.state.v, &v0));
    assert_eq!(b.state.step, step0);
    b.restore_bytes(&snap).unwrap();
    assert_eq!(b.state.step, 7);
}

#[test]
fn versions_are_named() {
    let mut sim = scene();
    let mut snap = sim.snapshot_bytes().unwrap();
    // The previous format (3) and a future one are named with the supported version.
    for found in [3, SNAPSHOT_VERSION + 1] {
        snap[8..12].copy_from_slice(&found.to_le_bytes());
        let e = sim.restore_bytes(&snap).unwrap_err();
        assert!(
            matches!(e, ComputeError::SnapshotVersion { found: f, supported: SNAPSHOT_VERSION } if f == found),
            "{e}"
        );
        let msg = e.to_string();
        assert!(
            msg.contains(&format!("version {found}"))
                && msg.contains(&format!("version {SNAPSHOT_VERSION}")),
            "{msg}"
        );
    }
    // A version-2 file: a bare postcard struct led by the text "pcdc-snapshot-2".
    let mut old = vec![15u8];
    old.extend_from_slice(b"pcdc-snapshot-2");
    old.extend_from_slice(&[2, 5, 0, 0, 0, 0]);
    let e = sim.restore_bytes(&old).unwrap_err();
    assert!(
        matches!(e, ComputeError::SnapshotVersion { found: 2, .. }),
        "{e}"
    );
    let e = sim
        .restore_bytes(b"hello, world, this is text")
        .unwrap_err();
    assert!(e.to_string().contains("not a pcdc snapshot"), "{e}");
}

#[test]
fn foreign_scenes_are_refused_by_name() {
    let mut a = scene();
    a.run(3).unwrap();
    let snap = a.snapshot_bytes().unwrap();
    // Same counts, shifted mesh.
    let shifted = builders::rectangle(0.5, 0.0, 1.0, 1.0, 0.5).unwrap();
    let mut b = scene_with(shifted, Springs::new(1e3, 1.0));
    let e = b.restore_bytes(&snap).unwrap_err().to_string();
    assert!(e.contains("different mesh"), "{e}");
    // Same mesh, other stiffness (the physics' own fingerprint).
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let mut c = scene_with(mesh.clone(), Springs::new(2e3, 1.0));
    let e = c.restore_bytes(&snap).unwrap_err().to_string();
    assert!(e.contains("physics 'springs'"), "{e}");
    // A physics without a fingerprint hook: another density shows in the masses.
    let plain = |rho| Springs {
        hook: false,
        ..Springs::new(1e3, rho)
    };
    let mut d1 = scene_with(mesh.clone(), plain(1.0));
    d1.run(3).unwrap();
    let snap_plain = d1.snapshot_bytes().unwrap();
    let mut d2 = scene_with(mesh.clone(), plain(2.0));
    let e = d2.restore_bytes(&snap_plain).unwrap_err().to_string();
    assert!(e.contains("node masses"), "{e}");
    // Another composition.
    let mut e2 = Simulation::builder(mesh, cpu())
        .physics(Springs::new(1e3, 1.0))
        .physics(Springs {
            owner: false,
            ..Springs::new(1e3, 1.0)
        })
        .build()
        .unwrap();
    let e = e2.restore_bytes(&snap).unwrap_err().to_string();
    assert!(e.contains("composes the physics"), "{e}");
}

/// Snapshots with a valid checksum but impossible content are refused, and leave the
/// simulation unchanged.
#[test]
fn forged_content_is_refused() {
    let mut a = scene();
    a.run(4).unwrap();
    let good = decode(&a.snapshot_bytes().unwrap());
    type Edit = fn(&mut Payload);
    let cases: [(&str, Edit, &str); 9] = [
        ("nan dt", |p| p.dt = f64::NAN, "time step"),
        ("negative dt", |p| p.dt = -1e-3, "time step"),
        ("infinite time", |p| p.time_mut(f64::INFINITY), "time inf"),
        ("nan velocity", |p| p.state.v[3] = f64::NAN, "node 1"),
        ("runaway", |p| p.state.u[0] = 1e9, "runaway"),
        (
            "short u",
            |p| {
                p.state.u.pop();
            },
            "node arrays",
        ),
        (
            "missing physics state",
            |p| {
                p.physics_state.pop();
            },
            "physics states",
        ),
        (
            "bad physics state",
            |p| p.physics_state[0].push(1),
            "springs state",
        ),
        ("counts", |p| p.n_nodes += 1, "nodes"),
    ];
    let mut b = scene();
    b.run(2).unwrap();
    let u0 = b.state.u.clone();
    for (what, edit, expect) in cases {
        let mut p = decode(&a.snapshot_bytes().unwrap());
        edit(&mut p);
        let e = b.restore_bytes(&forge(&p)).unwrap_err().to_string();
        assert!(e.contains(expect), "{what}: {e}");
        assert!(same_bits(&b.state.u, &u0) && b.state.step == 2, "{what}");
    }
    // Bytes after the payload inside a valid checksum.
    let mut payload = postcard::to_stdvec(&PayloadRef {
        dim: &good.dim,
        n_nodes: good.n_nodes,
        n_elements: good.n_elements,
        mesh: good.mesh,
        physics: good.physics.clone(),
        physics_params: good.physics_params.clone(),
        layout: good.layout,
        dt: good.dt,
        state: &good.state,
        physics_state: good.physics_state.clone(),
    })
    .unwrap();
    payload.push(0);
    let e = b.restore_bytes(&seal(&payload)).unwrap_err().to_string();
    assert!(e.contains("left after the payload"), "{e}");
}

/// A physics with no state of its own (the trait's defaults).
struct Quiet;

impl Physics<Dim2> for Quiet {
    fn name(&self) -> &str {
        "quiet"
    }
    fn init(&mut self, _ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
}

/// The default `restore_state` refuses bytes for a physics that saved none.
#[test]
fn stateless_physics_refuse_a_state() {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let build = || {
        Simulation::builder(mesh.clone(), cpu())
            .physics(Springs::new(1e3, 1.0))
            .physics(Quiet)
            .build()
            .unwrap()
    };
    let mut a = build();
    a.run(2).unwrap();
    let mut p = decode(&a.snapshot_bytes().unwrap());
    assert!(p.physics_state[1].is_empty());
    p.physics_state[1] = vec![0; 5];
    let mut b = build();
    let e = b.restore_bytes(&forge(&p)).unwrap_err().to_string();
    assert!(
        e.contains("'quiet' keeps no state") && e.contains("5 bytes"),
        "{e}"
    );
    b.restore_bytes(&a.snapshot_bytes().unwrap()).unwrap();
}

/// A physics that refuses its state gets the others' previous states restored.
#[test]
fn physics_states_restore_all_or_nothing() {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let build = |c0, c1| {
        let (mut s0, mut s1) = (Springs::new(1e3, 1.0), Springs::new(1e3, 1.0));
        s0.counter = c0;
        s1.counter = c1;
        s1.owner = false;
        Simulation::builder(mesh.clone(), cpu())
            .physics(s0)
            .physics(s1)
            .build()
            .unwrap()
    };
    let a = build(11, 12);
    let mut p = decode(&a.snapshot_bytes().unwrap());
    p.physics_state[1] = vec![1, 2, 3];
    let mut b = build(21, 22);
    let e = b.restore_bytes(&forge(&p)).unwrap_err().to_string();
    assert!(e.contains("springs state"), "{e}");
    let states: Vec<Vec<u8>> = b.physics.iter().map(|q| q.save_state().unwrap()).collect();
    assert_eq!(states[0], 21u64.to_le_bytes());
    assert_eq!(states[1], 22u64.to_le_bytes());
    b.restore_bytes(&a.snapshot_bytes().unwrap()).unwrap();
    assert_eq!(b.physics[0].save_state().unwrap(), 11u64.to_le_bytes());
}

impl Payload {
    fn time_mut(&mut self, t: f64) {
        self.state.time = t;
    }
}
