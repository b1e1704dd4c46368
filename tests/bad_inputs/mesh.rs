//! Meshes: `Mesh::new`, deserialisation (JSON) and the specimen builders.

use pcdc_mesh::{builders, Dim2, Dim3, Mesh};

use crate::{case, run};

/// The unit square cut on its diagonal.
fn square() -> Mesh<Dim2> {
    Mesh::new(
        vec![0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0],
        vec![0, 1, 2, 0, 2, 3],
    )
    .unwrap()
}

/// The square as JSON with `from` replaced by `to` (once).
fn json_with(from: &str, to: &str) -> String {
    let mut m = square();
    m.add_node_group("left", vec![0, 3]).unwrap();
    let json = serde_json::to_string(&m).unwrap();
    assert!(json.contains(from), "{from} not in {json}");
    json.replacen(from, to, 1)
}

fn from_json(json: String) -> Result<Mesh<Dim2>, serde_json::Error> {
    serde_json::from_str(&json)
}

fn m2(coords: &[f64], elements: &[u32]) -> Result<Mesh<Dim2>, pcdc_mesh::MeshError> {
    Mesh::new(coords.to_vec(), elements.to_vec())
}

const SQ: [f64; 8] = [0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0, 1.0];

#[test]
fn bad_meshes_are_named_errors() {
    run(
        "mesh",
        vec![
            case(
                "odd coordinate count",
                "not a multiple of the dimension 2",
                || m2(&SQ[..7], &[0, 1, 2]),
            ),
            case("odd connectivity", "not a multiple of 3 nodes", || {
                m2(&SQ, &[0, 1, 2, 3])
            }),
            case("no elements", "no elements", || m2(&SQ, &[])),
            case("NaN coordinate", "node 1 has a non-finite", || {
                m2(&[0.0, 0.0, f64::NAN, 0.0, 0.0, 1.0], &[0, 1, 2])
            }),
            case("infinite coordinate", "non-finite", || {
                m2(&[0.0, 0.0, 1.0, 0.0, 0.0, f64::INFINITY], &[0, 1, 2])
            }),
            case(
                "coordinate beyond 1e100 m",
                "beyond the limit of 1e100 m",
                || m2(&[0.0, 0.0, 1e200, 0.0, 0.0, 1.0], &[0, 1, 2]),
            ),
            case(
                "builder: 1e200 m rectangle",
                "beyond the limit of 1e100 m",
                || builders::rectangle(0.0, 0.0, 1e200, 1e200, 1e200),
            ),
            case("node index out of range", "refers to node 7", || {
                m2(&SQ[..6], &[0, 1, 7])
            }),
            case("repeated node", "repeats node 1", || {
                m2(&SQ[..6], &[0, 1, 1])
            }),
            case("clockwise triangle", "inverted", || {
                m2(&SQ[..6], &[0, 2, 1])
            }),
            case("collinear triangle", "degenerate", || {
                m2(&[0.0, 0.0, 1.0, 0.0, 2.0, 0.0], &[0, 1, 2])
            }),
            case("dangling node", "node 3 is dangling", || {
                m2(&[0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 5.0, 5.0], &[0, 1, 2])
            }),
            case(
                "edge shared by three triangles",
                "more than two elements",
                || {
                    m2(
                        &[0.0, 0.0, 1.0, 0.0, 0.5, 1.0, 0.5, -1.0, 0.5, 2.0],
                        &[0, 1, 2, 1, 0, 3, 0, 1, 4],
                    )
                },
            ),
            case("inverted tetrahedron", "inverted", || {
                Mesh::<Dim3>::new(
                    vec![0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
                    vec![0, 2, 1, 3],
                )
            }),
            case("group index out of range", "refers to index 99", || {
                square().add_node_group("g", vec![99])
            }),
            case("face group index out of range", "face group 'f'", || {
                square().add_face_group("f", vec![5])
            }),
            case(
                "json: element node out of range",
                "refers to node 9",
                || from_json(json_with("\"elements\":[0,1,2,", "\"elements\":[0,1,9,")),
            ),
            case("json: inverted element", "inverted", || {
                from_json(json_with("\"elements\":[0,1,2,", "\"elements\":[0,2,1,"))
            }),
            case("json: NaN-free but short coords", "not a multiple", || {
                from_json(json_with("\"coords\":[0.0,0.0,", "\"coords\":[0.0,"))
            }),
            case("json: tampered face owner", "faces.owner[0]", || {
                from_json(json_with("\"owner\":[0,", "\"owner\":[1,"))
            }),
            case(
                "json: dropped boundary face",
                "faces.boundary has 3 entries",
                || from_json(json_with("\"boundary\":[0,", "\"boundary\":[")),
            ),
            case(
                "json: group index out of range",
                "refers to index 7",
                || from_json(json_with("\"left\":[0,3]", "\"left\":[0,7]")),
            ),
            case("json: missing groups", "missing field `groups`", || {
                from_json(json_with(",\"groups\":", ",\"x\":"))
            }),
            case("builder: zero size", "size = 0", || {
                builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.0)
            }),
            case("builder: NaN origin", "x0 = NaN", || {
                builders::rectangle(f64::NAN, 0.0, 1.0, 1.0, 0.1)
            }),
            case("builder: negative radius", "radius = -1", || {
                builders::disc([0.0, 0.0], -1.0, 0.1)
            }),
            case("builder: beyond 32-bit indices", "32-bit indices", || {
                builders::rectangle(0.0, 0.0, 1.0, 1.0, 1e-9)
            }),
            case(
                "builder: 2D mesh over the memory limit",
                "above the memory limit of 1073741824 bytes",
                || builders::rectangle(0.0, 0.0, 1.0, 1.0, 1e-4),
            ),
            case(
                "builder: 3D mesh over the memory limit",
                "size = 0.002: a mesh of about",
                || builders::cuboid([0.0; 3], [1.0; 3], 2e-3),
            ),
        ],
    );
}
