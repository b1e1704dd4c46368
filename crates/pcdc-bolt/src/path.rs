//! The elements along a bolt's path: the candidate hosts of its nodes.
//!
//! A bolt node is grouted to the element that holds it. When it leaves that element
//! (its grout slips along the bolt, or the host breaks away and moves off), it is
//! re-found among the elements its bolt's reference path crosses from the node two nodes
//! before it to the node two after it ([`REACH`]; for the head and the tail, up to two
//! end-segment lengths beyond them): the elements it can reach by sliding along the bolt
//! by two segment lengths. Beyond that reach, or where no element holds it (an open
//! crack, outside the rock), it stays with its last host. Every node of the path's
//! elements has a force slot of the bolt's own ([`PathNode`]), summing the reactions of
//! the bolt nodes its elements host, so the engine's gather is fixed when the simulation
//! is built and a node can change host during a run, on the GPU too.

use pcdc_mesh::{Dim, Mesh};

use crate::host::{Host, Locator};

/// An element on a bolt's path.
#[derive(Clone, Debug)]
pub(crate) struct PathElement {
    /// Element index.
    pub element: u32,
    /// Its `D + 1` nodes.
    pub nodes: [u32; 4],
    /// 2D: the adjugate of its reference edge matrix D_m (dm3, −dm1, −dm2, dm0), so that
    /// D_x adj(D_m) = det(D_m) F gives its rotation without a division.
    pub ref_adj: [f64; 4],
    /// The bolt nodes (indices in the bolt-node set) whose candidates hold it:
    /// `[first, end)`.
    pub node_range: [u32; 2],
    /// The index of each of its nodes among its bolt's path nodes ([`PathNode`]).
    pub local: [u32; 4],
}

/// A mesh node of the elements on a bolt's path: one force slot, which sums the grout
/// reactions of the bolt nodes hosted by its elements (in bolt-node order). Adjacent
/// elements of a continuous mesh share their nodes, so there are fewer of these than
/// element corners.
#[derive(Clone, Debug)]
pub(crate) struct PathNode {
    /// Mesh node.
    pub node: u32,
    /// The bolt nodes that may add to it: `[first, end)`.
    pub node_range: [u32; 2],
    /// Its `(path element, corner)` pairs: `[first, end)` in [`PathNodes::refs`].
    pub refs: [u32; 2],
}

/// Every bolt's path nodes (bolt after bolt) and their `(path element, corner)` pairs.
#[derive(Clone, Debug, Default)]
pub(crate) struct PathNodes {
    pub nodes: Vec<PathNode>,
    pub refs: Vec<[u32; 2]>,
}

impl PathNodes {
    /// Adds the path nodes of one bolt's elements `path[first..]` (their node ranges
    /// set), numbering them from 0 for that bolt in `PathElement::local`; returns how
    /// many were added.
    pub fn add_bolt(&mut self, d: usize, path: &mut [PathElement], first: usize) -> usize {
        let start = self.nodes.len();
        let mut local_of = std::collections::HashMap::new();
        let mut lists: Vec<Vec<[u32; 2]>> = Vec::new();
        for (j, pe) in path.iter_mut().enumerate().skip(first) {
            for q in 0..=d {
                let m = pe.nodes[q];
                let local = *local_of.entry(m).or_insert_with(|| {
                    self.nodes.push(PathNode {
                        node: m,
                        node_range: [u32::MAX, 0],
                        refs: [0, 0],
                    });
                    lists.push(Vec::new());
                    lists.len() - 1
                });
                pe.local[q] = local as u32;
                lists[local].push([j as u32, q as u32]);
                let pn = &mut self.nodes[start + local];
                pn.node_range = [
                    pn.node_range[0].min(pe.node_range[0]),
                    pn.node_range[1].max(pe.node_range[1]),
                ];
            }
        }
        for (pn, list) in self.nodes[start..].iter_mut().zip(lists) {
            let r0 = self.refs.len() as u32;
            self.refs.extend(list);
            pn.refs = [r0, self.refs.len() as u32];
            if pn.node_range[0] > pn.node_range[1] {
                pn.node_range = [0, 0];
            }
        }
        self.nodes.len() - start
    }
}

/// One bolt's path: its elements (in the order the path meets them; the path runs on
/// [`REACH`] segment lengths beyond the head and the tail), and for each of its nodes the range of
/// its candidates in that list and its host in the reference
/// mesh (an index in that list, with the weights).
pub(crate) struct BoltPath {
    pub elements: Vec<u32>,
    pub windows: Vec<[usize; 2]>,
    pub hosts: Vec<(usize, Host)>,
}

