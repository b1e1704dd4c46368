// The cell of element e's box centre (z = 0 in 2D).
fn centre_cell(e: u32, cell: Real) -> vec3<i32> {
    var c = vec3<i32>(0, 0, 0);
    for (var k = 0u; k < D; k = k + 1u) {
        c[k] = cell_of(Real(0.5) * (boxes[2u * D * e + k] + boxes[2u * D * e + D + k]), cell);
    }
    return c;
}
