// Fracture flow (manual 7.5) on the GPU: the same arithmetic, in the same order, as the
// CPU path of pcdc-hydro (`flow.rs`, `physics.rs`). One module per kernel; the backend
// keeps only the entry point it is built for (`fn kernel`), so each kernel below is
// spliced in by name: `geometry_kernel`, `volume_kernel`, `leak_start_kernel`,
// `channel_kernel`, `node_kernel`, `pore_kernel`, `force_kernel` (the geometry and force
// kernels also take `points_library`).
//
// hy_info, stride INFO = 3 NPC: the joint's side-A nodes (NPC), side-B nodes (NPC), the
// channel's flow nodes (NPC). Consts: D, NPC, INV_NPC, RHO, MU (dynamic viscosity),
// BULK (K_f as used), DMIN, DMAX, G0..G2 (fluid gravity), G_ABS.

const NONE: u32 = 0xffffffffu;

// f(s) = s²(3 − 2s), s clamped to [0, 1] (eq. 81).
fn sat_weight(s: Real) -> Real {
    let sc = clamp(s, Real(0.0), Real(1.0));
    return sc * sc * (3.0 - 2.0 * sc);
}

fn dot3(a: array<Real, 3>, b: array<Real, 3>) -> Real {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

fn sub3(a: array<Real, 3>, b: array<Real, 3>) -> array<Real, 3> {
    return array<Real, 3>(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
}

fn cross3(a: array<Real, 3>, b: array<Real, 3>) -> array<Real, 3> {
    return array<Real, 3>(
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    );
}

struct Shape {
    measure: Real,
    normal: array<Real, 3>,
    opening: Real,
    weight: array<Real, 3>,
    grad: array<array<Real, 3>, 3>,
}

// `flow::channel_shape`: midplane points and pair gaps of one channel.
fn channel_shape(mid: array<array<Real, 3>, 3>, gap: array<array<Real, 3>, 3>) -> Shape {
    var sh: Shape;
    if NPC == 2u {
        let dx = mid[1][0] - mid[0][0];
        let dy = mid[1][1] - mid[0][1];
        let len = sqrt(dx * dx + dy * dy);
        sh.measure = len;
        if len > 0.0 {
            // One division (as `flow::channel_shape`).
            let inv = 1.0 / len;
            sh.normal = array<Real, 3>(dy * inv, -dx * inv, Real(0.0));
            sh.weight[0] = inv;
            let t0 = dx * (inv * inv);
            let t1 = dy * (inv * inv);
            sh.grad[0] = array<Real, 3>(-t0, -t1, Real(0.0));
            sh.grad[1] = array<Real, 3>(t0, t1, Real(0.0));
        }
    } else {
        let a = sub3(mid[1], mid[0]);
        let b = sub3(mid[2], mid[0]);
        let c = cross3(a, b);
        let twice = sqrt(dot3(c, c));
        sh.measure = 0.5 * twice;
        if twice > 0.0 {
            let inv = 1.0 / twice;
            let n = array<Real, 3>(c[0] * inv, c[1] * inv, c[2] * inv);
            sh.normal = n;
            // Edges (0,1), (1,2), (2,0) with opposite vertices 2, 0, 1.
            let half = 0.5 * inv;
            sh.weight[0] = dot3(sub3(mid[0], mid[2]), sub3(mid[1], mid[2])) * half;
            sh.weight[1] = dot3(sub3(mid[1], mid[0]), sub3(mid[2], mid[0])) * half;
            sh.weight[2] = dot3(sub3(mid[2], mid[1]), sub3(mid[0], mid[1])) * half;
            for (var k = 0u; k < 3u; k = k + 1u) {
                let g = cross3(n, sub3(mid[(k + 2u) % 3u], mid[(k + 1u) % 3u]));
                sh.grad[k] = array<Real, 3>(g[0] * inv, g[1] * inv, g[2] * inv);
            }
        }
    }
    var o = Real(0.0);
    for (var k = 0u; k < NPC; k = k + 1u) {
        o = o + dot3(gap[k], sh.normal);
    }
    sh.opening = o / Real(NPC);
    return sh;
}

//!points_library
// Midplane points and gaps of channel c from the current positions (geometry and force
// kernels, which bind `coords` and `disp`).
fn channel_points(c: u32, mid: ptr<function, array<array<Real, 3>, 3>>, gap: ptr<function, array<array<Real, 3>, 3>>) {
    let r = c * INFO;
    for (var k = 0u; k < NPC; k = k + 1u) {
        let na = hy_info[r + k] * D;
        let nb = hy_info[r + NPC + k] * D;
        for (var q = 0u; q < D; q = q + 1u) {
            let xa = coords[na + q] + disp[na + q];
            let xb = coords[nb + q] + disp[nb + q];
            (*mid)[k][q] = 0.5 * (xa + xb);
            (*gap)[k][q] = xb - xa;
        }
    }
}

//!geometry_kernel
// Per channel, after the position update: shape, aperture (eq. 79), weights, gradients
// and g·m_k.
fn kernel(c: u32) {
    var mid: array<array<Real, 3>, 3>;
    var gap: array<array<Real, 3>, 3>;
    channel_points(c, &mid, &gap);
    for (var k = 0u; k < NPC; k = k + 1u) {
        hy_gpot[c * NPC + k] = G0 * mid[k][0] + G1 * mid[k][1] + G2 * mid[k][2];
    }
    let sh = channel_shape(mid, gap);
    hy_measure[c] = sh.measure;
    let delta = clamp(hy_delta0[c] + sh.opening, DMIN, DMAX);
    channel_aperture[c] = delta;
    // Calibrated channels blend from their calibrated weights to their own as they open.
    var beta = Real(0.0);
    let dr = hy_delta_ref[c];
    if (dr > 0.0) {
        let r = min(dr / delta, Real(1.0));
        beta = r * r * r;
    }
    for (var e = 0u; e < 3u; e = e + 1u) {
        let w = sh.weight[e];
        hy_weight[c * 3u + e] = w + beta * (hy_calib[c * 3u + e] - w);
    }
    for (var k = 0u; k < NPC; k = k + 1u) {
        for (var q = 0u; q < D; q = q + 1u) {
            hy_grad[(c * NPC + k) * D + q] = sh.grad[k][q];
        }
    }
}

//!volume_kernel
// Per flow node: V_l = Σ A δ / N over its channels, in incidence order.
fn kernel(l: u32) {
    var sum = Real(0.0);
    for (var i = hy_inc_ptr[l]; i < hy_inc_ptr[l + 1u]; i = i + 1u) {
        let c = hy_inc[i] / NPC;
        sum = sum + hy_measure[c] * channel_aperture[c] * INV_NPC;
    }
    hy_volume[l] = sum;
}

//!leak_start_kernel
// Per channel: leak-off starts when the joint has broken.
fn kernel(c: u32) {
    if channel_leak_age[c] < 0.0 && joint_damage[hy_joint[c]] >= 1.0 {
        channel_leak_age[c] = Real(0.0);
    }
}

//!channel_kernel
// Per channel, each fluid step: nodal volume shares (eq. 82–83 corrected), flux
// (eq. 75, 80) and leak-off (eq. 86–88 corrected).
fn kernel(c: u32) {
    let dt = p_dt() * FIELD_DT_SCALE;
    let r = c * INFO + 2u * NPC;
    var psi: array<Real, 3>;
    var fw: array<Real, 3>;
    var s_mean = Real(0.0);
    var p_mean = Real(0.0);
    for (var k = 0u; k < NPC; k = k + 1u) {
        let l = hy_info[r + k];
        psi[k] = flow_pressure[l] - RHO * hy_gpot[c * NPC + k];
        fw[k] = sat_weight(flow_saturation[l]);
        s_mean = s_mean + flow_saturation[l];
        p_mean = p_mean + flow_pressure[l];
    }
    s_mean = s_mean * INV_NPC;
    p_mean = p_mean * INV_NPC;
    let fs = sat_weight(s_mean);
    let delta = channel_aperture[c];
    let k_full = delta * delta * delta / (12.0 * MU);
    let k = k_full * fs;
    // Each edge carries the saturation weight of the node its flow leaves.
    let kdt = k_full * dt;
    var share: array<Real, 3>;
    if NPC == 2u {
        let q0 = kdt * hy_weight[c * 3u] * (psi[0] - psi[1]);
        let q = q0 * select(fw[1], fw[0], q0 > 0.0);
        share[0] = -q;
        share[1] = q;
    } else {
        for (var e = 0u; e < 3u; e = e + 1u) {
            let i = e;
            let j = (e + 1u) % 3u;
            let q0 = kdt * hy_weight[c * 3u + e] * (psi[i] - psi[j]);
            let q = q0 * select(fw[j], fw[i], q0 > 0.0);
            share[i] = share[i] - q;
            share[j] = share[j] + q;
        }
    }
    for (var k2 = 0u; k2 < NPC; k2 = k2 + 1u) {
        hy_share[c * NPC + k2] = share[k2];
    }
    var q = array<Real, 3>(Real(0.0), Real(0.0), Real(0.0));
    for (var j = 0u; j < NPC; j = j + 1u) {
        for (var d = 0u; d < 3u; d = d + 1u) {
            var g = Real(0.0);
            if d < D {
                g = hy_grad[(c * NPC + j) * D + d];
            }
            q[d] = q[d] - k * psi[j] * g;
        }
    }
    for (var d = 0u; d < D; d = d + 1u) {
        channel_flux[c * D + d] = q[d];
    }
    var leak = Real(0.0);
    if LEAK == 1u {
        let age = channel_leak_age[c];
        if age >= 0.0 {
            let dp = p_mean - LEAK_PS;
            var cl = Real(0.0);
            if dp > 0.0 {
                cl = dp * sqrt(LEAK_KS * LEAK_NS * (1.0 / BULK + LEAK_CS) / (PI * MU));
            }
            let s0 = sqrt(max(age, Real(0.0)));
            let s1 = sqrt(max(age + dt, Real(0.0)));
            leak = fs * (4.0 * hy_measure[c] * cl * (s1 - s0)) / Real(NPC);
            channel_leak_age[c] = age + dt;
        }
    }
    hy_leak[c] = leak;
}

//!node_kernel
// Per flow node, each fluid step: content (eq. 83–85 in conservative form), conditions,
// pressure and saturation, balance terms.
fn kernel(l: u32) {
    let dt = p_dt() * FIELD_DT_SCALE;
    var gain = Real(0.0);
    var lost = Real(0.0);
    for (var i = hy_inc_ptr[l]; i < hy_inc_ptr[l + 1u]; i = i + 1u) {
        let e = hy_inc[i];
        gain = gain + hy_share[e];
        lost = lost + hy_leak[e / NPC];
    }
    var inject = Real(0.0);
    for (var i = hy_rate_ptr[l]; i < hy_rate_ptr[l + 1u]; i = i + 1u) {
        inject = inject + signal(hy_rate_sig[i]) * hy_rate_share[i] * dt;
    }
    let trial = flow_stored[l] + gain - lost + inject;
    flow_balance[l * 4u + 1u] = flow_balance[l * 4u + 1u] + inject;
    flow_balance[l * 4u + 3u] = flow_balance[l * 4u + 3u] + lost;
    let v = hy_volume[l];
    let w0 = flow_balance[l * 4u];
    var next = trial;
    let kind = hy_bc[l * 2u];
    if kind != 0u {
        let value = signal(hy_bc[l * 2u + 1u]);
        var held = false;
        var ph = Real(0.0);
        if kind == 2u {
            ph = RHO * G_ABS * (value - hy_elev[l]);
            held = ph > 0.0;
            // Above the water level, a seepage face: no pressure above atmospheric.
            if !held && w0 + trial > v {
                ph = Real(0.0);
                held = true;
            }
        } else {
            ph = max(value, Real(0.0));
            held = true;
        }
        if held {
            next = v * (1.0 + ph / BULK) - w0;
            flow_balance[l * 4u + 2u] = flow_balance[l * 4u + 2u] + (next - trial);
        }
    }
    flow_stored[l] = next;
    let w = w0 + next;
    var p = Real(0.0);
    var s = Real(1.0);
    if w >= v {
        p = BULK * (w / v - 1.0);
    } else {
        s = max(w / v, Real(0.0));
    }
    flow_pressure[l] = p;
    flow_peak_pressure[l] = max(flow_peak_pressure[l], p);
    flow_saturation[l] = s;
    if !(abs(p) <= REAL_MAX) {
        atomicMin(&status[2], ERR_DIVERGED);
        atomicMin(&status[3], l);
    }
}

//!pore_kernel
// Per mesh node: the pressure of its flow node (0 off the network).
fn kernel(n: u32) {
    let f = hy_mesh_flow[n];
    if f == NONE {
        pore_pressure[n] = Real(0.0);
    } else {
        pore_pressure[n] = flow_pressure[f];
    }
}

//!force_kernel
// Per channel (two-way coupling): the linear pressure integrated over both faces,
// ∫ N_k p dA, side A against the normal, side B along it.
fn kernel(c: u32) {
    var mid: array<array<Real, 3>, 3>;
    var gap: array<array<Real, 3>, 3>;
    channel_points(c, &mid, &gap);
    // A n without the square root, as `flow::area_normal`.
    var an: array<Real, 3>;
    if NPC == 2u {
        an = array<Real, 3>(mid[1][1] - mid[0][1], -(mid[1][0] - mid[0][0]), Real(0.0));
    } else {
        let cr = cross3(sub3(mid[1], mid[0]), sub3(mid[2], mid[0]));
        an = array<Real, 3>(0.5 * cr[0], 0.5 * cr[1], 0.5 * cr[2]);
    }
    let r = c * INFO + 2u * NPC;
    var pk: array<Real, 3>;
    for (var k = 0u; k < NPC; k = k + 1u) {
        pk[k] = flow_pressure[hy_info[r + k]];
    }
    let s0 = (SLOT_FIRST + 2u * NPC * c) * D;
    for (var k = 0u; k < NPC; k = k + 1u) {
        var f = Real(0.0);
        if NPC == 2u {
            f = (2.0 * pk[k] + pk[1u - k]) / 6.0;
        } else {
            f = (pk[k] + pk[0] + pk[1] + pk[2]) / 12.0;
        }
        for (var q = 0u; q < D; q = q + 1u) {
            slots[s0 + k * D + q] = -f * an[q];
            slots[s0 + (NPC + k) * D + q] = f * an[q];
        }
    }
}
