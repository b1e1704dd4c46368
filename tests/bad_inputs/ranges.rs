//! Range selections that cannot select anything, through the mesh's selection calls and
//! free-point queries.

use pcdc_mesh::{builders, Dim2, Mesh, Range};

use crate::{case, run};

fn square() -> Mesh<Dim2> {
    builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap()
}

fn select2(r: Range) -> Result<Vec<u32>, pcdc_mesh::MeshError> {
    square().select_nodes(&r)
}

fn select3(r: Range) -> Result<Vec<u32>, pcdc_mesh::MeshError> {
    builders::cuboid([0.0; 3], [1.0; 3], 0.5)
        .unwrap()
        .select_elements(&r)
}

const NAN: f64 = f64::NAN;
const INF: f64 = f64::INFINITY;

#[test]
fn ranges_that_select_nothing_are_errors() {
    run(
        "ranges",
        vec![
            case("ball: NaN radius", "ball radius NaN", || {
                select2(Range::Ball {
                    center: [0.0; 3],
                    radius: NAN,
                })
            }),
            case("ball: negative radius", "ball radius -1", || {
                select2(Range::Ball {
                    center: [0.0; 3],
                    radius: -1.0,
                })
            }),
            case("ball: NaN centre", "ball centre", || {
                select2(Range::Ball {
                    center: [NAN, 0.0, 0.0],
                    radius: 1.0,
                })
            }),
            case("ball: infinite centre", "not finite", || {
                select2(Range::Ball {
                    center: [0.0, INF, 0.0],
                    radius: 1.0,
                })
            }),
            case("plane: zero normal", "plane normal", || {
                select2(Range::plane([0.0; 3], [0.0; 3], 0.1))
            }),
            case("plane: z-only normal in 2D", "z-only normal", || {
                select2(Range::plane([0.0; 3], [0.0, 0.0, 1.0], 0.1))
            }),
            case("plane: NaN normal", "plane normal", || {
                select2(Range::plane([0.0; 3], [NAN, 1.0, 0.0], 0.1))
            }),
            case("plane: NaN tolerance", "plane tolerance NaN", || {
                select2(Range::plane([0.0; 3], [1.0, 0.0, 0.0], NAN))
            }),
            case("plane: negative tolerance", "plane tolerance -0.1", || {
                select2(Range::plane([0.0; 3], [1.0, 0.0, 0.0], -0.1))
            }),
            case("plane: NaN point", "plane point", || {
                select2(Range::plane([NAN, 0.0, 0.0], [1.0, 0.0, 0.0], 0.1))
            }),
            case("half-space: zero normal", "half-space normal", || {
                select2(Range::HalfSpace {
                    point: [0.0; 3],
                    normal: [0.0; 3],
                })
            }),
            case("half-space: z-only normal in 2D", "z-only normal", || {
                select2(Range::HalfSpace {
                    point: [0.0; 3],
                    normal: [0.0, 0.0, -2.0],
                })
            }),
            case("half-space: infinite point", "half-space point", || {
                select2(Range::HalfSpace {
                    point: [INF, 0.0, 0.0],
                    normal: [1.0, 0.0, 0.0],
                })
            }),
            case("box: NaN corner", "NaN in component 0", || {
                select2(Range::rect(NAN, 0.0, 1.0, 1.0))
            }),
            case(
                "box: crossed corners",
                "min[1] = 1 and max[1] = 0 select nothing",
                || select2(Range::rect(0.0, 1.0, 1.0, 0.0)),
            ),
            case("box: min at +infinity", "select nothing", || {
                select2(Range::rect(INF, 0.0, INF, 1.0))
            }),
            case("box: 3D NaN z corner", "NaN in component 2", || {
                select3(Range::cuboid([0.0, 0.0, NAN], [1.0; 3]))
            }),
            case("3D: zero plane normal", "plane normal", || {
                select3(Range::plane([0.0; 3], [0.0; 3], 0.1))
            }),
            case("nested in and/not", "ball radius", || {
                select2(
                    Range::All.and(
                        Range::Ball {
                            center: [0.0; 3],
                            radius: NAN,
                        }
                        .complement(),
                    ),
                )
            }),
            case("unknown group", "no node group named 'nope'", || {
                select2(Range::group("nope"))
            }),
            case("unknown face group", "no face group named 'top2'", || {
                square().select_boundary_faces(&Range::group("top2"))
            }),
            case(
                "free point: group range",
                "cannot select a free point",
                || Range::group("left").contains_point(&[0.0, 0.0]),
            ),
            case("free point: 4 components", "dimension 4", || {
                Range::All.contains_point(&[0.0; 4])
            }),
        ],
    );
}
