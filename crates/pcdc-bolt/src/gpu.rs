//! The GPU kernels of the bolts (`shaders/bolt.wgsl`), in the force phase: a segment
//! pass (axial force, written per segment), a node pass (each bolt node gathers its two
//! segments' forces in a fixed order, re-locates itself if it has left its host, adds
//! the grout and plate, and writes its own slot and its grout vector) and a host pass
//! (each node of the elements on a bolt's path sums the grout reactions of the bolt
//! nodes its elements host, in bolt-node order, into its slot): the CPU's arithmetic in the same order, no float
//! atomics. Bolt-node conditions: one kernel per item, node forces in the force phase,
//! velocities and accelerations after the velocity update, their tables evaluated on the
//! host per step (signals) at the times the CPU uses.

use pcdc_compute::gpu::{Access, GpuData, GpuSetup, Kernel, Phase};
use pcdc_compute::{names, ComputeError};
use pcdc_mesh::Dim;

use crate::boundary::BcKind;
use crate::fields::*;
use crate::physics::NONE;
use crate::{BoltBoundary, Bolts};

/// The WGSL of both kernels: a shared head, then one section per kernel after a
/// `//!name` line.
pub(crate) const BOLT_WGSL: &str = include_str!("shaders/bolt.wgsl");

/// The source of kernel `name`: the shared head (segment state; not for the host pass,
/// which needs none of its buffers) and that section.
pub(crate) fn kernel_source(name: &str) -> String {
    let head_end = if name == "host_kernel" {
        0
    } else {
        BOLT_WGSL.find("//!").unwrap_or(BOLT_WGSL.len())
    };
    let marker = format!("//!{name}\n");
    let body = BOLT_WGSL.find(&marker).map_or("", |at| {
        let start = at + marker.len();
        let end = BOLT_WGSL[start..]
            .find("//!")
            .map_or(BOLT_WGSL.len(), |i| start + i);
        &BOLT_WGSL[start..end]
    });
    format!("{}{body}", &BOLT_WGSL[..head_end])
}

/// Data of a device buffer: never empty (a zero-length binding is invalid).
fn nonempty<T: Default>(mut v: Vec<T>) -> Vec<T> {
    if v.is_empty() {
        v.push(T::default());
    }
    v
}

