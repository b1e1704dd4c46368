// Mechanical boundary: node force (N). One invocation per slot of the block; every slot
// gets the same force, component k read from signal(SIG + k) (the table at the start of
// the step, 0 for a free component), exactly as `Boundary::compute_forces`.
//
// Constants: D (dimension), SLOT0 (global index of the block's first slot), SIG (first
// of the D signals). Bindings: slots (read_write).
fn kernel(s: u32) {
    let base = (SLOT0 + s) * D;
    for (var k = 0u; k < D; k = k + 1u) {
        slots[base + k] = signal(SIG + k);
    }
}
