//! The unstructured mesher: quality, size, groups, constraints, holes, seeds, bad input.
#![cfg(feature = "mesher")]

use pcdc_mesh::mesher::{self, Domain, Loop, MesherOptions, SizeField};
use pcdc_mesh::{Dim2, Mesh, MeshError};

fn area(mesh: &Mesh<Dim2>) -> f64 {
    let q = mesher::quality(mesh);
    q.mean_area * mesh.n_elements() as f64
}

#[test]
fn rectangle_quality_size_and_groups() {
    let (w, h, size) = (0.052, 0.108, 0.002);
    let t = std::time::Instant::now();
    let mesh = mesher::rectangle(0.0, 0.0, w, h, &MesherOptions::uniform(size)).unwrap();
    let q = mesher::quality(&mesh);
    eprintln!("{} elements, {:?}, {:?}", mesh.n_elements(), q, t.elapsed());
    assert!(
        q.min_angle_deg >= mesher::DEFAULT_MIN_ANGLE_DEG - 1e-9,
        "{q:?}"
    );
    assert!((area(&mesh) - w * h).abs() < 1e-12 * w * h);
    let eq = 0.75f64.sqrt() / 2.0 * size * size;
    assert!(
        (q.mean_area / eq - 1.0).abs() < 0.12,
        "mean area {} vs {eq}",
        q.mean_area
    );
    for (g, x, y) in [
        ("left", Some(0.0), None),
        ("right", Some(w), None),
        ("bottom", None, Some(0.0)),
        ("top", None, Some(h)),
    ] {
        let nodes = &mesh.groups().nodes[g];
        assert!(
            nodes.len() as f64 >= (if x.is_some() { h } else { w }) / size * 0.9,
            "{g}"
        );
        for &n in nodes {
            let p = mesh.node(n as usize);
            if let Some(x) = x {
                assert!((p[0] - x).abs() < 1e-12, "{g}");
            }
            if let Some(y) = y {
                assert!((p[1] - y).abs() < 1e-12, "{g}");
            }
        }
        assert_eq!(mesh.groups().faces[g].len(), nodes.len() - 1, "{g}");
    }
}

#[test]
fn seeds_reproduce_and_differ() {
    let o = MesherOptions::uniform(0.004);
    let a = mesher::rectangle(0.0, 0.0, 0.05, 0.1, &o).unwrap();
    let b = mesher::rectangle(0.0, 0.0, 0.05, 0.1, &o).unwrap();
    let c = mesher::rectangle(0.0, 0.0, 0.05, 0.1, &o.clone().seed(7)).unwrap();
    assert_eq!(a.coords(), b.coords());
    assert_eq!(a.elements(), b.elements());
    assert_ne!(a.coords(), c.coords());
    let (na, nc) = (a.n_elements() as f64, c.n_elements() as f64);
    assert!((na / nc - 1.0).abs() < 0.05, "{na} vs {nc}");
}

/// The edges point every way: the share of interior edge length in each 15° sector of
/// direction stays within 15 % of 1/12 (sampling scatter of about 7500 edges is
/// ±4-8 %), where a structured pattern puts all of it in two or three sectors.
#[test]
fn edge_directions_are_isotropic() {
    let mesh =
        mesher::rectangle(0.0, 0.0, 0.1, 0.1, &MesherOptions::uniform(0.002).seed(3)).unwrap();
    let shares = direction_shares(&mesh);
    for (k, share) in shares.iter().enumerate() {
        assert!(
            (share - 1.0).abs() < 0.15,
            "sector {k}: {share} of the uniform share"
        );
    }
    let structured = pcdc_mesh::builders::rectangle(0.0, 0.0, 0.1, 0.1, 0.002).unwrap();
    let shares = direction_shares(&structured);
    assert!(
        shares.iter().filter(|&&s| s == 0.0).count() >= 8,
        "{shares:?}"
    );
}