/// Declares the buffers and the two kernels of [`Bolts`].
pub(crate) fn bolts<D: Dim>(b: &Bolts, setup: &mut GpuSetup<'_, D>) -> Result<(), ComputeError> {
    let d = D::D;
    if b.nodes.is_empty() {
        return Err(ComputeError::Gpu(format!(
            "{}: GPU setup before init",
            crate::NAME
        )));
    }
    let mut seg_nodes = Vec::with_capacity(2 * b.segments.len());
    let mut seg_real = Vec::with_capacity(9 * b.segments.len());
    for s in &b.segments {
        seg_nodes.extend_from_slice(&s.n);
        // An infinite failure strain as the largest finite value: the comparison is the same.
        seg_real.extend_from_slice(&[
            s.l0,
            s.law.ea,
            s.law.tensile,
            s.law.compressive,
            s.law.failure_strain.min(f64::MAX),
            s.damping,
        ]);
        seg_real.extend_from_slice(&s.dx);
    }
    // Slots, bolt after bolt as registered: one per bolt node, then one per path node.
    let (mut node_slot, mut pn_slot) = (Vec::new(), Vec::new());
    let mut slot = 0u32;
    for span in &b.spans {
        node_slot.extend((0..span.nodes as u32).map(|i| slot + i));
        slot += span.nodes as u32;
        pn_slot.extend((0..span.path_nodes as u32).map(|m| slot + m));
        slot += span.path_nodes as u32;
    }
    let mut node_u = Vec::with_capacity(6 * b.nodes.len());
    let mut node_r = Vec::with_capacity(11 * b.nodes.len());
    for (n, s) in b.nodes.iter().zip(&node_slot) {
        node_u.extend_from_slice(&[n.node, n.prev, n.next, n.cand[0], n.cand[1], *s]);
        node_r.extend_from_slice(&[n.k_axial, n.k_normal, n.bond_length, n.plate]);
        node_r.extend_from_slice(&n.bond);
        node_r.push(n.c_lateral);
    }
    let mut path_u = Vec::with_capacity(5 * b.path.len());
    for pe in &b.path {
        path_u.push(pe.element);
        path_u.extend_from_slice(&pe.nodes);
    }
    let pn = &b.path_nodes;
    let mut pn_u = Vec::with_capacity(5 * pn.nodes.len());
    for (p, s) in pn.nodes.iter().zip(&pn_slot) {
        pn_u.extend_from_slice(&[*s, p.node_range[0], p.node_range[1], p.refs[0], p.refs[1]]);
    }
    let refs: Vec<u32> = pn.refs.iter().flatten().copied().collect();
    let seg_force = vec![0.0; 3 * b.segments.len()];
    let bs_nodes = setup.upload("bolt segment nodes", GpuData::U32(nonempty(seg_nodes)));
    let bs_real = setup.upload("bolt segment laws", GpuData::Real(nonempty(seg_real)));
    let bs_force = setup.upload("bolt segment forces", GpuData::Real(nonempty(seg_force)));
    let bn_u32 = setup.upload("bolt node data", GpuData::U32(node_u));
    let bn_real = setup.upload("bolt node grout", GpuData::Real(node_r));
    let bp_u32 = setup.upload("bolt path elements", GpuData::U32(path_u));
    let bq_u32 = setup.upload("bolt path nodes", GpuData::U32(pn_u));
    let bq_refs = setup.upload("bolt path node corners", GpuData::U32(refs));
    let bn_grout = setup.upload(
        "bolt node grout vectors",
        GpuData::Real(vec![0.0; 3 * b.nodes.len()]),
    );
    use Access::{Read as R, ReadWrite as W};
    let consts = |k: Kernel| {
        k.const_u32("D", d as u32)
            .const_u32("NSYM", D::NSYM as u32)
            .const_u32("NONE", NONE)
            .const_u32("BS_STRIDE", 9)
            .const_u32("ALEN", crate::anchor_len(d) as u32)
            .const_real("LEAVE", crate::walk::LEAVE)
            .const_real("ENTER", crate::walk::ENTER)
            .const_real("STRETCH", crate::walk::STRETCH)
    };
    let seg = consts(Kernel::new(
        "bolt segments",
        kernel_source("segment_kernel"),
        b.segments.len(),
    ))
    .bind("disp", setup.displacement(), R)
    .bind("vel", setup.velocity(), R)
    .bind("bs_nodes", bs_nodes, R)
    .bind("bs_real", bs_real, R)
    .bind("bs_force", bs_force, W)
    .bind("bolt_axial_force", setup.field(BOLT_AXIAL_FORCE)?, W)
    .bind(
        "bolt_plastic_elongation",
        setup.field(BOLT_PLASTIC_ELONGATION)?,
        W,
    )
    .bind("bolt_state", setup.field(BOLT_STATE)?, W);
    setup.kernel(Phase::Forces, seg)?;
    // The host rotation (3D, the mechanics' field) through a function, so that the 2D
    // module binds no rotation.
    let rotation = if d == 3 {
        "fn bolt_rotation(i: u32) -> Real { return rotation[i]; }\n"
    } else {
        "fn bolt_rotation(i: u32) -> Real { return 0.0; }\n"
    };
    let src = format!("{rotation}{}", kernel_source("node_kernel"));
    let anchor = setup.field(BOLT_ANCHOR)?;
    let mut node = consts(Kernel::new("bolt nodes", src, b.nodes.len()))
        .const_u32("SLOT0", setup.slot_first())
        .bind("coords", setup.coords(), R)
        .bind("disp", setup.displacement(), R)
        .bind("vel", setup.velocity(), R)
        .bind("bs_nodes", bs_nodes, R)
        .bind("bs_real", bs_real, R)
        .bind("bs_force", bs_force, R)
        .bind("bn_u32", bn_u32, R)
        .bind("bn_real", bn_real, R)
        .bind("bp_u32", bp_u32, R)
        .bind("stress", setup.field(names::STRESS)?, R)
        .bind("bolt_slip", setup.field(BOLT_SLIP)?, W)
        .bind("bolt_grout_force", setup.field(BOLT_GROUT_FORCE)?, W)
        .bind("bolt_anchor", anchor, W)
        .bind("bolt_host", setup.field(BOLT_HOST)?, W)
        .bind("bn_grout", bn_grout, W)
        .bind("slots", setup.slots(), W);
    if d == 3 {
        node = node.bind("rotation", setup.field(names::ROTATION)?, R);
    }
    setup.kernel(Phase::Forces, node)?;
    let hosts = consts(Kernel::new(
        "bolt hosts",
        kernel_source("host_kernel"),
        pn.nodes.len(),
    ))
    .const_u32("SLOT0", setup.slot_first())
    .bind("bn_u32", bn_u32, R)
    .bind("bq_u32", bq_u32, R)
    .bind("bq_refs", bq_refs, R)
    .bind("bolt_anchor", anchor, R)
    .bind("bn_grout", bn_grout, R)
    .bind("slots", setup.slots(), W);
    setup.kernel(Phase::Forces, hosts)
}

