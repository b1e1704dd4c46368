// Where contact can happen (the CPU's `exclusion` module): a sealed element (every
// vertex closed, or the element null) and a pair sharing an intact vertex are skipped. REGIONS = 0 when no
// bonds are declared (nothing skipped; the buffers are placeholders).
fn sealed(e: u32) -> bool {
    // A null element (excavated, manual 7.2.8) touches nothing.
    if element_null[e] != 0.0 {
        return true;
    }
    if REGIONS == 0u {
        return false;
    }
    for (var a = 0u; a < NPE; a = a + 1u) {
        if (vertex_flags[elem_vertex[e * NPE + a]] & 2u) == 0u {
            return false;
        }
    }
    return true;
}

fn share_intact_vertex(e: u32, f: u32) -> bool {
    if REGIONS == 0u {
        return false;
    }
    for (var a = 0u; a < NPE; a = a + 1u) {
        let v = elem_vertex[e * NPE + a];
        if (vertex_flags[v] & 1u) == 0u {
            continue;
        }
        for (var b = 0u; b < NPE; b = b + 1u) {
            if elem_vertex[f * NPE + b] == v {
                return true;
            }
        }
    }
    return false;
}
