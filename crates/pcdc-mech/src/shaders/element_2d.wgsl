// Co-rotated Tri3 element forces (one invocation per element): the same arithmetic, in
// the same order, as `Mechanics::element_2d` on the CPU (see kinematics.rs):
// F = D_s D_m⁻¹, polar F = R U, ε = U − I in the co-rotated frame, σ from the model,
// viscous stress D_f C sym(Rᵀ Ḟ) (eq. 17-19), f_a = −V₀ R σ ∇N_a into the slots.
fn kernel(e: u32) {
    // A null element carries no force (manual 7.2.8).
    if element_null[e] != 0.0 {
        let s0 = (SLOT_FIRST + 3u * e) * 2u;
        for (var k = 0u; k < 6u; k = k + 1u) {
            slots[s0 + k] = 0.0;
        }
        return;
    }
    let n0 = conn[3u * e] * 2u;
    let n1 = conn[3u * e + 1u] * 2u;
    let n2 = conn[3u * e + 2u] * 2u;
    let g = e * GEO;
    let m0 = geo[g];
    let m1 = geo[g + 1u];
    let m2 = geo[g + 2u];
    let m3 = geo[g + 3u];
    let vol = geo[g + 4u];
    let cv = geo[g + 5u];
    // H = [u₁ − u₀, u₂ − u₀] D_m⁻¹, F = I + H (displacement differences keep small strains).
    let d0 = disp[n1] - disp[n0];
    let d1 = disp[n2] - disp[n0];
    let d2 = disp[n1 + 1u] - disp[n0 + 1u];
    let d3 = disp[n2 + 1u] - disp[n0 + 1u];
    let h0 = d0 * m0 + d1 * m2;
    let h1 = d0 * m1 + d1 * m3;
    let h2 = d2 * m0 + d3 * m2;
    let h3 = d2 * m1 + d3 * m3;
    // Polar decomposition in closed form: R = [[co, −si], [si, co]], cm1 = co − 1.
    let pc = 2.0 + (h0 + h3);
    let ps = h2 - h1;
    let pr = sqrt(pc * pc + ps * ps);
    var co = Real(1.0);
    var si = Real(0.0);
    var cm1 = Real(0.0);
    if pr > 0.0 {
        // One division: q = 1 / (r (c + r)) gives 1/r = (c + r) q.
        if pc >= 0.0 {
            let q = 1.0 / (pr * (pc + pr));
            let inv_r = (pc + pr) * q;
            co = pc * inv_r;
            si = ps * inv_r;
            cm1 = -(ps * ps) * q;
        } else {
            let inv_r = 1.0 / pr;
            co = pc * inv_r;
            si = ps * inv_r;
            cm1 = co - 1.0;
        }
    }
    var eps = Sym(cm1 + co * h0 + si * h2, cm1 + co * h3 - si * h1, 0.0, 0.5 * (co * (h1 + h2) + si * (h3 - h0)), 0.0, 0.0);
    /*mixed*/
    let de = Sym(eps[0] - strain[3u * e], eps[1] - strain[3u * e + 1u], 0.0, eps[3] - strain[3u * e + 2u], 0.0, 0.0);
    strain[3u * e] = eps[0];
    strain[3u * e + 1u] = eps[1];
    strain[3u * e + 2u] = eps[3];
    var st: ModelState;
    for (var k = 0u; k < NSTATE; k = k + 1u) {
        st[k] = model_state[e * NSTATE + k];
    }
    let sig0 = Sym(stress[3u * e], stress[3u * e + 1u], stress_zz[e], stress[3u * e + 2u], 0.0, 0.0);
    let mat = material[e];
    let sig = call_model(mat_info[2u * mat], eps, de, sig0, &st, /*coupling*/mat_info[2u * mat + 1u]);
    for (var k = 0u; k < NSTATE; k = k + 1u) {
        model_state[e * NSTATE + k] = st[k];
    }
    stress[3u * e] = sig[0];
    stress[3u * e + 1u] = sig[1];
    stress[3u * e + 2u] = sig[3];
    stress_zz[e] = sig[2];
    var sxx = sig[0];
    var syy = sig[1];
    var sxy = sig[3];
    if p_damping() && cv > 0.0 {
        let vx0 = vel[n0];
        let vy0 = vel[n0 + 1u];
        let dv0 = vel[n1] - vx0;
        let dv1 = vel[n2] - vx0;
        let dv2 = vel[n1 + 1u] - vy0;
        let dv3 = vel[n2 + 1u] - vy0;
        let fd0 = dv0 * m0 + dv1 * m2;
        let fd1 = dv0 * m1 + dv1 * m3;
        let fd2 = dv2 * m0 + dv3 * m2;
        let fd3 = dv2 * m1 + dv3 * m3;
        let r00 = co * fd0 + si * fd2;
        let r01 = co * fd1 + si * fd3;
        let r10 = -si * fd0 + co * fd2;
        let r11 = -si * fd1 + co * fd3;
        sxx = sxx + cv * r00;
        syy = syy + cv * r11;
        sxy = sxy + cv * 0.5 * (r01 + r10);
    }
    let p00 = co * sxx - si * sxy;
    let p01 = co * sxy - si * syy;
    let p10 = si * sxx + co * sxy;
    let p11 = si * sxy + co * syy;
    let f1x = -vol * (p00 * m0 + p01 * m1);
    let f1y = -vol * (p10 * m0 + p11 * m1);
    let f2x = -vol * (p00 * m2 + p01 * m3);
    let f2y = -vol * (p10 * m2 + p11 * m3);
    let s = (SLOT_FIRST + 3u * e) * 2u;
    slots[s] = -(f1x + f2x);
    slots[s + 1u] = -(f1y + f2y);
    slots[s + 2u] = f1x;
    slots[s + 3u] = f1y;
    slots[s + 4u] = f2x;
    slots[s + 5u] = f2y;
}
