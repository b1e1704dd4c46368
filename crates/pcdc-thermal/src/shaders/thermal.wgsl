// Heat conduction (manual 7.6) on the GPU: the same arithmetic, in the same order, as
// the CPU path of pcdc-thermal (`conduction.rs`, `physics.rs`). One module per kernel,
// spliced in by name after the shared head: `element_kernel`, `node_kernel`,
// `group_kernel`, `write_kernel`.
//
// Consts: D, NPE, FREE (no condition), ERR_DIVERGED. th_k holds k_ij of each material
// (9 values, row-major 3 × 3); th_cond_kind 0 flux, 1 convection.
//
// Fluid heat (`fluid.rs`): `fluid_channel_kernel`, `fluid_node_kernel` (before the node
// kernel: they read the solid's temperatures at the start of the step) and
// `fluid_wall_kernel` (after it: the walls' exchange at the fluid's new temperatures).
// Consts NPC (nodes per channel), RC = ρ_f C_f, KF = k_f, HSF = h_sf. fl_slots holds 5
// values per channel node: volume share, exchange H, inflow, inflow heat, conducted.

//!element_kernel
// Per element: ∇T, q = −k ∇T (heat_flux) and the nodal rates R_a = Ω ∇N_a · q (eq. 95–98).
fn kernel(e: u32) {
    let m = th_material[e];
    var t: array<Real, 4>;
    for (var a = 0u; a < NPE; a = a + 1u) {
        t[a] = temperature[th_conn[e * NPE + a]];
    }
    let g0 = e * NPE * D;
    var gt = array<Real, 3>(0.0, 0.0, 0.0);
    for (var a = 0u; a < NPE; a = a + 1u) {
        for (var i = 0u; i < D; i = i + 1u) {
            gt[i] = gt[i] + t[a] * th_grad[g0 + a * D + i];
        }
    }
    var q = array<Real, 3>(0.0, 0.0, 0.0);
    for (var i = 0u; i < D; i = i + 1u) {
        for (var j = 0u; j < D; j = j + 1u) {
            q[i] = q[i] - th_k[m * 9u + i * 3u + j] * gt[j];
        }
    }
    for (var i = 0u; i < D; i = i + 1u) {
        heat_flux[e * D + i] = q[i];
    }
    let vol = th_measure[e];
    for (var a = 0u; a < NPE; a = a + 1u) {
        var s = Real(0.0);
        for (var i = 0u; i < D; i = i + 1u) {
            s = s + th_grad[g0 + a * D + i] * q[i];
        }
        th_rates[e * NPE + a] = vol * s;
    }
}

//!node_kernel
// Per node: its element slots in a fixed order, then its face conditions (eq. 100–101).
fn kernel(n: u32) {
    var s = Real(0.0);
    for (var k = th_slot_start[n]; k < th_slot_start[n + 1u]; k = k + 1u) {
        s = s + th_rates[th_slots[k]];
    }
    var b = Real(0.0);
    for (var j = th_entry_start[n]; j < th_entry_start[n + 1u]; j = j + 1u) {
        let c = th_entry_cond[j];
        let v = signal(th_cond_signal[c]);
        var x = v;
        if th_cond_kind[c] == 1u {
            x = th_cond_h[c] * (v - temperature[n]);
        }
        b = b + th_entry_share[j] * x;
    }
    th_node_rate[n] = s + b;
    th_node_bnd[n] = b;
}

//!contact_kernel
// Per node, after its rate: heat across its pairs on broken joints whose faces touch
// (contact.rs; eq. 111–112), opening in [−L/2, 0] and sliding below L/2.
fn kernel(n: u32) {
    var r = Real(0.0);
    for (var e = th_ct_ptr[n]; e < th_ct_ptr[n + 1u]; e = e + 1u) {
        let j = th_ct_entries[2u * e];
        let m = th_ct_entries[2u * e + 1u];
        let size = th_ct_size[j];
        let o = joint_opening[j];
        var s2 = Real(0.0);
        for (var q = 0u; q < D; q = q + 1u) {
            let x = joint_sliding[j * D + q];
            s2 = s2 + x * x;
        }
        let touching = o <= 0.0 && o >= -0.5 * size && s2 <= 0.25 * size * size;
        if joint_damage[j] >= 1.0 && touching {
            r = r + HC * th_ct_share[e] * (temperature[m] - temperature[n]);
        }
    }
    th_node_rate[n] = th_node_rate[n] + r;
}

