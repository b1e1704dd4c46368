//! A bolt's geometry: a polyline of two-node bar segments from the head (node 0, at the
//! excavation face, where a face plate bears) to the tail (the far, anchored end),
//! placed by its end points and a segment count, by its node positions, along lines
//! (a 2D face group, or a Gmsh curve group in 2D or 3D).

use pcdc_mesh::{Dim, Mesh};

use crate::{BoltError, BoltMaterial};

/// One bolt or cable: its name (used in errors and output), node positions (m, head
/// first; the z of 2D bolts is ignored), properties, free (ungrouted) length from the
/// head and optional face plate.
#[derive(Clone, Debug, PartialEq)]
pub struct Bolt {
    name: String,
    points: Vec<[f64; 3]>,
    material: BoltMaterial,
    free_length: f64,
    plate: Option<f64>,
}

fn finite(name: &str, p: &[f64; 3]) -> Result<(), BoltError> {
    if p.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(BoltError::Geometry {
            bolt: name.to_string(),
            reason: format!("point {p:?} is not finite"),
        })
    }
}

/// Node `n` of `mesh` as a 3-vector (m; z = 0 in 2D).
fn position<D: Dim>(mesh: &Mesh<D>, n: u32) -> [f64; 3] {
    let mut p = [0.0; 3];
    p[..D::D].copy_from_slice(mesh.node(n as usize));
    p
}

fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

impl Bolt {
    /// A straight bolt from `head` to `tail` (m) in `segments` equal segments (≥ 1).
    /// Errors (naming the bolt) on coincident or non-finite end points or no segment.
    pub fn straight(
        name: impl Into<String>,
        head: [f64; 3],
        tail: [f64; 3],
        segments: usize,
        material: BoltMaterial,
    ) -> Result<Self, BoltError> {
        let name = name.into();
        finite(&name, &head)?;
        finite(&name, &tail)?;
        if segments == 0 {
            return Err(BoltError::Geometry {
                bolt: name,
                reason: "needs at least one segment".into(),
            });
        }
        let points = (0..=segments)
            .map(|i| {
                let t = i as f64 / segments as f64;
                std::array::from_fn(|k| head[k] + t * (tail[k] - head[k]))
            })
            .collect::<Vec<_>>();
        Self::polyline(name, &points, material)
    }

    /// A bolt whose nodes are `points` (m, head first, at least two); consecutive
    /// points must differ.
    pub fn polyline(
        name: impl Into<String>,
        points: &[[f64; 3]],
        material: BoltMaterial,
    ) -> Result<Self, BoltError> {
        let name = name.into();
        if points.len() < 2 {
            return Err(BoltError::Geometry {
                bolt: name,
                reason: format!("needs at least two points, got {}", points.len()),
            });
        }
        for p in points {
            finite(&name, p)?;
        }
        let scale = points
            .iter()
            .flatten()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(f64::MIN_POSITIVE);
        for (i, w) in points.windows(2).enumerate() {
            if dist(&w[0], &w[1]) <= 1e-12 * scale {
                return Err(BoltError::Geometry {
                    bolt: name,
                    reason: format!(
                        "points {i} and {} coincide at {:?}: a segment needs two distinct end points",
                        i + 1,
                        w[0]
                    ),
                });
            }
        }
        Ok(Bolt {
            name,
            points: points.to_vec(),
            material,
            free_length: 0.0,
            plate: None,
        })
    }

