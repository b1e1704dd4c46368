// Gather without integration (force evaluation for static solves and reports): node
// force and the sum of absolute slot contributions per dof.
fn kernel(n: u32) {
    var sum: array<Real, 3>;
    var abs_sum: array<Real, 3>;
    let a = gather_ptr[n];
    let b = gather_ptr[n + 1u];
    for (var j = a; j < b; j = j + 1u) {
        let s = gather_idx[j];
        for (var k = 0u; k < D; k = k + 1u) {
            let f = slots[s * D + k];
            sum[k] = sum[k] + f;
            abs_sum[k] = abs_sum[k] + abs(f);
        }
    }
    for (var k = 0u; k < D; k = k + 1u) {
        force[n * D + k] = sum[k];
        gross[n * D + k] = abs_sum[k];
    }
}
