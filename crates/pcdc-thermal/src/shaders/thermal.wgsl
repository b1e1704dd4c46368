// Heat conduction (manual 7.6) on the GPU: the same arithmetic, in the same order, as
// the CPU path of pcdc-thermal (`conduction.rs`, `physics.rs`). One module per kernel,
// spliced in by name after the shared head: `element_kernel`, `node_kernel`,
// `group_kernel`, `write_kernel`.
//
// Consts: D, NPE, FREE (no condition), ERR_DIVERGED. th_k holds k_ij of each material
// (9 values, row-major 3 × 3); th_cond_kind 0 flux, 1 convection.

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
