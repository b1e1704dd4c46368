// Broad phase, step 5 (a single invocation, only when rebuilding): exclusive prefix sum
// of the bucket counts (the counting sort's offsets); clears the fill counters.
fn kernel(i: u32) {
    if atomicLoad(&flag[0]) == 0u {
        return;
    }
    var sum = 0u;
    for (var b = 0u; b < NBUCKETS; b = b + 1u) {
        bucket_start[b] = sum;
        sum = sum + atomicLoad(&bucket_count[b]);
        atomicStore(&bucket_fill[b], 0u);
    }
    bucket_start[NBUCKETS] = sum;
}