    /// A 2D bolt along the lines of face group `group` of `mesh` (e.g. a Gmsh physical
    /// line group), one segment per line, ordered into one open polyline whose head is
    /// the end nearer to `head_near` (m). Errors if the group is missing, is not a 2D
    /// line group, or its lines do not form one open chain.
    pub fn from_face_group<D: Dim>(
        name: impl Into<String>,
        mesh: &Mesh<D>,
        group: &str,
        head_near: [f64; 3],
        material: BoltMaterial,
    ) -> Result<Self, BoltError> {
        let name = name.into();
        let geometry = |reason: String| BoltError::Geometry {
            bolt: name.clone(),
            reason,
        };
        if D::D != 2 {
            return Err(geometry(
                "a bolt from a face group needs a 2D mesh (in 3D use Bolt::from_line_group)".into(),
            ));
        }
        let faces = mesh
            .groups()
            .faces
            .get(group)
            .ok_or_else(|| geometry(format!("the mesh has no face group '{group}'")))?;
        let lines: Vec<[[f64; 3]; 2]> = faces
            .iter()
            .map(|&f| {
                let nodes = mesh.face(f as usize);
                [position(mesh, nodes[0]), position(mesh, nodes[1])]
            })
            .collect();
        let what = format!("face group '{group}'");
        Self::chained(name, &lines, head_near, material, &what)
    }

    /// A bolt along the lines of physical curve group `group` of a Gmsh import
    /// ([`MshImport::lines`](pcdc_mesh::gmsh::MshImport::lines)), in 2D or 3D: one segment
    /// per line, chained into one open polyline whose head is the end nearer to
    /// `head_near` (m). Mesh the curve embedded in the volume (Gmsh `fragment` or
    /// `embed`, as `meshes/make_specimens.py` does), so that every bolt node lies on an
    /// element's edge. Errors if the import has no such curve group or its lines do not
    /// form one open chain.
    pub fn from_line_group<D: Dim>(
        name: impl Into<String>,
        import: &pcdc_mesh::gmsh::MshImport<D>,
        group: &str,
        head_near: [f64; 3],
        material: BoltMaterial,
    ) -> Result<Self, BoltError> {
        let name = name.into();
        let pairs = import.lines.get(group).ok_or_else(|| BoltError::Geometry {
            bolt: name.clone(),
            reason: format!("the Gmsh import has no physical curve group '{group}'"),
        })?;
        let mesh = &import.mesh;
        let lines: Vec<[[f64; 3]; 2]> = pairs
            .iter()
            .map(|&[a, b]| [position(mesh, a), position(mesh, b)])
            .collect();
        let what = format!("curve group '{group}'");
        Self::chained(name, &lines, head_near, material, &what)
    }

    /// A bolt along `lines` (pairs of end points, m, in any order and orientation),
    /// chained into one open polyline by shared end points (equal coordinates), head
    /// at the end nearer to `head_near`. Errors if the lines do not form one open chain.
    pub fn from_lines(
        name: impl Into<String>,
        lines: &[[[f64; 3]; 2]],
        head_near: [f64; 3],
        material: BoltMaterial,
    ) -> Result<Self, BoltError> {
        Self::chained(name.into(), lines, head_near, material, "the lines")
    }

