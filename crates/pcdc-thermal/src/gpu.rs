//! The GPU kernels of [`crate::Thermal`] (`shaders/thermal.wgsl`), all in the field
//! phase: the element pass (fluxes, nodal rates per element slot), the node pass (slots
//! gathered in a fixed order, face conditions), the group pass (one update per thermal
//! node) and the write pass (temperatures, heat supplied). The same arithmetic in the
//! same order as the CPU path, no float atomics. Conditions are per-step signals (their
//! values at the end of the mechanical step, as on the CPU). With fluid heat, the fluid
//! channel and node passes run before the node pass (against the solid at the start of
//! the step) and a wall pass after it adds the exchange at the fluid's new temperatures.
//!
//! The thermal nodes (groups of split copies joined by conducting joints) are fixed on
//! the device for unsplit meshes, `Conducting` and `Insulating`. With
//! [`crate::JointHeat::FollowDamage`] on a split mesh, whose groups split as joints
//! break, the group pass runs per original vertex instead: a union-find over the
//! vertex's node pairs whose joints are intact (damage < 1) gives its thermal nodes,
//! each updated with its members in ascending order as on the CPU.

use pcdc_compute::gpu::{Access, GpuBuffer, GpuData, GpuSetup, Kernel, Phase};
use pcdc_compute::names::{JOINT_DAMAGE, JOINT_OPENING, JOINT_SLIDING, TEMPERATURE};
use pcdc_compute::ComputeError;
use pcdc_mesh::Dim;

use crate::boundary::FaceHeat;
use crate::fields::{FLUID_HEAT_BALANCE, FLUID_HEAT_CAPACITY, FLUID_TEMPERATURE};
use crate::fields::{HEAT_CAPACITY, HEAT_FLUX, HEAT_SUPPLIED};
use crate::physics::{Derived, Groups, FREE};
use crate::FluidHeat;
use pcdc_compute::names::{CHANNEL_APERTURE, CHANNEL_FLUX, FLOW_SATURATION};

/// The WGSL of every kernel: a shared head, then one section per kernel after a
/// `//!name` line.
pub(crate) const THERMAL_WGSL: &str = include_str!("shaders/thermal.wgsl");

/// The source of kernel `name`: the shared head and that section.
pub(crate) fn kernel_source(name: &str) -> String {
    let head_end = THERMAL_WGSL.find("//!").unwrap_or(THERMAL_WGSL.len());
    let marker = format!("//!{name}\n");
    let body = THERMAL_WGSL.find(&marker).map_or("", |at| {
        let start = at + marker.len();
        let end = THERMAL_WGSL[start..]
            .find("//!")
            .map_or(THERMAL_WGSL.len(), |i| start + i);
        &THERMAL_WGSL[start..end]
    });
    format!("{}{body}", &THERMAL_WGSL[..head_end])
}

