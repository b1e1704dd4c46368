// Rock bolts (manual 7.9) on the GPU: the same arithmetic, in the same order, as the CPU
// path of pcdc-bolt (`physics.rs`, `material.rs`). A shared head, then one section per
// kernel after a marker line (two slashes, a bang and its name): `segment_kernel` (axial force per segment), then
// `node_kernel` (bar forces gathered from the node's two segments in a fixed order,
// grout against the host, face plate; writes the node's slot and its host's slots).
//
// Consts: D, NSYM, STRIDE (slots per bolt node, D + 2), SLOT0 (first slot), NONE.
// bs_nodes: 2 nodes per segment; bs_real (BS_STRIDE = 9 per segment): l0, EA, f_t, f_c,
// ε_f, damping, reference vector ΔX;
// bn_u32: node, host, prev, next, 4 host nodes per bolt node; bn_real (14 per node): 4 weights, k_axial,
// k_normal, bond length, plate, 6 bond constants per bolt node.

// Unit vector and length of v (zero vector and 0 for a zero v).
fn unit4(v: array<Real, 3>) -> array<Real, 4> {
    let l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if l > 0.0 {
        let inv = 1.0 / l;
        return array<Real, 4>(v[0] * inv, v[1] * inv, v[2] * inv, l);
    }
    return array<Real, 4>(0.0, 0.0, 0.0, 0.0);
}

fn displacement(n: u32) -> array<Real, 3> {
    var u = array<Real, 3>(0.0, 0.0, 0.0);
    for (var k = 0u; k < D; k = k + 1u) {
        u[k] = disp[n * D + k];
    }
    return u;
}

// A segment's unit direction and elongation (2 ΔX·Δu + Δu·Δu) / (L + L0).
fn segment_state(s: u32) -> array<Real, 4> {
    let u0 = displacement(bs_nodes[2u * s]);
    let u1 = displacement(bs_nodes[2u * s + 1u]);
    let du = array<Real, 3>(u1[0] - u0[0], u1[1] - u0[1], u1[2] - u0[2]);
    let b = BS_STRIDE * s;
    let x = array<Real, 3>(bs_real[b + 6u], bs_real[b + 7u], bs_real[b + 8u]);
    let e = unit4(array<Real, 3>(x[0] + du[0], x[1] + du[1], x[2] + du[2]));
    let q = 2.0 * (x[0] * du[0] + x[1] * du[1] + x[2] * du[2])
        + (du[0] * du[0] + du[1] * du[1] + du[2] * du[2]);
    return array<Real, 4>(e[0], e[1], e[2], q / (e[3] + bs_real[b]));
}

//!segment_kernel
fn kernel(s: u32) {
    let n0 = bs_nodes[2u * s];
    let n1 = bs_nodes[2u * s + 1u];
    let b = BS_STRIDE * s;
    let l0 = bs_real[b];
    let ea = bs_real[b + 1u];
    let ft = bs_real[b + 2u];
    let fc = bs_real[b + 3u];
    let eps_f = bs_real[b + 4u];
    let damp = bs_real[b + 5u];
    let u = segment_state(s);
    let elong = u[3];
    var up = bolt_plastic_elongation[s];
    var f: Real = 0.0;
    var st: Real = 3.0;
    let broken = bolt_state[s] > 2.5;
    if !(broken || elong / l0 >= eps_f) {
        let k = ea / l0;
        let trial = k * (elong - up);
        if trial > ft {
            f = ft;
            up = elong - ft / k;
            st = 1.0;
        } else if trial < -fc {
            f = -fc;
            up = elong + fc / k;
            st = 2.0;
        } else {
            f = trial;
            st = 0.0;
        }
    }
    bolt_axial_force[s] = f;
    bolt_plastic_elongation[s] = up;
    bolt_state[s] = st;
    var total = f;
    if damp > 0.0 && st != 3.0 {
        var rel: Real = 0.0;
        for (var k = 0u; k < D; k = k + 1u) {
            rel = rel + (vel[n1 * D + k] - vel[n0 * D + k]) * u[k];
        }
        total = total + damp * rel;
    }
    for (var k = 0u; k < 3u; k = k + 1u) {
        bs_force[3u * s + k] = total * u[k];
    }
}

//!node_kernel
fn position(n: u32) -> array<Real, 3> {
    var p = array<Real, 3>(0.0, 0.0, 0.0);
    for (var k = 0u; k < D; k = k + 1u) {
        p[k] = coords[n * D + k] + disp[n * D + k];
    }
    return p;
}

// Rotation of a triangle from its reference to its current positions as r (cos, sin),
// r = det(Dm) |..| of any sign: Dx adj(Dm), without a division (as on the CPU).
fn rotation_2d(h: array<u32, 4>) -> array<Real, 2> {
    var xr: array<Real, 6>;
    var xc: array<Real, 6>;
    for (var q = 0u; q < 3u; q = q + 1u) {
        let p = position(h[q]);
        for (var k = 0u; k < 2u; k = k + 1u) {
            xr[2u * q + k] = coords[h[q] * 2u + k];
            xc[2u * q + k] = p[k];
        }
    }
    let dm0 = xr[2] - xr[0];
    let dm1 = xr[4] - xr[0];
    let dm2 = xr[3] - xr[1];
    let dm3 = xr[5] - xr[1];
    let i0 = dm3;
    let i1 = -dm1;
    let i2 = -dm2;
    let i3 = dm0;
    let dx0 = xc[2] - xc[0];
    let dx1 = xc[4] - xc[0];
    let dx2 = xc[3] - xc[1];
    let dx3 = xc[5] - xc[1];
    let f0 = dx0 * i0 + dx1 * i2;
    let f1 = dx0 * i1 + dx1 * i3;
    let f2 = dx2 * i0 + dx3 * i2;
    let f3 = dx2 * i1 + dx3 * i3;
    return array<Real, 2>(f0 + f3, f2 - f1);
}