/// How far a node reaches along its bolt, in segments either way (beyond the head and
/// the tail, in lengths of the end segment).
pub(crate) const REACH: usize = 2;

/// The elements found along a path, in the order found, and each one's index.
#[derive(Default)]
struct Found {
    list: Vec<u32>,
    index: std::collections::HashMap<usize, usize>,
}

impl Found {
    /// The path index of element `e`, added at the end if new (a long cable meets
    /// thousands, so not a linear search).
    fn index(&mut self, e: usize) -> usize {
        let list = &mut self.list;
        *self.index.entry(e).or_insert_with(|| {
            list.push(e as u32);
            list.len() - 1
        })
    }
}

/// Samples per element size along the path (an element the path only clips at a corner
/// may be missed; a node passing through it is re-found in the next one).
const SAMPLES_PER_CELL: f64 = 4.0;

/// Finds the elements along the polyline `points` (a bolt's nodes) and each node's host
/// (with `relocate` false, the hosts only). `Err` with the node index when a node lies
/// outside the mesh.
pub(crate) fn bolt_path<D: Dim>(
    locator: &Locator<'_, D>,
    points: &[[f64; 3]],
    relocate: bool,
) -> Result<BoltPath, usize> {
    let d = D::D;
    let mut elements = Found::default();
    // The nodes' hosts first, so that each is on the path whatever the sampling finds.
    let mut hosts = Vec::with_capacity(points.len());
    for (k, p) in points.iter().enumerate() {
        let host = locator.locate(&p[..d], 1e-9).ok_or(k)?;
        hosts.push(host);
    }
    // The path in order: REACH end-segment lengths before the head (where the head
    // slides to when the bolt is pulled), every segment (its samples, then its end node's
    // host), REACH lengths beyond the tail; each stretch as the range of path indices it
    // found, so that every node's candidates are contiguous and near each other.
    let step = locator.cell() / SAMPLES_PER_CELL;
    let sample = |a: [f64; 3], b: [f64; 3], elements: &mut Found| -> [usize; 2] {
        if !relocate {
            return [usize::MAX, 0];
        }
        let len = ((0..d).map(|k| (b[k] - a[k]).powi(2)).sum::<f64>()).sqrt();
        let n = ((len / step).ceil() as usize).clamp(1, 1 << 16);
        let mut range = [usize::MAX, 0];
        for i in 1..=n {
            let t = i as f64 / n as f64;
            let p: Vec<f64> = (0..d).map(|k| a[k] + t * (b[k] - a[k])).collect();
            if let Some(h) = locator.locate(&p, 1e-9) {
                let j = elements.index(h.element);
                range = [range[0].min(j), range[1].max(j + 1)];
            }
        }
        range
    };
    let join = |a: [usize; 2], b: [usize; 2]| [a[0].min(b[0]), a[1].max(b[1])];
    let last = points.len() - 1;
    let beyond = |a: [f64; 3], b: [f64; 3]| -> [f64; 3] {
        std::array::from_fn(|k| a[k] + REACH as f64 * (a[k] - b[k]))
    };
    let mut head = [usize::MAX, 0];
    if last > 0 {
        head = sample(beyond(points[0], points[1]), points[0], &mut elements);
    }
    let mut host_index = vec![0usize; points.len()];
    host_index[0] = elements.index(hosts[0].element);
    head = join(head, [host_index[0], host_index[0] + 1]);
    let mut seg_range: Vec<[usize; 2]> = Vec::with_capacity(last);
    for s in 0..last {
        let r = sample(points[s], points[s + 1], &mut elements);
        let j = elements.index(hosts[s + 1].element);
        host_index[s + 1] = j;
        let ends = [host_index[s].min(j), host_index[s].max(j) + 1];
        seg_range.push(join(r, ends));
    }
    let mut tail = [host_index[last], host_index[last] + 1];
    if last > 0 {
        let far = beyond(points[last], points[last - 1]);
        tail = join(tail, sample(points[last], far, &mut elements));
    }
    // Node k reaches the segments k − REACH .. k + REACH (and beyond the ends); without
    // re-location, its host only.
    let windows = (0..points.len())
        .map(|k| {
            if !relocate {
                return [host_index[k], host_index[k] + 1];
            }
            let mut w = [usize::MAX, 0];
            for r in &seg_range[k.saturating_sub(REACH)..(k + REACH).min(last)] {
                w = [w[0].min(r[0]), w[1].max(r[1])];
            }
            for r in [
                (k < REACH).then_some(head),
                (k + REACH > last).then_some(tail),
            ]
            .into_iter()
            .flatten()
            {
                w = [w[0].min(r[0]), w[1].max(r[1])];
            }
            w
        })
        .collect();
    Ok(BoltPath {
        elements: elements.list,
        windows,
        hosts: host_index.into_iter().zip(hosts).collect(),
    })
}

