// Mechanical boundary: prescribed node acceleration, after the velocity update. One
// invocation per node of the item; for component k (bit k of MASK) the velocity
// integrated from the acceleration (field bc_accel_velocity, m/s) grows by
// signal(SIG + k) = a(t) dt and overwrites the node velocity, as
// `Boundary::apply_kinematics`.
//
// Constants: D, MASK (prescribed components), SIG (first of the D signals).
// Bindings: nodes (read), vel (read_write), acc (read_write).
fn kernel(j: u32) {
    let base = nodes[j] * D;
    for (var k = 0u; k < D; k = k + 1u) {
        if ((MASK >> k) & 1u) != 0u {
            let i = base + k;
            let a = acc[i] + signal(SIG + k);
            acc[i] = a;
            vel[i] = a;
        }
    }
}
