// Broad phase, step 3 (one invocation per element, only when rebuilding): the bucket of
// the element's box centre on the grid of cell size = largest box extent (so boxes that
// overlap sit in neighbouring cells), counted with an integer atomic.
fn kernel(e: u32) {
    if atomicLoad(&flag[p_step() & 1u]) == 0u {
        return;
    }
    let cell = max(Real(bitcast<f32>(atomicLoad(&cell_bits[0]))), REAL_TINY);
    let b = bucket(centre_cell(e, cell));
    keys[e] = b;
    atomicAdd(&bucket_count[b], 1u);
}