/// The path element of `element` in `mesh`, without its node range.
pub(crate) fn path_element<D: Dim>(mesh: &Mesh<D>, element: u32) -> PathElement {
    let d = D::D;
    let mut nodes = [0u32; 4];
    nodes[..=d].copy_from_slice(mesh.element(element as usize));
    let mut ref_adj = [0.0; 4];
    if d == 2 {
        let x = |q: usize| mesh.node(nodes[q] as usize);
        let (x0, x1, x2) = (x(0), x(1), x(2));
        let dm = [x1[0] - x0[0], x2[0] - x0[0], x1[1] - x0[1], x2[1] - x0[1]];
        ref_adj = [dm[3], -dm[1], -dm[2], dm[0]];
    }
    PathElement {
        element,
        nodes,
        ref_adj,
        node_range: [u32::MAX, 0],
        local: [0; 4],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pcdc_mesh::{builders, Dim2};

    #[test]
    fn windows_hold_the_own_host_and_reach_two_segments_and_beyond_the_ends() {
        // Elements 0.1 m across, a bolt of five 0.2 m segments off the mesh lines.
        let mesh = builders::rectangle(0.0, 0.0, 2.0, 1.0, 0.1).unwrap();
        let locator = Locator::new(&mesh);
        let pts: Vec<[f64; 3]> = (0..6)
            .map(|k| [0.55 + 0.2 * k as f64, 0.537, 0.0])
            .collect();
        let path = bolt_path(&locator, &pts, true).unwrap();
        let at = |x: f64| locator.locate(&[x, 0.537], 1e-9).unwrap().element as u32;
        let within = |k: usize, e: u32| {
            let w = path.windows[k];
            path.elements[w[0]..w[1]].contains(&e)
        };
        for (k, &(local, host)) in path.hosts.iter().enumerate() {
            assert_eq!(path.elements[local] as usize, host.element);
            assert!(within(k, host.element as u32), "node {k}");
            // Two segments either way along the bolt, and no further.
            let x = pts[k][0];
            if k >= 2 {
                assert!(within(k, at(x - 0.39)), "node {k} back");
            }
            if k + 2 <= 5 {
                assert!(within(k, at(x + 0.39)), "node {k} on");
            }
            if k >= 3 {
                assert!(!within(k, at(x - 0.61)), "node {k} too far back");
            }
        }
        // The head reaches two segment lengths beyond itself, the tail too.
        assert!(within(0, at(0.55 - 0.39)));
        assert!(within(5, at(1.55 + 0.39)));
        // Without re-location: the hosts only, each node's window its own host.
        let fixed = bolt_path(&locator, &pts, false).unwrap();
        for (k, w) in fixed.windows.iter().enumerate() {
            assert_eq!(w[1] - w[0], 1, "node {k}");
            assert_eq!(fixed.hosts[k].0, w[0]);
        }
    }

    #[test]
    fn path_nodes_are_shared_by_neighbouring_elements() {
        let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.1).unwrap();
        let locator = Locator::new(&mesh);
        let pts = [[0.15, 0.537, 0.0], [0.85, 0.537, 0.0]];
        let route = bolt_path::<Dim2>(&locator, &pts, true).unwrap();
        let mut path: Vec<PathElement> = route
            .elements
            .iter()
            .map(|&e| {
                let mut pe = path_element(&mesh, e);
                pe.node_range = [0, 2];
                pe
            })
            .collect();
        let mut pn = PathNodes::default();
        let added = pn.add_bolt(2, &mut path, 0);
        // Every corner maps to its mesh node, each mesh node once.
        for pe in &path {
            for q in 0..3 {
                assert_eq!(pn.nodes[pe.local[q] as usize].node, pe.nodes[q]);
            }
        }
        let mut seen: Vec<u32> = pn.nodes.iter().map(|p| p.node).collect();
        seen.sort_unstable();
        seen.dedup();
        assert_eq!(seen.len(), added);
        assert!(
            added < 3 * path.len(),
            "{added} nodes for {} elements",
            path.len()
        );
        // Each (element, corner) pair is listed under its node exactly once.
        let pairs: usize = pn
            .nodes
            .iter()
            .map(|p| (p.refs[1] - p.refs[0]) as usize)
            .sum();
        assert_eq!(pairs, 3 * path.len());
    }
}
