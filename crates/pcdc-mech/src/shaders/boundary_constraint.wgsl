// Mechanical boundary: move constraint on the node velocity (m/s), after the velocity
// update. One invocation per node of the item, as `Boundary::apply_kinematics`:
// KIND 0 fixed (v = 0), 1 along the unit direction u (v = (v·u) u), 2 in the plane with
// unit normal u (v -= (v·u) u). The dot product sums components in order 0, 1, 2.
//
// Constants: D, KIND, U0, U1, U2 (unit vector, Real). Bindings: nodes (read),
// vel (read_write).
fn kernel(j: u32) {
    let base = nodes[j] * D;
    if KIND == 0u {
        for (var k = 0u; k < D; k = k + 1u) {
            vel[base + k] = Real(0.0);
        }
        return;
    }
    var u = array<Real, 3>(U0, U1, U2);
    var dot = vel[base] * u[0];
    for (var k = 1u; k < D; k = k + 1u) {
        dot = dot + vel[base + k] * u[k];
    }
    for (var k = 0u; k < D; k = k + 1u) {
        if KIND == 1u {
            vel[base + k] = dot * u[k];
        } else {
            vel[base + k] = vel[base + k] - dot * u[k];
        }
    }
}
