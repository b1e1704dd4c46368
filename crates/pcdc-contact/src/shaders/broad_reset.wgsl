// Broad phase, step 8 (a single invocation): lower the rebuild flag for the next step.
fn kernel(i: u32) {
    atomicStore(&flag[0], 0u);
}
