// Broad phase, step 6 (one invocation per node, only when rebuilding): the positions of
// this build, against which later steps measure the motion.
fn kernel(n: u32) {
    if atomicLoad(&flag[p_step() & 1u]) == 0u {
        return;
    }
    for (var k = 0u; k < D; k = k + 1u) {
        let i = n * D + k;
        reference[i] = coords[i] + disp[i];
    }
}
