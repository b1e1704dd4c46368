// Mechanical boundary: prescribed node velocity (m/s), after the velocity update. One
// invocation per node of the item; component k (bit k of MASK) is set to
// signal(SIG + k), the table at the half step t + dt/2, as `Boundary::apply_kinematics`.
//
// Constants: D, MASK (prescribed components), SIG (first of the D signals).
// Bindings: nodes (read), vel (read_write).
fn kernel(j: u32) {
    let base = nodes[j] * D;
    for (var k = 0u; k < D; k = k + 1u) {
        if ((MASK >> k) & 1u) != 0u {
            vel[base + k] = signal(SIG + k);
        }
    }
}
