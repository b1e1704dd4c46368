// Broad phase, step 3 (one invocation per element, only when rebuilding): the bucket of
// the element's box centre on the grid of cell size = largest box extent (so boxes that
// overlap sit in neighbouring cells), counted with an integer atomic.
fn kernel(e: u32) {
    if atomicLoad(&flag[p_step() & 1u]) == 0u {
        return;
    }
    let cell = max(Real(bitcast<f32>(atomicLoad(&cell_bits[0]))), REAL_TINY);
    let cx = cell_of(Real(0.5) * (boxes[4u * e] + boxes[4u * e + 2u]), cell);
    let cy = cell_of(Real(0.5) * (boxes[4u * e + 1u] + boxes[4u * e + 3u]), cell);
    let b = bucket(cx, cy);
    keys[e] = b;
    atomicAdd(&bucket_count[b], 1u);
}
