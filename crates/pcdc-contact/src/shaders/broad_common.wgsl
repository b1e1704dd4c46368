// Bucket of a grid cell: cells are hashed into NBUCKETS (a power of two) buckets; a
// bucket may hold several cells, the box test sorts them out.
fn cell_of(x: Real, cell: Real) -> i32 {
    return i32(floor(x / cell));
}
fn bucket(cx: i32, cy: i32) -> u32 {
    return ((bitcast<u32>(cx) * 73856093u) ^ (bitcast<u32>(cy) * 19349663u)) & (NBUCKETS - 1u);
}