/// Node forces: every slot of the item gets the same force, component k from signal
/// SIG + k.
const FORCE_WGSL: &str = r#"
fn kernel(s: u32) {
    let base = (SLOT0 + s) * D;
    for (var k = 0u; k < D; k = k + 1u) {
        slots[base + k] = signal(SIG + k);
    }
}
"#;

/// Prescribed velocity on the components of MASK.
const VELOCITY_WGSL: &str = r#"
fn kernel(j: u32) {
    let base = nodes[j] * D;
    for (var k = 0u; k < D; k = k + 1u) {
        if ((MASK >> k) & 1u) != 0u {
            vel[base + k] = signal(SIG + k);
        }
    }
}
"#;

/// Prescribed acceleration: the integrated velocity (field bolt_bc_velocity, by
/// bolt-node index) grows by a dt and overwrites the node's velocity.
const ACCELERATION_WGSL: &str = r#"
fn kernel(j: u32) {
    let base = nodes[j] * D;
    let own = set_index[j] * D;
    for (var k = 0u; k < D; k = k + 1u) {
        if ((MASK >> k) & 1u) != 0u {
            let a = acc[own + k] + signal(SIG + k);
            acc[own + k] = a;
            vel[base + k] = a;
        }
    }
}
"#;

/// Declares one kernel per condition of a [`BoltBoundary`].
pub(crate) fn boundary<D: Dim>(
    b: &BoltBoundary,
    setup: &mut GpuSetup<'_, D>,
) -> Result<(), ComputeError> {
    let d = D::D;
    let mut slot = setup.slot_first();
    for (i, r) in b.resolved.iter().enumerate() {
        let label = |what: &str| format!("bolt boundary {i}: {what}");
        // One signal per component, consecutive.
        let mut first = None;
        for k in 0..d {
            let v = r.values[k].clone();
            let scale = r.scale;
            let s =
                match r.kind {
                    // Forces at the start of the step, as `compute_forces` (kin.time).
                    BcKind::Force => {
                        setup.signal(move |t, _| v.as_ref().map_or(0.0, |v| v.at(t)) * scale)
                    }
                    // Velocities at the half step, as `apply_kinematics`.
                    BcKind::Velocity => setup
                        .signal(move |t, dt| v.as_ref().map_or(0.0, |v| v.at((t + dt) - 0.5 * dt))),
                    // Acceleration increments a(t) dt, as `apply_kinematics`.
                    BcKind::Acceleration => setup
                        .signal(move |t, dt| v.as_ref().map_or(0.0, |v| v.at((t + dt) - dt) * dt)),
                };
            first.get_or_insert(s);
        }
        let sig = first.expect("at least one component");
        let mask = (0..d)
            .filter(|&k| r.values[k].is_some())
            .fold(0u32, |m, k| m | (1 << k));
        let nodes: Vec<u32> = r.nodes.iter().map(|n| n.0).collect();
        match r.kind {
            BcKind::Force => {
                let k = Kernel::new(label("force"), FORCE_WGSL, nodes.len())
                    .const_u32("D", d as u32)
                    .const_u32("SLOT0", slot)
                    .const_u32("SIG", sig)
                    .bind("slots", setup.slots(), Access::ReadWrite);
                setup.kernel(Phase::Forces, k)?;
                slot += nodes.len() as u32;
            }
            BcKind::Velocity => {
                let nb = setup.upload(&label("nodes"), GpuData::U32(nodes.clone()));
                let k = Kernel::new(label("velocity"), VELOCITY_WGSL, nodes.len())
                    .const_u32("D", d as u32)
                    .const_u32("MASK", mask)
                    .const_u32("SIG", sig)
                    .bind("nodes", nb, Access::Read)
                    .bind("vel", setup.velocity(), Access::ReadWrite);
                setup.kernel(Phase::Kinematics, k)?;
            }
            BcKind::Acceleration => {
                let own: Vec<u32> = r.nodes.iter().map(|n| n.1).collect();
                let nb = setup.upload(&label("nodes"), GpuData::U32(nodes.clone()));
                let ob = setup.upload(&label("bolt-node index"), GpuData::U32(own));
                let k = Kernel::new(label("acceleration"), ACCELERATION_WGSL, nodes.len())
                    .const_u32("D", d as u32)
                    .const_u32("MASK", mask)
                    .const_u32("SIG", sig)
                    .bind("nodes", nb, Access::Read)
                    .bind("set_index", ob, Access::Read)
                    .bind("vel", setup.velocity(), Access::ReadWrite)
                    .bind("acc", setup.field(BOLT_BC_VELOCITY)?, Access::ReadWrite);
                setup.kernel(Phase::Kinematics, k)?;
            }
        }
    }
    Ok(())
}
