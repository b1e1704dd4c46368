// Broad phase, step 5a (one invocation per element, only when rebuilding): the element
// takes a place in its bucket. The order inside a bucket depends on scheduling; the
// candidate lists are sorted afterwards, so nothing downstream depends on it.
fn kernel(e: u32) {
    if atomicLoad(&flag[p_step() & 1u]) == 0u {
        return;
    }
    let b = keys[e];
    let at = atomicAdd(&bucket_fill[b], 1u);
    bucket_items[bucket_start[b] + at] = e;
}
