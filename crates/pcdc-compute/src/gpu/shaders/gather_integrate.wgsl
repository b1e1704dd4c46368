// Gather + central-difference velocity update (one invocation per node), the same
// arithmetic in the same order as the CPU backend:
//   F = Σ slots (registration order),  v += (F + m_phys g − α|F| sign v) (dt / m).
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
    let m_phys = mass_phys[n];
    let dtm = p_dt() / mass[n];
    let alpha = p_alpha();
    for (var k = 0u; k < D; k = k + 1u) {
        let i = n * D + k;
        force[i] = sum[k];
        var fk = sum[k] + m_phys * p_gravity(k);
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
        vel[i] = vk + fk * dtm;
    }
}
