// Co-rotated Tet4 element forces (one invocation per element): the same arithmetic, in
// the same order, as `Mechanics::element_3d` on the CPU, with the warm-started Newton
// polar decomposition of kinematics.rs.
alias M3 = array<Real, 9>;

fn mul3(a: M3, b: M3) -> M3 {
    var c: M3;
    for (var i = 0u; i < 3u; i = i + 1u) {
        for (var j = 0u; j < 3u; j = j + 1u) {
            c[3u * i + j] = a[3u * i] * b[j] + a[3u * i + 1u] * b[3u + j] + a[3u * i + 2u] * b[6u + j];
        }
    }
    return c;
}

fn mul3_tn(a: M3, b: M3) -> M3 {
    var c: M3;
    for (var i = 0u; i < 3u; i = i + 1u) {
        for (var j = 0u; j < 3u; j = j + 1u) {
            c[3u * i + j] = a[i] * b[j] + a[3u + i] * b[3u + j] + a[6u + i] * b[6u + j];
        }
    }
    return c;
}

fn inv_transpose3(a: M3) -> M3 {
    let det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6])
        + a[2] * (a[3] * a[7] - a[4] * a[6]);
    let inv_det = 1.0 / det;
    return M3(
        (a[4] * a[8] - a[5] * a[7]) * inv_det,
        (a[5] * a[6] - a[3] * a[8]) * inv_det,
        (a[3] * a[7] - a[4] * a[6]) * inv_det,
        (a[2] * a[7] - a[1] * a[8]) * inv_det,
        (a[0] * a[8] - a[2] * a[6]) * inv_det,
        (a[1] * a[6] - a[0] * a[7]) * inv_det,
        (a[1] * a[5] - a[2] * a[4]) * inv_det,
        (a[2] * a[3] - a[0] * a[5]) * inv_det,
        (a[0] * a[4] - a[1] * a[3]) * inv_det,
    );
}

fn polar_3d(f: M3, r_prev: M3) -> M3 {
    var x = mul3_tn(r_prev, f);
    for (var it = 0u; it < 40u; it = it + 1u) {
        let inv = inv_transpose3(x);
        var next: M3;
        var change = Real(0.0);
        for (var k = 0u; k < 9u; k = k + 1u) {
            next[k] = 0.5 * (x[k] + inv[k]);
            change = max(change, abs(next[k] - x[k]));
        }
        x = next;
        if change <= POLAR_TOL || !(change <= REAL_MAX) {
            break;
        }
    }
    return mul3(r_prev, x);
}

// F = I + [u_j − u₀] D_m⁻¹ of element e, from displacement differences (they keep small
// strains), as `Mechanics::deformation_gradient_3d` on the CPU.
fn deformation_gradient(e: u32, mm: M3) -> M3 {
    let o0 = conn[4u * e] * 3u;
    var du: M3;
    for (var i = 0u; i < 3u; i = i + 1u) {
        let o = disp[o0 + i];
        for (var j = 0u; j < 3u; j = j + 1u) {
            du[3u * i + j] = disp[conn[4u * e + j + 1u] * 3u + i] - o;
        }
    }
    var f = mul3(du, mm);
    f[0] = f[0] + 1.0;
    f[4] = f[4] + 1.0;
    f[8] = f[8] + 1.0;
    return f;
}

fn kernel(e: u32) {
    // A null element carries no force (manual 7.2.8).
    if element_null[e] != 0.0 {
        let s0 = (SLOT_FIRST + 4u * e) * 3u;
        for (var k = 0u; k < 12u; k = k + 1u) {
            slots[s0 + k] = 0.0;
        }
        return;
    }
    var n: array<u32, 4>;
    for (var a = 0u; a < 4u; a = a + 1u) {
        n[a] = conn[4u * e + a] * 3u;
    }
    let g = e * GEO;
    var mm: M3;
    for (var k = 0u; k < 9u; k = k + 1u) {
        mm[k] = geo[g + k];
    }
    let vol = geo[g + 9u];
    let cv = geo[g + 10u];
    let f = deformation_gradient(e, mm);
    var r_prev: M3;
    for (var k = 0u; k < 9u; k = k + 1u) {
        r_prev[k] = rotation[9u * e + k];
    }
    /*polar*/
    for (var k = 0u; k < 9u; k = k + 1u) {
        rotation[9u * e + k] = r[k];
    }
    let u = mul3_tn(r, f);
    var eps = Sym(u[0] - 1.0, u[4] - 1.0, u[8] - 1.0, 0.5 * (u[1] + u[3]), 0.5 * (u[5] + u[7]), 0.5 * (u[2] + u[6]));
    /*mixed*/
    var de: Sym;
    for (var k = 0u; k < 6u; k = k + 1u) {
        de[k] = eps[k] - strain[6u * e + k];
    }
    for (var k = 0u; k < 6u; k = k + 1u) {
        strain[6u * e + k] = eps[k];
    }
    var sig0: Sym;
    for (var k = 0u; k < 6u; k = k + 1u) {
        sig0[k] = stress[6u * e + k];
    }
    var st: ModelState;
    for (var k = 0u; k < NSTATE; k = k + 1u) {
        st[k] = model_state[e * NSTATE + k];
    }
    let mat = material[e];
    var sig = call_model(mat_info[2u * mat], eps, de, sig0, &st, /*coupling*/mat_info[2u * mat + 1u]);
    for (var k = 0u; k < NSTATE; k = k + 1u) {
        model_state[e * NSTATE + k] = st[k];
    }
    for (var k = 0u; k < 6u; k = k + 1u) {
        stress[6u * e + k] = sig[k];
    }
    if p_damping() && cv > 0.0 {
        var dv: M3;
        for (var i = 0u; i < 3u; i = i + 1u) {
            let o = vel[n[0] + i];
            for (var j = 0u; j < 3u; j = j + 1u) {
                dv[3u * i + j] = vel[n[j + 1u] + i] - o;
            }
        }
        let fd = mul3(dv, mm);
        let rd = mul3_tn(r, fd);
        sig[0] = sig[0] + cv * rd[0];
        sig[1] = sig[1] + cv * rd[4];
        sig[2] = sig[2] + cv * rd[8];
        sig[3] = sig[3] + cv * 0.5 * (rd[1] + rd[3]);
        sig[4] = sig[4] + cv * 0.5 * (rd[5] + rd[7]);
        sig[5] = sig[5] + cv * 0.5 * (rd[2] + rd[6]);
    }
    let s = M3(sig[0], sig[3], sig[5], sig[3], sig[1], sig[4], sig[5], sig[4], sig[2]);
    let pk = mul3(r, s);
    var f0: array<Real, 3>;
    let base = (SLOT_FIRST + 4u * e) * 3u;
    for (var a = 0u; a < 3u; a = a + 1u) {
        for (var i = 0u; i < 3u; i = i + 1u) {
            let fa = -vol * (pk[3u * i] * mm[3u * a] + pk[3u * i + 1u] * mm[3u * a + 1u] + pk[3u * i + 2u] * mm[3u * a + 2u]);
            slots[base + 3u * (a + 1u) + i] = fa;
            f0[i] = f0[i] - fa;
        }
    }
    for (var i = 0u; i < 3u; i = i + 1u) {
        slots[base + i] = f0[i];
    }
}
