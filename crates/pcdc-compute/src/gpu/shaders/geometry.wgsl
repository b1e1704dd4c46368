// Measure and unit normal of a face with vertex coordinates x (stride D): the WGSL twin
// of `Dim::face_measure_normal`, operation for operation. 2D: edge a -> b of a
// counter-clockwise triangle, normal = edge direction turned clockwise, measure =
// length. 3D: triangle, normal = (b − a) × (c − a) normalised, measure = area. A
// degenerate face leaves n untouched (callers pass a zeroed n). Needs `const D: u32`.
fn face_measure_normal(x: array<Real, 9>, n: ptr<function, array<Real, 3>>) -> Real {
    if D == 2u {
        let dx = x[2] - x[0];
        let dy = x[3] - x[1];
        let len = sqrt(dx * dx + dy * dy);
        if len > 0.0 {
            let inv = 1.0 / len;
            (*n)[0] = dy * inv;
            (*n)[1] = -dx * inv;
        }
        return len;
    }
    let a0 = x[3] - x[0];
    let a1 = x[4] - x[1];
    let a2 = x[5] - x[2];
    let b0 = x[6] - x[0];
    let b1 = x[7] - x[1];
    let b2 = x[8] - x[2];
    let c0 = a1 * b2 - a2 * b1;
    let c1 = a2 * b0 - a0 * b2;
    let c2 = a0 * b1 - a1 * b0;
    let len = sqrt(c0 * c0 + c1 * c1 + c2 * c2);
    if len > 0.0 {
        let inv = 1.0 / len;
        (*n)[0] = c0 * inv;
        (*n)[1] = c1 * inv;
        (*n)[2] = c2 * inv;
    }
    return 0.5 * len;
}
