// Rock bolts (manual 7.9) on the GPU: the same arithmetic, in the same order, as the CPU
// path of pcdc-bolt (`walk.rs`, `material.rs`). A shared head, then one section per
// kernel after a marker line (two slashes, a bang and its name): `segment_kernel` (axial
// force per segment), `node_kernel` (bar forces gathered from the node's two segments in
// a fixed order, re-location, grout against the host, face plate; writes the node's slot
// and its grout vector), then `host_kernel` (per node of the elements on a bolt's path:
// the grout reactions of the bolt nodes its elements host, in node order, into its slot).
//
// Consts: D, NSYM, SLOT0 (first slot), NONE, ALEN (2D + 3 values of bolt_anchor per node).
// bs_nodes: 2 nodes per segment; bs_real (BS_STRIDE = 9 per segment): l0, EA, f_t, f_c,
// ε_f, damping, reference vector ΔX;
// bn_u32 (6 per bolt node): node, prev, next, first and end candidate (path index), slot;
// bn_real (11 per node): k_axial, k_normal, bond length, plate, 6 bond constants, lateral
// damping;
// bp_u32 (5 per path element): element, 4 nodes;
// bq_u32 (5 per path node): slot, first and end bolt node that may add to it, first and
// end of its (path element, corner) pairs in bq_refs;
// bolt_anchor (ALEN per node): candidate index, D + 1 weights, D offsets, margin, axial
// displacement carried over.

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

fn path_nodes(j: u32) -> array<u32, 4> {
    return array<u32, 4>(bp_u32[5u * j + 1u], bp_u32[5u * j + 2u], bp_u32[5u * j + 3u],
        bp_u32[5u * j + 4u]);
}

// Current positions of a path element's D + 1 nodes (stride D).
fn element_positions(h: array<u32, 4>) -> array<Real, 12> {
    var x: array<Real, 12>;
    for (var q = 0u; q <= D; q = q + 1u) {
        let p = position(h[q]);
        for (var k = 0u; k < D; k = k + 1u) {
            x[q * D + k] = p[k];
        }
    }
    return x;
}

fn det3(a: array<Real, 3>, b: array<Real, 3>, c: array<Real, 3>) -> Real {
    return a[0] * (b[1] * c[2] - b[2] * c[1]) - b[0] * (a[1] * c[2] - a[2] * c[1])
        + c[0] * (a[1] * b[2] - a[2] * b[1]);
}

// Barycentric coordinates of p in the simplex x (as `host::barycentric`).
fn barycentric(x: array<Real, 12>, p: array<Real, 3>) -> array<Real, 4> {
    var w = array<Real, 4>(0.0, 0.0, 0.0, 0.0);
    if D == 2u {
        let a = x[2] - x[0];
        let b = x[4] - x[0];
        let c = x[3] - x[1];
        let e = x[5] - x[1];
        let det = a * e - b * c;
        let px = p[0] - x[0];
        let py = p[1] - x[1];
        w[1] = (e * px - b * py) / det;
        w[2] = (a * py - c * px) / det;
        w[0] = 1.0 - w[1] - w[2];
    } else {
        let c1 = array<Real, 3>(x[3] - x[0], x[4] - x[1], x[5] - x[2]);
        let c2 = array<Real, 3>(x[6] - x[0], x[7] - x[1], x[8] - x[2]);
        let c3 = array<Real, 3>(x[9] - x[0], x[10] - x[1], x[11] - x[2]);
        let r = array<Real, 3>(p[0] - x[0], p[1] - x[1], p[2] - x[2]);
        let det = det3(c1, c2, c3);
        w[1] = det3(r, c2, c3) / det;
        w[2] = det3(c1, r, c3) / det;
        w[3] = det3(c1, c2, r) / det;
        w[0] = 1.0 - w[1] - w[2] - w[3];
    }
    return w;
}

fn smallest(w: array<Real, 4>) -> Real {
    var m = w[0];
    for (var q = 1u; q <= D; q = q + 1u) {
        m = min(m, w[q]);
    }
    return m;
}

fn sub3(x: array<Real, 12>, a: u32, b: u32) -> array<Real, 3> {
    return array<Real, 3>(x[3u * a] - x[3u * b], x[3u * a + 1u] - x[3u * b + 1u],
        x[3u * a + 2u] - x[3u * b + 2u]);
}

fn cross_norm(a: array<Real, 3>, b: array<Real, 3>) -> Real {
    let c0 = a[1] * b[2] - a[2] * b[1];
    let c1 = a[2] * b[0] - a[0] * b[2];
    let c2 = a[0] * b[1] - a[1] * b[0];
    return sqrt(c0 * c0 + c1 * c1 + c2 * c2);
}