/// Interior edge length per 15° sector of direction, relative to the uniform share.
fn direction_shares(mesh: &Mesh<Dim2>) -> Vec<f64> {
    let mut bins = [0.0; 12];
    let x = mesh.coords();
    for e in 0..mesh.n_elements() {
        let t = mesh.element(e);
        for k in 0..3 {
            let (a, b) = (t[k] as usize, t[(k + 1) % 3] as usize);
            let (dx, dy) = (x[2 * b] - x[2 * a], x[2 * b + 1] - x[2 * a + 1]);
            // Interior edges only: the square's sides are all at 0° and 90°.
            let mid = [x[2 * a] + 0.5 * dx, x[2 * a + 1] + 0.5 * dy];
            if mid.iter().any(|&c| !(1e-12..=0.1 - 1e-12).contains(&c)) {
                continue;
            }
            let ang = dy.atan2(dx).rem_euclid(std::f64::consts::PI).to_degrees();
            bins[((ang / 15.0) as usize).min(11)] += (dx * dx + dy * dy).sqrt();
        }
    }
    let total: f64 = bins.iter().sum();
    bins.iter().map(|b| b / total * 12.0).collect()
}

#[test]
fn disc_and_ring_fill_their_areas() {
    let r = 0.025;
    let d = mesher::disc([0.0, 0.0], r, 0.001, 1).unwrap();
    let q = mesher::quality(&d);
    let n = (std::f64::consts::TAU * r / 0.001).round();
    let polygon = 0.5 * n * r * r * (std::f64::consts::TAU / n).sin();
    assert!(
        (area(&d) - polygon).abs() < 1e-12,
        "{} vs {polygon}",
        area(&d)
    );
    assert!(q.min_angle_deg >= 28.0 - 1e-9, "{q:?}");
    let eq = 0.75f64.sqrt() / 2.0 * 1e-6;
    assert!(
        (q.mean_area / eq - 1.0).abs() < 0.1,
        "mean area {} vs {eq}",
        q.mean_area
    );
    for &nd in &d.groups().nodes["boundary"] {
        let p = d.node(nd as usize);
        assert!(((p[0] * p[0] + p[1] * p[1]).sqrt() - r).abs() < 1e-12);
    }
    let ring = mesher::ring([0.0, 0.0], 1.0, 10.0, 0.1, 1.5, 0).unwrap();
    let q = mesher::quality(&ring);
    assert!(q.min_angle_deg >= 28.0 - 1e-9, "{q:?}");
    assert!(!ring.groups().nodes["inner"].is_empty() && !ring.groups().faces["outer"].is_empty());
    // Graded: small elements at the hole, large far away.
    let mut c = [0.0; 2];
    let (mut near, mut far) = (Vec::new(), Vec::new());
    for e in 0..ring.n_elements() {
        ring.element_centroid(e, &mut c);
        let rr = (c[0] * c[0] + c[1] * c[1]).sqrt();
        if rr < 1.2 {
            near.push(ring.element_measure(e))
        }
        if rr > 8.0 {
            far.push(ring.element_measure(e))
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (hn, hf) = ((mean(&near) / 0.433).sqrt(), (mean(&far) / 0.433).sqrt());
    eprintln!(
        "ring: {} elements, size near {hn}, far {hf}",
        ring.n_elements()
    );
    assert!(hn < 0.15 && hf > 1.0, "near {hn}, far {hf}");
}

#[test]
fn plate_with_hole_has_its_groups_and_no_elements_in_the_hole() {
    let m = mesher::plate_with_hole(0.2, 0.1, 0.03, 0.004, 0.02, 5).unwrap();
    let mut c = [0.0; 2];
    for e in 0..m.n_elements() {
        m.element_centroid(e, &mut c);
        assert!(c[0].hypot(c[1]) > 0.029);
    }
    for g in ["hole", "left", "right", "top", "bottom"] {
        assert!(!m.groups().faces[g].is_empty(), "{g}");
    }
    let expected = 0.4 * 0.2 - std::f64::consts::PI * 0.03f64.powi(2);
    assert!((area(&m) - expected).abs() < 0.01 * expected);
}

/// A constraint line becomes a chain of mesh edges: its face group holds interior faces
/// on the line whose lengths add up to the line's length.
#[test]
fn constraint_lines_are_mesh_edges() {
    let outer = Loop::new(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    let (a, b, c) = ([0.2, 0.3], [0.5, 0.55], [0.8, 0.5]);
    let domain = Domain::new(outer).line(vec![a, b, c], Some("fracture"));
    let m = mesher::triangulate(&domain, &MesherOptions::uniform(0.05)).unwrap();
    let faces = &m.groups().faces["fracture"];
    let mut n = [0.0; 2];
    let total: f64 = faces
        .iter()
        .map(|&f| m.face_measure_normal(f as usize, &mut n))
        .sum();
    let len = |p: [f64; 2], q: [f64; 2]| (q[0] - p[0]).hypot(q[1] - p[1]);
    assert!((total - len(a, b) - len(b, c)).abs() < 1e-12, "{total}");
    assert!(faces.iter().all(|f| !m.faces().boundary.contains(f)));
    assert!(mesher::quality(&m).min_angle_deg >= 28.0 - 1e-9);
    // The line does not cut the domain: every element is kept.
    assert!((area(&m) - 1.0).abs() < 1e-12);
}

fn domain_error(d: &Domain, o: &MesherOptions) -> String {
    match mesher::triangulate(d, o) {
        Err(e) => e.to_string(),
        Ok(m) => panic!("meshed a bad domain into {} elements", m.n_elements()),
    }
}

#[test]
fn bad_domains_and_options_are_named() {
    let o = MesherOptions::uniform(0.1);
    let square = || Loop::new(vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]);
    let bow = Domain::new(Loop::new(vec![
        [0.0, 0.0],
        [1.0, 1.0],
        [1.0, 0.0],
        [0.0, 1.0],
    ]));
    let e = domain_error(&bow, &o);
    assert!(e.contains("outer boundary") && e.contains("meets"), "{e}");
    let outside = Domain::new(square()).hole(Loop::circle([3.0, 3.0], 0.2, 12));
    let e = domain_error(&outside, &o);
    assert!(e.contains("hole 0") && e.contains("outside"), "{e}");
    let crossing = Domain::new(square()).hole(Loop::circle([1.0, 0.5], 0.2, 12));
    assert!(domain_error(&crossing, &o).contains("hole 0"));
    let nested = Domain::new(square())
        .hole(Loop::circle([0.5, 0.5], 0.3, 16))
        .hole(Loop::circle([0.5, 0.5], 0.1, 12));
    assert!(
        domain_error(&nested, &o).contains("meets") || domain_error(&nested, &o).contains("nested")
    );
    let line_out = Domain::new(square()).line(vec![[0.5, 0.5], [1.5, 0.5]], None);
    assert!(
        domain_error(&line_out, &o).contains("line 0"),
        "{}",
        domain_error(&line_out, &o)
    );
    let dup = Domain::new(Loop::new(vec![
        [0.0, 0.0],
        [1.0, 0.0],
        [1.0, 0.0],
        [0.0, 1.0],
    ]));
    assert!(domain_error(&dup, &o).contains("zero length"));
    let two = Domain::new(Loop::new(vec![[0.0, 0.0], [1.0, 0.0]]));
    assert!(domain_error(&two, &o).contains("three points"));
    let nan = Domain::new(Loop::new(vec![[0.0, 0.0], [f64::NAN, 0.0], [0.0, 1.0]]));
    assert!(domain_error(&nan, &o).contains("non-finite"));
    let sq = Domain::new(square());
    assert!(domain_error(&sq, &MesherOptions::uniform(1e-6)).contains("1e-4"));
    assert!(domain_error(&sq, &MesherOptions::uniform(-1.0)).contains("size"));
    assert!(domain_error(&sq, &MesherOptions::uniform(5.0)).contains("extent"));
    let mut steep = MesherOptions::uniform(0.1);
    steep.min_angle_deg = 40.0;
    assert!(domain_error(&sq, &steep).contains("min_angle_deg"));
    let graded = MesherOptions {
        size: SizeField::Graded {
            near: 0.05,
            far: 0.2,
            growth: 0.3,
        },
        ..MesherOptions::uniform(0.1)
    };
    assert!(domain_error(&sq, &graded).contains("graded"));
    // A very wide gradation is refused before it allocates the sampler's grid.
    let holed = Domain::new(Loop::new(vec![
        [0.0, 0.0],
        [100.0, 0.0],
        [100.0, 100.0],
        [0.0, 100.0],
    ]))
    .hole(Loop::circle([50.0, 50.0], 1.0, 16));
    let wide = MesherOptions {
        size: SizeField::Graded {
            near: 0.011,
            far: 5.0,
            growth: 0.5,
        },
        ..MesherOptions::uniform(1.0)
    };
    assert!(domain_error(&holed, &wide).contains("64 million"));
    // Serde input goes through the same checks.
    let d: Domain =
        serde_json::from_str(r#"{"outer": {"points": [[0,0],[1,1],[1,0],[0,1]]}}"#).unwrap();
    assert!(matches!(
        mesher::triangulate(&d, &o),
        Err(MeshError::Domain { .. })
    ));
}
