// Bucket of a grid cell: cells are hashed into NBUCKETS (a power of two) buckets; a
// bucket may hold several cells, the box test sorts them out. D = 2 or 3 (nodes stride
// D, boxes stride 2 D: lows then highs); in 2D the z index is 0, which leaves the hash
// of (cx, cy) as it was.
fn cell_of(x: Real, cell: Real) -> i32 {
    return i32(floor(x / cell));
}
fn bucket(c: vec3<i32>) -> u32 {
    return ((bitcast<u32>(c.x) * 73856093u) ^ (bitcast<u32>(c.y) * 19349663u)
        ^ (bitcast<u32>(c.z) * 83492791u)) & (NBUCKETS - 1u);
}