//!group_kernel
// Per thermal node: one explicit update (eq. 94, 99 corrected), or the held value.
fn kernel(g: u32) {
    let dt = p_dt() * FIELD_DT_SCALE;
    var r = Real(0.0);
    var c = Real(0.0);
    var held = FREE;
    let first = th_group_start[g];
    for (var k = first; k < th_group_start[g + 1u]; k = k + 1u) {
        let n = th_members[k];
        r = r + th_node_rate[n];
        c = c + heat_capacity[n];
        if th_fixed[n] != FREE {
            held = th_fixed[n];
        }
    }
    let unheld = temperature[th_members[first]] + dt * r / c;
    var next = unheld;
    if held != FREE {
        next = signal(held);
    }
    th_group_temp[2u * g] = unheld;
    th_group_temp[2u * g + 1u] = next;
}

//!vertex_group_kernel
// Per original vertex, with joints that stop conducting when they break: its split
// copies joined by intact joints (damage < 1) form the thermal nodes (smallest local
// index names each), each updated as in group_kernel, members in ascending order; the
// result goes to every member node (th_group_of is the identity here).
fn kernel(v: u32) {
    let dt = p_dt() * FIELD_DT_SCALE;
    let first = th_group_start[v];
    let count = th_group_start[v + 1u] - first;
    var parent: array<u32, MAXV>;
    for (var i = 0u; i < count; i = i + 1u) {
        parent[i] = i;
    }
    for (var p = th_pair_start[v]; p < th_pair_start[v + 1u]; p = p + 1u) {
        if joint_damage[th_pairs[3u * p]] >= 1.0 {
            continue;
        }
        var a = th_pairs[3u * p + 1u];
        while parent[a] != a {
            a = parent[a];
        }
        var b = th_pairs[3u * p + 2u];
        while parent[b] != b {
            b = parent[b];
        }
        parent[max(a, b)] = min(a, b);
    }
    for (var i = 0u; i < count; i = i + 1u) {
        var r = i;
        while parent[r] != r {
            r = parent[r];
        }
        parent[i] = r;
    }
    for (var root = 0u; root < count; root = root + 1u) {
        if parent[root] != root {
            continue;
        }
        var rate = Real(0.0);
        var c = Real(0.0);
        var held = FREE;
        for (var i = root; i < count; i = i + 1u) {
            if parent[i] == root {
                let n = th_members[first + i];
                rate = rate + th_node_rate[n];
                c = c + heat_capacity[n];
                if th_fixed[n] != FREE {
                    held = th_fixed[n];
                }
            }
        }
        let unheld = temperature[th_members[first + root]] + dt * rate / c;
        var next = unheld;
        if held != FREE {
            next = signal(held);
        }
        for (var i = root; i < count; i = i + 1u) {
            if parent[i] == root {
                let n = th_members[first + i];
                th_group_temp[2u * n] = unheld;
                th_group_temp[2u * n + 1u] = next;
            }
        }
    }
}

//!write_kernel
// Per node: the group's temperature and the heat supplied from outside.
fn kernel(n: u32) {
    let dt = p_dt() * FIELD_DT_SCALE;
    let g = th_group_of[n];
    let unheld = th_group_temp[2u * g];
    let next = th_group_temp[2u * g + 1u];
    heat_supplied[n] = heat_supplied[n] + (dt * th_node_bnd[n] + heat_capacity[n] * (next - unheld));
    temperature[n] = next;
    if !(abs(next) <= REAL_MAX) {
        atomicMin(&status[2], ERR_DIVERGED);
        atomicMin(&status[3], n);
    }
}

