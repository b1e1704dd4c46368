// Gather + central-difference velocity update (one invocation per node), the same
// arithmetic in the same order as the CPU backend:
//   F = Σ slots (registration order),  v += dt (F + m_phys g − α|F| sign v) / m.
fn kernel(n: u32) {
    var sum: array<Real, 3>;
    let a = gather_ptr[n];
    let b = gather_ptr[n + 1u];
    for (var j = a; j < b; j = j + 1u) {
        let s = gather_idx[j];
        for (var k = 0u; k < D; k = k + 1u) {
            sum[k] = sum[k] + slots[s * D + k];
        }
    }
    let m = mass[n];
    let w = mass_phys[n] / m;
    let dt = p_dt();
    let alpha = p_alpha();
    for (var k = 0u; k < D; k = k + 1u) {
        let i = n * D + k;
        force[i] = sum[k];
        var fk = sum[k] + w * m * p_gravity(k);
        let vk = vel[i];
        if alpha > 0.0 {
            // Local non-viscous damping (Cundall).
            var sg = Real(0.0);
            if vk > 0.0 {
                sg = Real(1.0);
            } else if vk < 0.0 {
                sg = Real(-1.0);
            }
            fk = fk - alpha * abs(fk) * sg;
        }
        vel[i] = vk + dt * fk / m;
    }
}
