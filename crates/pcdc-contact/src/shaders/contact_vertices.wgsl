// Vertex flags of the bonded regions (one invocation per vertex, every step, after the
// joints wrote their broken flags): the CPU's `BondedRegions::update`. Bit 0: the fan is
// connected and none of its bonds is broken (intact); bit 1: intact and every element
// face at the vertex glued (closed).
fn kernel(v: u32) {
    let stat = vertex_static[v];
    var flags = 0u;
    if (stat & 1u) != 0u {
        var hold = true;
        for (var k = vertex_ptr[v]; k < vertex_ptr[v + 1u]; k = k + 1u) {
            if broken[vertex_faces[k]] != 0.0 {
                hold = false;
                break;
            }
        }
        if hold {
            flags = 1u;
            if (stat & 2u) != 0u {
                flags = 3u;
            }
        }
    }
    vertex_flags[v] = flags;
}