//!fluid_channel_kernel
// Per channel: midplane geometry, upwind inflow and conduction per channel node.
fn sat_weight(s: Real) -> Real {
    let x = clamp(s, Real(0.0), Real(1.0));
    return x * x * (3.0 - 2.0 * x);
}

fn sub3(a: array<Real, 3>, b: array<Real, 3>) -> array<Real, 3> {
    return array<Real, 3>(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

fn dot3(a: array<Real, 3>, b: array<Real, 3>) -> Real {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

fn cross3(a: array<Real, 3>, b: array<Real, 3>) -> array<Real, 3> {
    return array<Real, 3>(a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]);
}

fn kernel(c: u32) {
    var m: array<array<Real, 3>, 3>;
    for (var k = 0u; k < NPC; k = k + 1u) {
        let na = fl_walls[c * 2u * NPC + k] * D;
        let nb = fl_walls[c * 2u * NPC + NPC + k] * D;
        for (var q = 0u; q < D; q = q + 1u) {
            let xa = coords[na + q] + disp[na + q];
            let xb = coords[nb + q] + disp[nb + q];
            m[k][q] = 0.5 * (xa + xb);
        }
    }
    var qf = array<Real, 3>(0.0, 0.0, 0.0);
    for (var d = 0u; d < D; d = d + 1u) {
        qf[d] = channel_flux[c * D + d];
    }
    var measure = Real(0.0);
    var weight = array<Real, 3>(0.0, 0.0, 0.0);
    var rate = array<Real, 3>(0.0, 0.0, 0.0);
    var ei = array<u32, 3>(0u, 1u, 2u);
    var ej = array<u32, 3>(1u, 2u, 0u);
    var ek = array<u32, 3>(0u, 0u, 1u);
    var ne = 3u;
    if NPC == 2u {
        ne = 1u;
        let t = sub3(m[1], m[0]);
        let len = sqrt(dot3(t, t));
        if len > 0.0 {
            measure = len;
            weight[0] = 1.0 / len;
            rate[0] = dot3(qf, t) / len;
        }
    } else {
        ek = array<u32, 3>(2u, 0u, 1u);
        let nrm = cross3(sub3(m[1], m[0]), sub3(m[2], m[0]));
        let twice = sqrt(dot3(nrm, nrm));
        if twice > 0.0 {
            measure = 0.5 * twice;
            var cen: array<Real, 3>;
            for (var d = 0u; d < 3u; d = d + 1u) {
                cen[d] = (m[0][d] + m[1][d] + m[2][d]) / 3.0;
            }
            for (var e = 0u; e < 3u; e = e + 1u) {
                let i = ei[e];
                let j = ej[e];
                let k = ek[e];
                weight[e] = dot3(sub3(m[i], m[k]), sub3(m[j], m[k])) / (4.0 * measure);
                var mid: array<Real, 3>;
                for (var d = 0u; d < 3u; d = d + 1u) {
                    mid[d] = 0.5 * (m[i][d] + m[j][d]);
                }
                let seg = sub3(cen, mid);
                var n = cross3(seg, nrm);
                n = array<Real, 3>(n[0] / twice, n[1] / twice, n[2] / twice);
                if dot3(n, sub3(m[j], m[i])) < 0.0 {
                    n = array<Real, 3>(-n[0], -n[1], -n[2]);
                }
                rate[e] = dot3(qf, n);
            }
        }
    }
    let ap = channel_aperture[c];
    var vol: array<Real, 3>;
    var exch: array<Real, 3>;
    var inflow = array<Real, 3>(0.0, 0.0, 0.0);
    var heat_in = array<Real, 3>(0.0, 0.0, 0.0);
    var cond = array<Real, 3>(0.0, 0.0, 0.0);
    var l: array<u32, 3>;
    for (var k = 0u; k < NPC; k = k + 1u) {
        l[k] = fl_channel_nodes[c * NPC + k];
        vol[k] = ap * measure / Real(NPC);
        exch[k] = HSF * measure * sat_weight(flow_saturation[l[k]]) / Real(NPC);
    }
    for (var e = 0u; e < ne; e = e + 1u) {
        let i = ei[e];
        let j = ej[e];
        let a = l[i];
        let b = l[j];
        let f = rate[e] * RC;
        if f > 0.0 {
            inflow[j] = inflow[j] + f;
            heat_in[j] = heat_in[j] + f * fluid_temperature[a];
        } else if f < 0.0 {
            inflow[i] = inflow[i] - f;
            heat_in[i] = heat_in[i] - f * fluid_temperature[b];
        }
        let g = KF * ap * clamp(min(flow_saturation[a], flow_saturation[b]), Real(0.0), Real(1.0)) * weight[e];
        let h = g * (fluid_temperature[b] - fluid_temperature[a]);
        cond[i] = cond[i] + h;
        cond[j] = cond[j] - h;
    }
    for (var k = 0u; k < NPC; k = k + 1u) {
        let o = (c * NPC + k) * 5u;
        fl_slots[o] = vol[k];
        fl_slots[o + 1u] = exch[k];
        fl_slots[o + 2u] = inflow[k];
        fl_slots[o + 3u] = heat_in[k];
        fl_slots[o + 4u] = cond[k];
    }
}

//!fluid_node_kernel
// Per flow node: the point-implicit update (or the held value) and the heat balance.
fn kernel(l: u32) {
    let dt = p_dt() * FIELD_DT_SCALE;
    var vol = Real(0.0);
    var a_in = Real(0.0);
    var b_in = Real(0.0);
    var h = Real(0.0);
    var ht = Real(0.0);
    var cond = Real(0.0);
    for (var x = fl_inc_ptr[l]; x < fl_inc_ptr[l + 1u]; x = x + 1u) {
        let e = fl_incidence[x];
        let o = e * 5u;
        let c = e / NPC;
        let k = e % NPC;
        vol = vol + fl_slots[o];
        a_in = a_in + fl_slots[o + 2u];
        b_in = b_in + fl_slots[o + 3u];
        cond = cond + fl_slots[o + 4u];
        h = h + 2.0 * fl_slots[o + 1u];
        let wa = fl_walls[c * 2u * NPC + k];
        let wb = fl_walls[c * 2u * NPC + NPC + k];
        ht = ht + fl_slots[o + 1u] * (temperature[wa] + temperature[wb]);
    }
    let c_new = RC * clamp(flow_saturation[l], Real(0.0), Real(1.0)) * vol;
    let t_old = fluid_temperature[l];
    fluid_heat_balance[l * 4u + 3u] = fluid_heat_balance[l * 4u + 3u] + t_old * (c_new - fluid_heat_capacity[l]);
    let den = c_new + dt * (a_in + h);
    var unheld = t_old;
    if den > 0.0 {
        unheld = (c_new * t_old + dt * (b_in + ht + cond)) / den;
    }
    var next = unheld;
    if fl_fixed[l] != FREE {
        next = signal(fl_fixed[l]);
    }
    let adv = b_in - a_in * next;
    let ex = ht - h * next;
    fluid_heat_balance[l * 4u + 1u] = fluid_heat_balance[l * 4u + 1u] + (c_new * (next - t_old) - dt * (adv + ex + cond));
    fluid_heat_balance[l * 4u + 2u] = fluid_heat_balance[l * 4u + 2u] + dt * adv;
    fluid_temperature[l] = next;
    fluid_heat_capacity[l] = c_new;
    if !(abs(next) <= REAL_MAX) {
        atomicMin(&status[2], ERR_DIVERGED);
        atomicMin(&status[3], l);
    }
}

//!fluid_wall_kernel
// Per mesh node: the exchange with the fluid of the channels it walls, after its rate.
fn kernel(n: u32) {
    var w = Real(0.0);
    for (var x = fl_wall_ptr[n]; x < fl_wall_ptr[n + 1u]; x = x + 1u) {
        let e = fl_wall_slots[x];
        w = w + fl_slots[e * 5u + 1u] * (fluid_temperature[fl_channel_nodes[e]] - temperature[n]);
    }
    th_node_rate[n] = th_node_rate[n] + w;
}