// The smallest height of the simplex x (as `host::min_height`).
fn min_height(x: array<Real, 12>) -> Real {
    if D == 2u {
        let det = (x[2] - x[0]) * (x[5] - x[1]) - (x[4] - x[0]) * (x[3] - x[1]);
        let e01 = sqrt((x[0] - x[2]) * (x[0] - x[2]) + (x[1] - x[3]) * (x[1] - x[3]));
        let e12 = sqrt((x[2] - x[4]) * (x[2] - x[4]) + (x[3] - x[5]) * (x[3] - x[5]));
        let e02 = sqrt((x[0] - x[4]) * (x[0] - x[4]) + (x[1] - x[5]) * (x[1] - x[5]));
        return abs(det) / max(max(e01, e12), e02);
    }
    let e1 = sub3(x, 1u, 0u);
    let e2 = sub3(x, 2u, 0u);
    let e3 = sub3(x, 3u, 0u);
    let vol6 = abs(det3(e3, e1, e2));
    var area2 = cross_norm(e1, e2);
    area2 = max(area2, cross_norm(e1, e3));
    area2 = max(area2, cross_norm(e2, e3));
    area2 = max(area2, cross_norm(sub3(x, 2u, 1u), sub3(x, 3u, 1u)));
    return vol6 / area2;
}

// As `walk::margin`.
fn margin(wmin: Real, h: Real) -> Real {
    return max((wmin + LEAVE) * h / STRETCH, 0.0);
}

// Node displacement relative to its grout point (as `walk::relative_disp`).
fn relative_disp(node: u32, j: u32, a0: u32) -> array<Real, 3> {
    var r = displacement(node);
    for (var k = 0u; k < D; k = k + 1u) {
        r[k] = r[k] + bolt_anchor[a0 + D + 2u + k];
    }
    let h = path_nodes(j);
    for (var q = 0u; q <= D; q = q + 1u) {
        let u = displacement(h[q]);
        let w = bolt_anchor[a0 + 1u + q];
        for (var k = 0u; k < 3u; k = k + 1u) {
            r[k] = r[k] - w * u[k];
        }
    }
    return r;
}

