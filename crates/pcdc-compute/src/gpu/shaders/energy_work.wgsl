// Energy balance, after the kinematic conditions (one invocation per node): the work of
// each force source over the step with v̄ = (v⁻ + v⁺)/2, the arithmetic of `node_works`
// on the CPU: per physics (slots in registration order, `phys_of` generated from the
// slot ranges), gravity and local damping; the kinematic conditions get the rest of
// the node's kinetic-energy change ½ m (v⁺² − v⁻²). Each node accumulates into its own
// entries of `energy_acc` (stride NACC = NP + 3; no atomics). While tracking, the
// integration mass is the physical one (relaxation pauses the balance).
fn kernel(n: u32) {
    let dt = p_dt();
    let alpha = p_alpha();
    let m = mass[n];
    // Works accumulate in [base, base + NACC); the forward halves ½ Δt f · v⁺ of this
    // step overwrite [base + NACC, base + 2 NACC).
    let base = n * 2u * NACC;
    let fw = base + NACC;
    for (var q = 0u; q < NACC; q = q + 1u) {
        energy_acc[fw + q] = Real(0.0);
    }
    var vbar: array<Real, 3>;
    for (var k = 0u; k < D; k = k + 1u) {
        vbar[k] = 0.5 * (vel_prev[n * D + k] + vel[n * D + k]);
    }
    var fsum: array<Real, 3>;
    var total = Real(0.0);
    var total_fwd = Real(0.0);
    let a = gather_ptr[n];
    let b = gather_ptr[n + 1u];
    for (var j = a; j < b; j = j + 1u) {
        let s = gather_idx[j];
        var w = Real(0.0);
        var wf = Real(0.0);
        for (var k = 0u; k < D; k = k + 1u) {
            let f = slots[s * D + k];
            w = w + f * vbar[k];
            wf = wf + f * vel[n * D + k];
            fsum[k] = fsum[k] + f;
        }
        let p = phys_of(s);
        energy_acc[base + p] = energy_acc[base + p] + dt * w;
        energy_acc[fw + p] = energy_acc[fw + p] + 0.5 * dt * wf;
        total = total + dt * w;
        total_fwd = total_fwd + 0.5 * dt * wf;
    }
    var dke = Real(0.0);
    var dke_fwd = Real(0.0);
    for (var k = 0u; k < D; k = k + 1u) {
        let i = n * D + k;
        let vk = vel[i];
        let vp = vel_prev[i];
        let fg = m * p_gravity(k);
        energy_acc[base + NP] = energy_acc[base + NP] + dt * fg * vbar[k];
        energy_acc[fw + NP] = energy_acc[fw + NP] + 0.5 * dt * fg * vk;
        total = total + dt * fg * vbar[k];
        total_fwd = total_fwd + 0.5 * dt * fg * vk;
        if alpha > 0.0 && vp != 0.0 {
            var sg = Real(1.0);
            if vp < 0.0 {
                sg = Real(-1.0);
            }
            let fl = -alpha * abs(fsum[k] + fg) * sg;
            energy_acc[base + NP + 1u] = energy_acc[base + NP + 1u] + dt * fl * vbar[k];
            energy_acc[fw + NP + 1u] = energy_acc[fw + NP + 1u] + 0.5 * dt * fl * vk;
            total = total + dt * fl * vbar[k];
            total_fwd = total_fwd + 0.5 * dt * fl * vk;
        }
        dke = dke + vk * vk - vp * vp;
        dke_fwd = dke_fwd + (vk - vp) * vk;
    }
    energy_acc[base + NP + 2u] = energy_acc[base + NP + 2u] + 0.5 * m * dke - total;
    energy_acc[fw + NP + 2u] = energy_acc[fw + NP + 2u] + 0.5 * m * dke_fwd - total_fwd;
}