/// Declares the buffers and kernels of the thermal physics (see the module docs).
pub(crate) fn program<D: Dim>(
    d: &Derived,
    faces: &[(pcdc_mesh::Range, FaceHeat)],
    fixed: &[(pcdc_mesh::Range, pcdc_compute::TimeValue)],
    fluid: Option<(&FluidHeat, &[(pcdc_mesh::Range, pcdc_compute::TimeValue)])>,
    follow_damage: bool,
    setup: &mut GpuSetup<'_, D>,
) -> Result<(), ComputeError> {
    let (dim, npe) = (D::D, D::NODES_PER_ELEM);
    let (ne, nn, ng) = (d.material.len(), d.capacity.len(), d.groups.len());
    // Conditions as signals: face conditions' value (flux or environment temperature),
    // temperature conditions' value; the node's condition as its signal index.
    let mut kind = Vec::with_capacity(faces.len());
    let mut h = Vec::with_capacity(faces.len());
    let mut sig = Vec::with_capacity(faces.len());
    for (_, heat) in faces {
        let (k, hv, v) = match heat {
            FaceHeat::Flux(q) => (0u32, 0.0, q.clone()),
            FaceHeat::Convection(hc, te) => (1u32, *hc, te.clone()),
        };
        kind.push(k);
        h.push(hv);
        sig.push(setup.signal(move |t, dt| v.at(t + dt)));
    }
    let fixed_sig: Vec<u32> = fixed
        .iter()
        .map(|(_, v)| {
            let v = v.clone();
            setup.signal(move |t, dt| v.at(t + dt))
        })
        .collect();
    let held: Vec<u32> = d
        .fixed_of
        .iter()
        .map(|&c| {
            if c == FREE {
                FREE
            } else {
                fixed_sig[c as usize]
            }
        })
        .collect();
    // WGSL arrays may not be empty.
    let nonempty_u = |v: Vec<u32>| if v.is_empty() { vec![0] } else { v };
    let nonempty_r = |v: Vec<f64>| if v.is_empty() { vec![0.0] } else { v };
    let mut k9 = Vec::with_capacity(9 * d.k.len());
    for k in &d.k {
        k9.extend(k.iter().flatten());
    }
    let up_u = |s: &mut GpuSetup<'_, D>, label: &str, v: Vec<u32>| {
        s.upload(label, GpuData::U32(nonempty_u(v)))
    };
    let up_r = |s: &mut GpuSetup<'_, D>, label: &str, v: Vec<f64>| {
        s.upload(label, GpuData::Real(nonempty_r(v)))
    };
    let conn_data = setup.mesh.elements().to_vec();
    let conn = up_u(setup, "thermal connectivity", conn_data);
    let material = up_u(setup, "thermal material", d.material.clone());
    let kbuf = up_r(setup, "thermal conductivity", k9);
    let grad = up_r(setup, "thermal gradients", d.geo.grad.clone());
    let measure = up_r(setup, "thermal measure", d.geo.measure.clone());
    let rates = up_r(setup, "thermal rates", vec![0.0; ne * npe]);
    let slot_start = up_u(setup, "thermal slot start", d.slot_start.clone());
    let slots = up_u(setup, "thermal slots", d.slots.clone());
    let entry_start = up_u(setup, "thermal entry start", d.entries.start.clone());
    let entry_cond = up_u(setup, "thermal entry condition", d.entries.cond.clone());
    let entry_share = up_r(setup, "thermal entry share", d.entries.share.clone());
    let cond_kind = up_u(setup, "thermal condition kind", kind);
    let cond_h = up_r(setup, "thermal condition h", h);
    let cond_sig = up_u(setup, "thermal condition signal", sig);
    let node_rate = up_r(setup, "thermal node rate", vec![0.0; nn]);
    let node_bnd = up_r(setup, "thermal node face heat", vec![0.0; nn]);
    // Joints that stop conducting when they break: per original vertex (the split copies
    // the intact joints may join), its node pairs; the device finds the thermal nodes
    // within each vertex every step, and writes per node ([`vertex_groups`]).
    let vertex = if follow_damage {
        Some(vertex_groups(setup.mesh)?)
    } else {
        None
    };
    let (gs, gm, go, gt_len) = match &vertex {
        Some(v) => (
            v.groups.start.clone(),
            v.groups.members.clone(),
            (0..nn as u32).collect(),
            2 * nn,
        ),
        None => (
            d.groups.start.clone(),
            d.groups.members.clone(),
            d.groups.of.clone(),
            2 * ng,
        ),
    };
    let group_start = up_u(setup, "thermal group start", gs);
    let members = up_u(setup, "thermal group members", gm);
    let group_of = up_u(setup, "thermal group of node", go);
    let fixed_buf = up_u(setup, "thermal held", held);
    let group_temp = up_r(setup, "thermal group temperatures", vec![0.0; gt_len]);
    let err = setup.error(|n| {
        format!("divergence: temperature not finite at node {n}. Hint: the thermal step is above the stable one (a fixed schedule too coarse?)")
    });
    let (temp, flux, supplied, capacity, status) = (
        setup.field(TEMPERATURE)?,
        setup.field(HEAT_FLUX)?,
        setup.field(HEAT_SUPPLIED)?,
        setup.field(HEAT_CAPACITY)?,
        setup.status(),
    );
    let consts = |k: Kernel| -> Kernel {
        k.const_u32("D", dim as u32)
            .const_u32("NPE", npe as u32)
            .const_u32("FREE", FREE)
            .const_u32("ERR_DIVERGED", err)
    };
    let bind = |k: Kernel, names: &[(&str, GpuBuffer, Access)]| -> Kernel {
        names.iter().fold(k, |k, (n, b, a)| k.bind(n, *b, *a))
    };
    use Access::{Read as R, ReadWrite as W};
    let k = consts(Kernel::new(
        "thermal elements",
        kernel_source("element_kernel"),
        ne,
    ));
    let k = bind(
        k,
        &[
            ("th_conn", conn, R),
            ("th_material", material, R),
            ("th_k", kbuf, R),
            ("th_grad", grad, R),
            ("th_measure", measure, R),
            ("temperature", temp, R),
            ("heat_flux", flux, W),
            ("th_rates", rates, W),
        ],
    );
    setup.kernel(Phase::Field, k)?;
    // The fracture fluid against the solid at the start of the step (fluid module).
    let fluid_prog = match (fluid, d.fluid.as_ref()) {
        (Some((fl, fl_fixed)), Some(fs)) => {
            let net = &fs.net;
            let fixed_sig: Vec<u32> = fl_fixed
                .iter()
                .map(|(_, v)| {
                    let v = v.clone();
                    setup.signal(move |t, dt| v.at(t + dt))
                })
                .collect();
            let held: Vec<u32> = net
                .fixed_of
                .iter()
                .map(|&c| {
                    if c == FREE {
                        FREE
                    } else {
                        fixed_sig[c as usize]
                    }
                })
                .collect();
            let npc = net.npc;
            let b = FluidBuffers {
                channel_nodes: up_u(setup, "fluid heat channel nodes", net.channel_nodes.clone()),
                walls: up_u(setup, "fluid heat walls", net.walls.clone()),
                inc_ptr: up_u(setup, "fluid heat incidence ptr", net.inc_ptr.clone()),
                incidence: up_u(setup, "fluid heat incidence", net.incidence.clone()),
                wall_ptr: up_u(setup, "fluid heat wall ptr", net.wall_ptr.clone()),
                wall_slots: up_u(setup, "fluid heat wall slots", net.wall_slots.clone()),
                fixed: up_u(setup, "fluid heat held", held),
                slots: up_r(
                    setup,
                    "fluid heat slots",
                    vec![0.0; net.n_channels() * npc * 5],
                ),
            };
            let (rc, kf, hsf) = (fl.volumetric_capacity(), fl.conductivity(), fl.transfer());
            let fconsts = move |k: Kernel| -> Kernel {
                consts(k)
                    .const_u32("NPC", npc as u32)
                    .const_real("RC", rc)
                    .const_real("KF", kf)
                    .const_real("HSF", hsf)
            };
            let (tf, cap, bal, sat, ap, q) = (
                setup.field(FLUID_TEMPERATURE)?,
                setup.field(FLUID_HEAT_CAPACITY)?,
                setup.field(FLUID_HEAT_BALANCE)?,
                setup.field(FLOW_SATURATION)?,
                setup.field(CHANNEL_APERTURE)?,
                setup.field(CHANNEL_FLUX)?,
            );
            let (coords, disp) = (setup.coords(), setup.displacement());
            let k = fconsts(Kernel::new(
                "thermal fluid channels",
                kernel_source("fluid_channel_kernel"),
                net.n_channels(),
            ));
            let k = bind(
                k,
                &[
                    ("coords", coords, R),
                    ("disp", disp, R),
                    ("fl_walls", b.walls, R),
                    ("fl_channel_nodes", b.channel_nodes, R),
                    ("channel_flux", q, R),
                    ("channel_aperture", ap, R),
                    ("flow_saturation", sat, R),
                    ("fluid_temperature", tf, R),
                    ("fl_slots", b.slots, W),
                ],
            );
            setup.kernel(Phase::Field, k)?;
            let k = fconsts(Kernel::new(
                "thermal fluid nodes",
                kernel_source("fluid_node_kernel"),
                net.n_nodes(),
            ));
            let k = bind(
                k,
                &[
                    ("fl_inc_ptr", b.inc_ptr, R),
                    ("fl_incidence", b.incidence, R),
                    ("fl_slots", b.slots, R),
                    ("fl_walls", b.walls, R),
                    ("fl_fixed", b.fixed, R),
                    ("temperature", temp, R),
                    ("flow_saturation", sat, R),
                    ("fluid_temperature", tf, W),
                    ("fluid_heat_capacity", cap, W),
                    ("fluid_heat_balance", bal, W),
                    ("status", status, W),
                ],
            );
            setup.kernel(Phase::Field, k)?;
            Some((b, tf, fconsts))
        }
        _ => None,
    };
    let k = consts(Kernel::new(
        "thermal nodes",
        kernel_source("node_kernel"),
        nn,
    ));
    let k = bind(
        k,
        &[
            ("th_slot_start", slot_start, R),
            ("th_slots", slots, R),
            ("th_rates", rates, R),
            ("th_entry_start", entry_start, R),
            ("th_entry_cond", entry_cond, R),
            ("th_entry_share", entry_share, R),
            ("th_cond_kind", cond_kind, R),
            ("th_cond_h", cond_h, R),
            ("th_cond_signal", cond_sig, R),
            ("temperature", temp, R),
            ("th_node_rate", node_rate, W),
            ("th_node_bnd", node_bnd, W),
        ],
    );
    setup.kernel(Phase::Field, k)?;
    // The walls take the exchange at the fluid's new temperatures, after their rates.
    if let Some((b, tf, fconsts)) = fluid_prog {
        let k = fconsts(Kernel::new(
            "thermal fluid walls",
            kernel_source("fluid_wall_kernel"),
            nn,
        ));
        let k = bind(
            k,
            &[
                ("fl_wall_ptr", b.wall_ptr, R),
                ("fl_wall_slots", b.wall_slots, R),
                ("fl_slots", b.slots, R),
                ("fl_channel_nodes", b.channel_nodes, R),
                ("fluid_temperature", tf, R),
                ("temperature", temp, R),
                ("th_node_rate", node_rate, W),
            ],
        );
        setup.kernel(Phase::Field, k)?;
    }
    // Then broken joints whose faces touch (contact module).
    if let Some(p) = &d.contact {
        let ptr = up_u(setup, "thermal contact ptr", p.ptr.clone());
        let entries = up_u(setup, "thermal contact entries", p.entries.clone());
        let share = up_r(setup, "thermal contact share", p.share.clone());
        let size = up_r(setup, "thermal contact size", p.size.clone());
        let (damage, opening, sliding) = (
            setup.field(JOINT_DAMAGE)?,
            setup.field(JOINT_OPENING)?,
            setup.field(JOINT_SLIDING)?,
        );
        let k = consts(Kernel::new(
            "thermal contact",
            kernel_source("contact_kernel"),
            nn,
        ))
        .const_real("HC", p.h);
        let k = bind(
            k,
            &[
                ("th_ct_ptr", ptr, R),
                ("th_ct_entries", entries, R),
                ("th_ct_share", share, R),
                ("th_ct_size", size, R),
                ("joint_damage", damage, R),
                ("joint_opening", opening, R),
                ("joint_sliding", sliding, R),
                ("temperature", temp, R),
                ("th_node_rate", node_rate, W),
            ],
        );
        setup.kernel(Phase::Field, k)?;
    }
    match vertex {
        None => {
            let k = consts(Kernel::new(
                "thermal groups",
                kernel_source("group_kernel"),
                ng,
            ));
            let k = bind(
                k,
                &[
                    ("th_group_start", group_start, R),
                    ("th_members", members, R),
                    ("th_node_rate", node_rate, R),
                    ("heat_capacity", capacity, R),
                    ("th_fixed", fixed_buf, R),
                    ("temperature", temp, R),
                    ("th_group_temp", group_temp, W),
                ],
            );
            setup.kernel(Phase::Field, k)?;
        }
        Some(v) => {
            let pair_start = up_u(setup, "thermal vertex pair start", v.pair_start);
            let pairs = up_u(setup, "thermal vertex pairs", v.pairs);
            let damage = setup.field(JOINT_DAMAGE)?;
            let nv = v.groups.len();
            let k = consts(Kernel::new(
                "thermal vertex groups",
                kernel_source("vertex_group_kernel"),
                nv,
            ))
            .const_u32("MAXV", MAX_COPIES as u32);
            let k = bind(
                k,
                &[
                    ("th_group_start", group_start, R),
                    ("th_members", members, R),
                    ("th_pair_start", pair_start, R),
                    ("th_pairs", pairs, R),
                    ("joint_damage", damage, R),
                    ("th_node_rate", node_rate, R),
                    ("heat_capacity", capacity, R),
                    ("th_fixed", fixed_buf, R),
                    ("temperature", temp, R),
                    ("th_group_temp", group_temp, W),
                ],
            );
            setup.kernel(Phase::Field, k)?;
        }
    }
    let k = consts(Kernel::new(
        "thermal write",
        kernel_source("write_kernel"),
        nn,
    ));
    let k = bind(
        k,
        &[
            ("th_group_of", group_of, R),
            ("th_group_temp", group_temp, R),
            ("th_node_bnd", node_bnd, R),
            ("heat_capacity", capacity, R),
            ("heat_supplied", supplied, W),
            ("temperature", temp, W),
            ("status", status, W),
        ],
    );
    setup.kernel(Phase::Field, k)?;
    Ok(())
}

