//! Gmsh MSH 4.1 files: malformed text, unsupported content, bad options, and the
//! coincident-node warning.

use pcdc_mesh::gmsh::{self, ImportOptions};
use pcdc_mesh::{Dim2, Dim3};

use crate::{case, run};

/// A valid 2D file: the unit square in four triangles with physical groups.
const SQUARE: &str = include_str!("../../crates/pcdc-mesh/tests/data/square.msh");

/// Two triangles of the unit square whose diagonal has duplicate nodes 5 and 6.
const CUT_SQUARE: &str = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n\
    $Nodes\n1 6 1 6\n2 1 0 6\n1\n2\n3\n4\n5\n6\n\
    0 0 0\n1 0 0\n0 1 0\n1 1 0\n1 0 0\n0 1 0\n$EndNodes\n\
    $Elements\n1 2 1 2\n2 1 2 2\n1 1 2 3\n2 5 4 6\n$EndElements\n";

fn parse2(text: &str) -> Result<pcdc_mesh::Mesh<Dim2>, pcdc_mesh::MeshError> {
    gmsh::parse_msh::<Dim2>(text, "bad.msh")
}

/// The square with `from` replaced by `to` (once); `from` must occur.
fn square_with(from: &str, to: &str) -> String {
    assert!(SQUARE.contains(from), "{from}");
    SQUARE.replacen(from, to, 1)
}

/// Imports with `opts`, turning warnings into an error message.
fn warnings_of(text: &str, opts: ImportOptions) -> Result<(), String> {
    let import = gmsh::parse_msh_with::<Dim2>(text, "cut.msh", &opts).map_err(|e| e.to_string())?;
    match import.warnings.first() {
        Some(w) => Err(w.to_string()),
        None => Ok(()),
    }
}

#[test]
fn bad_gmsh_files_are_named_errors() {
    run(
        "gmsh",
        vec![
            case("empty file", "empty file", || parse2("")),
            case("not a mesh", "not a Gmsh MSH file", || parse2("hello\n")),
            case("BOM then not a mesh", "not a Gmsh MSH file", || {
                parse2("\u{feff}hello\n")
            }),
            case("legacy version 2.2", "version", || {
                parse2(&square_with("4.1 0 8", "2.2 0 8"))
            }),
            case("binary file", "binary MSH files are not supported", || {
                parse2(&square_with("4.1 0 8", "4.1 1 8"))
            }),
            case("missing $Elements", "missing $Elements section", || {
                parse2(&SQUARE[..SQUARE.find("$Elements").unwrap()])
            }),
            case("truncated", "end of file", || {
                parse2(&SQUARE[..SQUARE.find("$EndNodes").unwrap()])
            }),
            case("unknown node tag", "unknown node tag 7", || {
                parse2(&square_with("8 2 3 6", "8 2 3 7"))
            }),
            case("non-numeric coordinate", "y coordinate", || {
                parse2(&square_with("0.5 0.5 0", "0.5 x 0"))
            }),
            case("NaN coordinate", "must be finite", || {
                parse2(&square_with("0.5 0.5 0", "0.5 nan 0"))
            }),
            case("huge coordinate", "must be finite and at most", || {
                parse2(&square_with("0.5 0.5 0", "0.5 1e300 0"))
            }),
            case("z in a 2D mesh", "must lie in the plane z = 0", || {
                parse2(&square_with("0.5 0.5 0", "0.5 0.5 0.25"))
            }),
            case("quadrangle block", "quadrangle", || {
                parse2(&square_with("2 1 2 4\n", "2 1 3 4\n"))
            }),
            case("header node count", "declares 7 nodes", || {
                parse2(&square_with("6 6 1 9", "6 7 1 9"))
            }),
            case("degenerate triangle", "degenerate", || {
                parse2(&square_with("0.5 0.5 0", "0.5 0 0"))
            }),
            case("2D file read as 3D", "read it as Dim2", || {
                gmsh::parse_msh::<Dim3>(SQUARE, "sq.msh")
            }),
            case("missing file", "no_such_file.msh", || {
                gmsh::read_msh::<Dim2>("/nonexistent/no_such_file.msh")
            }),
            case(
                "NaN coincidence tolerance",
                "coincident_rel_tol = NaN",
                || {
                    warnings_of(
                        SQUARE,
                        ImportOptions {
                            coincident_rel_tol: f64::NAN,
                            ..Default::default()
                        },
                    )
                },
            ),
            case(
                "huge coincidence tolerance",
                "coincident_rel_tol = 0.5",
                || {
                    warnings_of(
                        SQUARE,
                        ImportOptions {
                            coincident_rel_tol: 0.5,
                            ..Default::default()
                        },
                    )
                },
            ),
            case(
                "unmerged coincident nodes (warning)",
                "mesh is cut there",
                || warnings_of(CUT_SQUARE, ImportOptions::default()),
            ),
        ],
    );
}

#[test]
fn accepted_variants_still_import() {
    // A byte-order mark is skipped; coincident nodes merge on request; a clean file warns
    // about nothing.
    let bom = format!("\u{feff}{SQUARE}");
    assert_eq!(parse2(&bom).unwrap().n_elements(), 4);
    let merge = ImportOptions {
        merge_coincident: true,
        ..Default::default()
    };
    let joined = gmsh::parse_msh_with::<Dim2>(CUT_SQUARE, "cut.msh", &merge).unwrap();
    assert_eq!((joined.merged_nodes, joined.mesh.n_nodes()), (2, 4));
    assert_eq!(warnings_of(SQUARE, ImportOptions::default()), Ok(()));
}