    /// Chains `lines` (`what` names them in errors) into one open polyline from the end
    /// nearer to `head_near`.
    fn chained(
        name: String,
        lines: &[[[f64; 3]; 2]],
        head_near: [f64; 3],
        material: BoltMaterial,
        what: &str,
    ) -> Result<Self, BoltError> {
        let geometry = |reason: String| BoltError::Geometry {
            bolt: name.clone(),
            reason,
        };
        // Chain by position (split copies of a vertex share it).
        let key = |x: &[f64; 3]| x.map(f64::to_bits);
        let mut points: Vec<[u64; 3]> = Vec::new();
        let mut edges: Vec<(usize, usize)> = Vec::new();
        let index = |k: [u64; 3], points: &mut Vec<[u64; 3]>| {
            points.iter().position(|p| *p == k).unwrap_or_else(|| {
                points.push(k);
                points.len() - 1
            })
        };
        for [p, q] in lines {
            let a = index(key(p), &mut points);
            let b = index(key(q), &mut points);
            if a != b && !edges.contains(&(a, b)) && !edges.contains(&(b, a)) {
                edges.push((a, b));
            }
        }
        let mut degree = vec![0usize; points.len()];
        for &(a, b) in &edges {
            degree[a] += 1;
            degree[b] += 1;
        }
        let ends: Vec<usize> = (0..points.len()).filter(|&p| degree[p] == 1).collect();
        if edges.is_empty() || ends.len() != 2 || degree.iter().any(|&d| d > 2) {
            return Err(geometry(format!(
                "{what} ({} lines) is not one open chain of lines",
                edges.len()
            )));
        }
        let pos = |p: usize| points[p].map(f64::from_bits);
        let head = if dist(&pos(ends[0]), &head_near) <= dist(&pos(ends[1]), &head_near) {
            ends[0]
        } else {
            ends[1]
        };
        let mut chain = vec![head];
        let mut used = vec![false; edges.len()];
        while let Some((e, &(a, b))) = edges.iter().enumerate().find(|(e, &(a, b))| {
            !used[*e] && (a == *chain.last().unwrap() || b == *chain.last().unwrap())
        }) {
            used[e] = true;
            let last = *chain.last().unwrap();
            chain.push(if a == last { b } else { a });
        }
        if chain.len() != edges.len() + 1 {
            return Err(geometry(format!(
                "{what} is not one connected chain of lines"
            )));
        }
        let pts: Vec<[f64; 3]> = chain.into_iter().map(pos).collect();
        Self::polyline(name, &pts, material)
    }

    /// Leaves the first `length` metres from the head ungrouted (the free length of an
    /// end-anchored or pretensioned bolt): its nodes keep the grout's lateral support
    /// (the borehole) but take no bond force, and its segments carry the pretension.
    /// Must be non-negative and shorter than the bolt.
    pub fn free_length(mut self, length: f64) -> Result<Self, BoltError> {
        let total = self.length();
        if !(length >= 0.0 && length < total) {
            return Err(BoltError::param(
                format!("free_length of bolt '{}'", self.name),
                length,
                format!("must be non-negative and below the bolt's length {total} m"),
            ));
        }
        self.free_length = length;
        Ok(self)
    }

    /// A face plate at the head bearing on the rock surface: a one-sided spring of
    /// `stiffness` (N/m per bolt; divided by the spacing in 2D) that pushes the head back
    /// out when the bolt pulls it into the rock, and the reaction into the rock.
    pub fn face_plate(mut self, stiffness: f64) -> Result<Self, BoltError> {
        if !(stiffness > 0.0 && stiffness.is_finite()) {
            return Err(BoltError::param(
                format!("face plate stiffness of bolt '{}'", self.name),
                stiffness,
                "must be positive (N/m)",
            ));
        }
        self.plate = Some(stiffness);
        Ok(self)
    }

    /// The bolt's name.
    pub fn name(&self) -> &str {
        &self.name
    }
    /// Node positions (m), head first.
    pub fn points(&self) -> &[[f64; 3]] {
        &self.points
    }
    /// Number of segments.
    pub fn segments(&self) -> usize {
        self.points.len() - 1
    }
    /// Properties.
    pub fn material(&self) -> &BoltMaterial {
        &self.material
    }
    /// Ungrouted length from the head (m).
    pub fn free(&self) -> f64 {
        self.free_length
    }
    /// Face plate stiffness (N/m), if any.
    pub fn plate(&self) -> Option<f64> {
        self.plate
    }
    /// Total reference length (m).
    pub fn length(&self) -> f64 {
        self.points.windows(2).map(|w| dist(&w[0], &w[1])).sum()
    }
    /// Reference length of segment `s` (m).
    pub fn segment_length(&self, s: usize) -> f64 {
        dist(&self.points[s], &self.points[s + 1])
    }
    /// Distance of node `n` from the head along the bolt (m).
    pub fn arc_length(&self, n: usize) -> f64 {
        (0..n).map(|s| self.segment_length(s)).sum()
    }
}
