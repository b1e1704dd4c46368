// Co-rotated Tri3 element forces (one invocation per element): the same arithmetic, in
// the same order, as `Mechanics::element_2d` on the CPU (see kinematics.rs):
// F = D_s D_m⁻¹, polar F = R U, ε = U − I in the co-rotated frame, σ from the model,
// viscous stress D_f C sym(Rᵀ Ḟ) (eq. 17-19), f_a = −V₀ R σ ∇N_a into the slots.
fn kernel(e: u32) {
    let n0 = conn[3u * e] * 2u;
    let n1 = conn[3u * e + 1u] * 2u;
    let n2 = conn[3u * e + 2u] * 2u;
    let x0 = coords[n0] + disp[n0];
    let x1 = coords[n0 + 1u] + disp[n0 + 1u];
    let x2 = coords[n1] + disp[n1];
    let x3 = coords[n1 + 1u] + disp[n1 + 1u];
    let x4 = coords[n2] + disp[n2];
    let x5 = coords[n2 + 1u] + disp[n2 + 1u];
    let g = e * GEO;
    let m0 = geo[g];
    let m1 = geo[g + 1u];
    let m2 = geo[g + 2u];
    let m3 = geo[g + 3u];
    let vol = geo[g + 4u];
    let cv = geo[g + 5u];
    let ds0 = x2 - x0;
    let ds1 = x4 - x0;
    let ds2 = x3 - x1;
    let ds3 = x5 - x1;
    let f0 = ds0 * m0 + ds1 * m2;
    let f1 = ds0 * m1 + ds1 * m3;
    let f2 = ds2 * m0 + ds3 * m2;
    let f3 = ds2 * m1 + ds3 * m3;
    // Polar decomposition in closed form: R = [[co, −si], [si, co]].
    let pc = f0 + f3;
    let ps = f2 - f1;
    let pr = sqrt(pc * pc + ps * ps);
    var co = Real(1.0);
    var si = Real(0.0);
    if pr > 0.0 {
        co = pc / pr;
        si = ps / pr;
    }
    let u00 = co * f0 + si * f2;
    let u01 = co * f1 + si * f3;
    let u10 = -si * f0 + co * f2;
    let u11 = -si * f1 + co * f3;
    let eps = Sym(u00 - 1.0, u11 - 1.0, 0.0, 0.5 * (u01 + u10), 0.0, 0.0);
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
    let sig = call_model(mat_info[2u * mat], eps, de, sig0, &st, mat_info[2u * mat + 1u]);
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
