// Energy balance, before the velocity update: keep v⁻ (one invocation per node).
fn kernel(n: u32) {
    for (var k = 0u; k < D; k = k + 1u) {
        vel_prev[n * D + k] = vel[n * D + k];
    }
}
