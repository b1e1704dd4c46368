// Broad phase, step 3 (a single invocation, only when rebuilding): the grid cell size is
// the largest box extent (so overlapping boxes sit in neighbouring cells), and the
// bucket counters are cleared. Serial: O(elements + buckets), on rebuild steps only.
fn kernel(i: u32) {
    if atomicLoad(&flag[0]) == 0u {
        return;
    }
    var cell = Real(0.0);
    for (var e = 0u; e < NE; e = e + 1u) {
        cell = max(cell, max(boxes[4u * e + 2u] - boxes[4u * e], boxes[4u * e + 3u] - boxes[4u * e + 1u]));
    }
    grid[0] = max(cell, REAL_TINY);
    for (var b = 0u; b < NBUCKETS; b = b + 1u) {
        atomicStore(&bucket_count[b], 0u);
    }
}
