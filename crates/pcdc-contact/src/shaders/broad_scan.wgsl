// Broad phase, step 4 (a single invocation, only when rebuilding): exclusive prefix sum
// of the bucket counts (the counting sort's offsets); keeps the cell size for step 5 and
// clears the counters, fill counters and cell maximum for the next build. Serial over
// the buckets: it runs on rebuild steps only.
fn kernel(i: u32) {
    if atomicLoad(&flag[p_step() & 1u]) == 0u {
        return;
    }
    grid[0] = max(Real(bitcast<f32>(atomicLoad(&cell_bits[0]))), REAL_TINY);
    atomicStore(&cell_bits[0], 0u);
    var sum = 0u;
    for (var b = 0u; b < NBUCKETS; b = b + 1u) {
        bucket_start[b] = sum;
        sum = sum + atomicLoad(&bucket_count[b]);
        atomicStore(&bucket_count[b], 0u);
        atomicStore(&bucket_fill[b], 0u);
    }
    bucket_start[NBUCKETS] = sum;
}