/// The device buffers of the fluid heat.
struct FluidBuffers {
    channel_nodes: GpuBuffer,
    walls: GpuBuffer,
    inc_ptr: GpuBuffer,
    incidence: GpuBuffer,
    wall_ptr: GpuBuffer,
    wall_slots: GpuBuffer,
    fixed: GpuBuffer,
    slots: GpuBuffer,
}

/// The most split copies of one vertex the device's thermal-node search holds.
pub(crate) const MAX_COPIES: usize = 64;

/// The split copies of every original vertex (the thermal nodes when every joint
/// conducts) and, per vertex, the node pairs of the joints between them: 3 values per
/// pair, the joint and the local indices (in the vertex's ascending members) of its two
/// nodes.
struct VertexGroups {
    groups: Groups,
    pair_start: Vec<u32>,
    pairs: Vec<u32>,
}

fn vertex_groups<D: Dim>(mesh: &pcdc_mesh::Mesh<D>) -> Result<VertexGroups, ComputeError> {
    let groups = Groups::build(mesh, |_| true);
    let nv = groups.len();
    if let Some(v) =
        (0..nv).find(|&v| (groups.start[v + 1] - groups.start[v]) as usize > MAX_COPIES)
    {
        return Err(ComputeError::NoGpuKernel {
            physics: "thermal".into(),
            reason: format!(
                "a vertex with {} split copies (node {}); joints that stop conducting when \
                 they break are followed on the device for at most {MAX_COPIES} copies per \
                 vertex: use the CPU",
                groups.start[v + 1] - groups.start[v],
                groups.members[groups.start[v] as usize]
            ),
        });
    }
    let local = |n: u32| -> u32 {
        let v = groups.of[n as usize] as usize;
        let m = &groups.members[groups.start[v] as usize..groups.start[v + 1] as usize];
        m.binary_search(&n).map_or(u32::MAX, |i| i as u32)
    };
    let joints = mesh.interfaces();
    let mut by_vertex: Vec<Vec<[u32; 3]>> = vec![Vec::new(); nv];
    for j in 0..joints.len() {
        let Some(iface) = joints.get(j) else { continue };
        for (a, b) in iface.node_pairs() {
            by_vertex[groups.of[a as usize] as usize].push([j as u32, local(a), local(b)]);
        }
    }
    let mut pair_start = Vec::with_capacity(nv + 1);
    pair_start.push(0u32);
    let mut pairs = Vec::new();
    for list in by_vertex {
        for p in list {
            pairs.extend_from_slice(&p);
        }
        pair_start.push((pairs.len() / 3) as u32);
    }
    Ok(VertexGroups {
        groups,
        pair_start,
        pairs,
    })
}
