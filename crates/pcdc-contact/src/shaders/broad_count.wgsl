fn box_centre_bucket(e: u32, cell: Real) -> u32 {
    let cx = cell_of(Real(0.5) * (boxes[4u * e] + boxes[4u * e + 2u]), cell);
    let cy = cell_of(Real(0.5) * (boxes[4u * e + 1u] + boxes[4u * e + 3u]), cell);
    return bucket(cx, cy);
}
// Broad phase, step 4 (one invocation per element, only when rebuilding): the bucket of
// the element's box centre, counted with an integer atomic.
fn kernel(e: u32) {
    if atomicLoad(&flag[0]) == 0u {
        return;
    }
    let b = box_centre_bucket(e, grid[0]);
    keys[e] = b;
    atomicAdd(&bucket_count[b], 1u);
}