// As `walk::relocate`: the new host's path index (anchor written), or NONE.
fn relocate(node: u32, c0: u32, c1: u32, a0: u32, a: array<Real, 4>, r: array<Real, 3>,
        delta: Real) -> u32 {
    let own = c0 + u32(bolt_anchor[a0]);
    let xn = position(node);
    var lateral: array<Real, 3>;
    var p: array<Real, 3>;
    for (var k = 0u; k < 3u; k = k + 1u) {
        lateral[k] = r[k] - delta * a[k];
        p[k] = xn[k] - lateral[k];
    }
    if smallest(barycentric(element_positions(path_nodes(own)), p)) >= -LEAVE {
        return NONE;
    }
    var best = NONE;
    var best_m: Real = 0.0;
    var best_w: array<Real, 4>;
    var best_x: array<Real, 12>;
    for (var j = c0; j < c1; j = j + 1u) {
        if j == own {
            continue;
        }
        let x = element_positions(path_nodes(j));
        let w = barycentric(x, p);
        let m = smallest(w);
        if best == NONE || m > best_m {
            best = j;
            best_m = m;
            best_w = w;
            best_x = x;
        }
    }
    if best == NONE || !(best_m >= -ENTER) {
        return NONE;
    }
    let un = displacement(node);
    let h = path_nodes(best);
    bolt_anchor[a0] = Real(best - c0);
    for (var q = 0u; q <= D; q = q + 1u) {
        bolt_anchor[a0 + 1u + q] = best_w[q];
    }
    for (var k = 0u; k < D; k = k + 1u) {
        var v = un[k];
        for (var q = 0u; q <= D; q = q + 1u) {
            let u = displacement(h[q]);
            v = v - best_w[q] * u[k];
        }
        bolt_anchor[a0 + D + 2u + k] = lateral[k] - v;
    }
    bolt_anchor[a0 + 2u * D + 2u] = margin(best_m, min_height(best_x));
    return best;
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
    let node = bn_u32[6u * i];
    let prev = bn_u32[6u * i + 1u];
    let next = bn_u32[6u * i + 2u];
    let c0 = bn_u32[6u * i + 3u];
    let c1 = bn_u32[6u * i + 4u];
    let slot = bn_u32[6u * i + 5u];
    let r0 = 11u * i;
    let k_axial = bn_real[r0];
    let k_normal = bn_real[r0 + 1u];
    let bond_length = bn_real[r0 + 2u];
    let plate = bn_real[r0 + 3u];
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
    // Against the host's material point where the node is grouted.
    let a0 = ALEN * i;
    var j = c0 + u32(bolt_anchor[a0]);
    var r = relative_disp(node, j, a0);
    var delta = r[0] * a[0] + r[1] * a[1] + r[2] * a[2];
    var slip = bolt_slip[i];
    if abs(delta) > bolt_anchor[a0 + 2u * D + 2u] && c1 - c0 > 1u {
        let moved = relocate(node, c0, c1, a0, a, r, delta);
        if moved != NONE {
            bolt_anchor[a0 + 2u * D + 3u] = bolt_anchor[a0 + 2u * D + 3u] + delta;
            j = moved;
            bolt_host[i] = Real(bp_u32[5u * j]);
            r = relative_disp(node, j, a0);
        }
    }
    let dl = r[0] * a[0] + r[1] * a[1] + r[2] * a[2];
    var lateral: array<Real, 3>;
    for (var k = 0u; k < 3u; k = k + 1u) {
        lateral[k] = r[k] - dl * a[k];
    }
    // The node's axial displacement against the rock (along the bolt's path).
    delta = dl + bolt_anchor[a0 + 2u * D + 3u];
    var fs: Real = 0.0;
    if k_axial > 0.0 {
        let sn = confinement(bp_u32[5u * j], a, path_nodes(j));
        let rock = bn_real[r0 + 4u] * (bn_real[r0 + 5u] + sn * bn_real[r0 + 6u]);
        let bolt = bn_real[r0 + 7u] * (bn_real[r0 + 8u] + sn * bn_real[r0 + 9u]);
        let cap = min(rock, bolt) * bond_length;
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
    }
    bolt_slip[i] = slip;
    bolt_grout_force[i] = fs;
    var g: array<Real, 3>;
    for (var k = 0u; k < 3u; k = k + 1u) {
        g[k] = fs * a[k] + k_normal * lateral[k];
    }
    let c_lateral = bn_real[r0 + 10u];
    if c_lateral > 0.0 {
        // Lateral damping on the node's sideways velocity against the rock.
        var w = array<Real, 3>(0.0, 0.0, 0.0);
        let h = path_nodes(j);
        for (var q = 0u; q <= D; q = q + 1u) {
            let wq = bolt_anchor[a0 + 1u + q];
            for (var k = 0u; k < D; k = k + 1u) {
                w[k] = w[k] + wq * vel[h[q] * D + k];
            }
        }
        var vr = array<Real, 3>(0.0, 0.0, 0.0);
        for (var k = 0u; k < D; k = k + 1u) {
            vr[k] = vel[node * D + k] - w[k];
        }
        let va = vr[0] * a[0] + vr[1] * a[1] + vr[2] * a[2];
        for (var k = 0u; k < 3u; k = k + 1u) {
            g[k] = g[k] + c_lateral * (vr[k] - va * a[k]);
        }
    }
    if plate > 0.0 && delta > 0.0 {
        for (var k = 0u; k < 3u; k = k + 1u) {
            g[k] = g[k] + plate * delta * a[k];
        }
    }
    let base = (SLOT0 + slot) * D;
    for (var k = 0u; k < D; k = k + 1u) {
        slots[base + k] = f[k] - g[k];
        bn_grout[3u * i + k] = g[k];
    }
}

//!host_kernel
// Path node m: the grout reactions of the bolt nodes hosted by its elements, in bolt-node
// order (as the CPU adds them), into its slot.
fn kernel(m: u32) {
    let slot = bq_u32[5u * m];
    let lo = bq_u32[5u * m + 1u];
    let hi = bq_u32[5u * m + 2u];
    let r0 = bq_u32[5u * m + 3u];
    let r1 = bq_u32[5u * m + 4u];
    var acc = array<Real, 3>(0.0, 0.0, 0.0);
    for (var i = lo; i < hi; i = i + 1u) {
        let a0 = ALEN * i;
        let host = bn_u32[6u * i + 3u] + u32(bolt_anchor[a0]);
        for (var r = r0; r < r1; r = r + 1u) {
            if bq_refs[2u * r] == host {
                let w = bolt_anchor[a0 + 1u + bq_refs[2u * r + 1u]];
                for (var k = 0u; k < D; k = k + 1u) {
                    acc[k] = acc[k] + w * bn_grout[3u * i + k];
                }
                break;
            }
        }
    }
    let base = (SLOT0 + slot) * D;
    for (var k = 0u; k < D; k = k + 1u) {
        slots[base + k] = acc[k];
    }
}