// Mean compressive normal stress across the axis a at host element e (≥ 0).
fn confinement(e: u32, a: array<Real, 4>, h: array<u32, 4>) -> Real {
    var trace: Real;
    var saa: Real;
    if D == 2u {
        let rot = rotation_2d(h);
        var c = rot[0];
        var sn = rot[1];
        var r2 = c * c + sn * sn;
        if r2 <= 0.0 {
            c = 1.0;
            sn = 0.0;
            r2 = 1.0;
        }
        let ac0 = c * a[0] + sn * a[1];
        let ac1 = -sn * a[0] + c * a[1];
        let s0 = stress[NSYM * e];
        let s1 = stress[NSYM * e + 1u];
        let s2 = stress[NSYM * e + 2u];
        trace = s0 + s1;
        saa = (ac0 * ac0 * s0 + ac1 * ac1 * s1 + 2.0 * ac0 * ac1 * s2) / r2;
    } else {
        var ac: array<Real, 3>;
        for (var i = 0u; i < 3u; i = i + 1u) {
            ac[i] = bolt_rotation(9u * e + i) * a[0] + bolt_rotation(9u * e + 3u + i) * a[1]
                + bolt_rotation(9u * e + 6u + i) * a[2];
        }
        let b = NSYM * e;
        trace = stress[b] + stress[b + 1u] + stress[b + 2u];
        saa = ac[0] * ac[0] * stress[b] + ac[1] * ac[1] * stress[b + 1u]
            + ac[2] * ac[2] * stress[b + 2u]
            + 2.0 * (ac[0] * ac[1] * stress[b + 3u] + ac[1] * ac[2] * stress[b + 4u]
                + ac[0] * ac[2] * stress[b + 5u]);
    }
    return max(-(trace - saa) / Real(D - 1u), 0.0);
}

fn kernel(i: u32) {
    let node = bn_u32[8u * i];
    let host = bn_u32[8u * i + 1u];
    let prev = bn_u32[8u * i + 2u];
    let next = bn_u32[8u * i + 3u];
    let h = array<u32, 4>(bn_u32[8u * i + 4u], bn_u32[8u * i + 5u], bn_u32[8u * i + 6u],
        bn_u32[8u * i + 7u]);
    let r0 = 14u * i;
    let w = array<Real, 4>(bn_real[r0], bn_real[r0 + 1u], bn_real[r0 + 2u], bn_real[r0 + 3u]);
    let k_axial = bn_real[r0 + 4u];
    let k_normal = bn_real[r0 + 5u];
    let bond_length = bn_real[r0 + 6u];
    let plate = bn_real[r0 + 7u];
    var f = array<Real, 3>(0.0, 0.0, 0.0);
    if prev != NONE {
        for (var k = 0u; k < 3u; k = k + 1u) {
            f[k] = f[k] - bs_force[3u * prev + k];
        }
    }
    if next != NONE {
        for (var k = 0u; k < 3u; k = k + 1u) {
            f[k] = f[k] + bs_force[3u * next + k];
        }
    }
    var axis = array<Real, 3>(0.0, 0.0, 0.0);
    if prev != NONE {
        let e = segment_state(prev);
        for (var k = 0u; k < 3u; k = k + 1u) {
            axis[k] = axis[k] + e[k];
        }
    }
    if next != NONE {
        let e = segment_state(next);
        for (var k = 0u; k < 3u; k = k + 1u) {
            axis[k] = axis[k] + e[k];
        }
    }
    let a = unit4(axis);
    // Displacement against the host's material point (zero under rigid motion).
    var r = displacement(node);
    for (var q = 0u; q <= D; q = q + 1u) {
        let u = displacement(h[q]);
        for (var k = 0u; k < 3u; k = k + 1u) {
            r[k] = r[k] - w[q] * u[k];
        }
    }
    let delta = r[0] * a[0] + r[1] * a[1] + r[2] * a[2];
    var fs: Real = 0.0;
    if k_axial > 0.0 {
        let sn = confinement(host, a, h);
        let rock = bn_real[r0 + 8u] * (bn_real[r0 + 9u] + sn * bn_real[r0 + 10u]);
        let bolt = bn_real[r0 + 11u] * (bn_real[r0 + 12u] + sn * bn_real[r0 + 13u]);
        let cap = min(rock, bolt) * bond_length;
        var slip = bolt_slip[i];
        let trial = k_axial * (delta - slip);
        if trial > cap {
            fs = cap;
            slip = delta - cap / k_axial;
        } else if trial < -cap {
            fs = -cap;
            slip = delta + cap / k_axial;
        } else {
            fs = trial;
        }
        bolt_slip[i] = slip;
    }
    bolt_grout_force[i] = fs;
    var g: array<Real, 3>;
    for (var k = 0u; k < 3u; k = k + 1u) {
        g[k] = fs * a[k] + k_normal * (r[k] - delta * a[k]);
    }
    if plate > 0.0 && delta > 0.0 {
        for (var k = 0u; k < 3u; k = k + 1u) {
            g[k] = g[k] + plate * delta * a[k];
        }
    }
    let base = (SLOT0 + i * STRIDE) * D;
    for (var k = 0u; k < D; k = k + 1u) {
        slots[base + k] = f[k] - g[k];
    }
    for (var q = 0u; q <= D; q = q + 1u) {
        for (var k = 0u; k < D; k = k + 1u) {
            slots[base + (q + 1u) * D + k] = w[q] * g[k];
        }
    }
}
