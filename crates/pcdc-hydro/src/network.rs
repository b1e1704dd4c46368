//! The flow network (manual 7.5.1, figs 54–55): a channel on every permeable joint (a
//! two-node line in 2D, a three-node triangle in 3D) and a flow node at every original
//! mesh vertex those channels touch.
//!
//! A flow node is one per vertex of the mesh before [`pcdc_mesh::split_nodes`]: the split
//! copies of a vertex (one per element) and every channel that meets there share it, so
//! the pressure is continuous across junctions and stays one value when the solid
//! separates (Irazu's and OpenFDEM's "cavity" of the split nodes at a vertex). Channel
//! `c` lies on joint (interface) `joint[c]`; its node `k` is the flow node of the
//! interface's node pair `k`.

use std::collections::HashMap;

use pcdc_compute::ComputeError;
use pcdc_mesh::{Dim, Mesh, Range};

/// Channels and flow nodes of a split mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Network {
    /// Flow nodes per channel (2 in 2D, 3 in 3D).
    pub npc: usize,
    /// Interface (joint) of each channel.
    pub joint: Vec<u32>,
    /// Flow node of each channel's node pair `k`, stride `npc`.
    pub channel_nodes: Vec<u32>,
    /// Per flow node, a mesh node standing for it (the first split copy met): its
    /// position is the flow node's position in output and for head conditions.
    pub node_mesh: Vec<u32>,
    /// Per mesh node, its flow node, or [`Network::NONE`] off the network.
    pub mesh_flow: Vec<u32>,
    /// Incidence in gather order: flow node `l` takes the channel-node entries
    /// `incidence[inc_ptr[l]..inc_ptr[l + 1]]` (entry `c * npc + k`), ascending.
    pub inc_ptr: Vec<u32>,
    /// See `inc_ptr`.
    pub incidence: Vec<u32>,
}

impl Network {
    /// "No flow node" in [`Network::mesh_flow`].
    pub const NONE: u32 = u32::MAX;

    /// The network on the interfaces of `mesh` whose side-A face centroid lies in
    /// `only` (every interface with `None`) and that are not `impermeable`: a joint is
    /// impermeable when either of its elements has its centroid in one of the ranges.
    pub fn build<D: Dim>(
        mesh: &Mesh<D>,
        only: Option<&Range>,
        impermeable: &[Range],
    ) -> Result<Self, ComputeError> {
        let joints = mesh.interfaces();
        if joints.is_empty() {
            return Err(ComputeError::param(
                "flow network",
                "no joints",
                "flow runs along the joints of a split mesh: split it with pcdc_mesh::split_nodes first",
            ));
        }
        let mut closed = vec![false; mesh.n_elements()];
        for r in impermeable {
            for e in mesh.select_elements(r)? {
                closed[e as usize] = true;
            }
        }
        let allowed = match only {
            Some(r) => Some(mesh.select_faces(r)?),
            None => None,
        };
        let npc = D::NODES_PER_FACE;
        let mut net = Network {
            npc,
            joint: Vec::new(),
            channel_nodes: Vec::new(),
            node_mesh: Vec::new(),
            mesh_flow: vec![Self::NONE; mesh.n_nodes()],
            inc_ptr: Vec::new(),
            incidence: Vec::new(),
        };
        let mut of_master: HashMap<u32, u32> = HashMap::new();
        for (j, joint) in joints.iter().enumerate() {
            if closed[joint.elements[0] as usize] || closed[joint.elements[1] as usize] {
                continue;
            }
            if let Some(faces) = &allowed {
                if faces.binary_search(&joint.faces[0]).is_err() {
                    continue;
                }
            }
            net.joint.push(j as u32);
            for k in 0..npc {
                let a = joint.side_a[k];
                let m = joints.master_of(a);
                let next = net.node_mesh.len() as u32;
                let f = *of_master.entry(m).or_insert(next);
                if f == next {
                    net.node_mesh.push(a);
                }
                net.channel_nodes.push(f);
            }
        }
        if net.joint.is_empty() {
            return Err(ComputeError::param(
                "flow network",
                "no permeable joint",
                "the network range and the impermeable ranges leave no channel",
            ));
        }
        for (n, m) in joints.master().iter().enumerate() {
            if let Some(&f) = of_master.get(m) {
                net.mesh_flow[n] = f;
            }
        }
        // Incidence lists, in ascending channel-node order (a counting sort).
        let nf = net.node_mesh.len();
        let mut count = vec![0u32; nf + 1];
        for &f in &net.channel_nodes {
            count[f as usize + 1] += 1;
        }
        for l in 0..nf {
            count[l + 1] += count[l];
        }
        let mut fill = count.clone();
        net.incidence = vec![0; net.channel_nodes.len()];
        for (e, &f) in net.channel_nodes.iter().enumerate() {
            net.incidence[fill[f as usize] as usize] = e as u32;
            fill[f as usize] += 1;
        }
        net.inc_ptr = count;
        Ok(net)
    }

    /// Number of channels.
    pub fn n_channels(&self) -> usize {
        self.joint.len()
    }

    /// Number of flow nodes.
    pub fn n_nodes(&self) -> usize {
        self.node_mesh.len()
    }

    /// The distinct flow nodes of the mesh nodes in `range` (nodes of the range off the
    /// network, e.g. a corner no joint reaches, are left out); an error when the range
    /// selects no node, or none on the network, naming a selected node (`what` names the
    /// condition).
    pub fn select<D: Dim>(
        &self,
        mesh: &Mesh<D>,
        range: &Range,
        what: &str,
    ) -> Result<Vec<u32>, ComputeError> {
        let nodes = mesh.select_nodes(range)?;
        if nodes.is_empty() {
            return Err(ComputeError::param(
                what,
                format!("{range:?}"),
                "the range selects no node",
            ));
        }
        let mut out = Vec::with_capacity(nodes.len());
        for &n in &nodes {
            let f = self.mesh_flow[n as usize];
            if f != Self::NONE {
                out.push(f);
            }
        }
        if out.is_empty() {
            let n = nodes[0];
            let x = mesh.node(n as usize);
            return Err(ComputeError::param(
                what,
                format!("node {n} at {x:?}"),
                "the range selects no node of the flow network (no permeable joint touches its nodes)",
            ));
        }
        out.sort_unstable();
        out.dedup();
        Ok(out)
    }

    /// The channels whose joint's side-A face has its centroid in `range`.
    pub fn channels_in<D: Dim>(
        &self,
        mesh: &Mesh<D>,
        range: &Range,
    ) -> Result<Vec<u32>, ComputeError> {
        let faces = mesh.select_faces(range)?;
        let joints = mesh.interfaces();
        let mut out = Vec::new();
        for (c, &j) in self.joint.iter().enumerate() {
            if faces.binary_search(&joints.faces()[2 * j as usize]).is_ok() {
                out.push(c as u32);
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pcdc_mesh::{builders, split_nodes};

    #[test]
    fn one_flow_node_per_vertex_shared_by_its_copies() {
        let mesh = builders::rectangle(0.0, 0.0, 2.0, 1.0, 0.5).unwrap();
        let split = split_nodes(&mesh, &Range::All).unwrap();
        let net = Network::build(&split, None, &[]).unwrap();
        // One flow node per original vertex on an interior edge (all 15 but the two
        // corners whose only triangle has no interior edge there).
        let mut masters: Vec<u32> = split
            .interfaces()
            .nodes()
            .iter()
            .map(|&n| split.interfaces().master_of(n))
            .collect();
        masters.sort_unstable();
        masters.dedup();
        assert_eq!(masters.len(), 13);
        assert_eq!(net.n_nodes(), masters.len());
        assert_eq!(net.n_channels(), split.interfaces().len());
        let joints = split.interfaces();
        for n in 0..split.n_nodes() {
            let f = net.mesh_flow[n];
            let on = masters.binary_search(&joints.master_of(n as u32)).is_ok();
            assert_eq!(f != Network::NONE, on);
            if !on {
                continue;
            }
            let rep = net.node_mesh[f as usize];
            assert_eq!(joints.master_of(rep), joints.master_of(n as u32));
        }
        // Incidence: every channel-node entry once, in ascending order per node.
        let mut seen = vec![false; net.channel_nodes.len()];
        for l in 0..net.n_nodes() {
            let list = &net.incidence[net.inc_ptr[l] as usize..net.inc_ptr[l + 1] as usize];
            assert!(list.windows(2).all(|w| w[0] < w[1]));
            for &e in list {
                assert_eq!(net.channel_nodes[e as usize], l as u32);
                seen[e as usize] = true;
            }
        }
        assert!(seen.iter().all(|&s| s));
    }

    #[test]
    fn impermeable_ranges_and_unsplit_meshes() {
        let mesh = builders::rectangle(0.0, 0.0, 2.0, 1.0, 0.5).unwrap();
        let e = Network::build(&mesh, None, &[]).unwrap_err().to_string();
        assert!(e.contains("split_nodes"), "{e}");
        let split = split_nodes(&mesh, &Range::All).unwrap();
        let all = Network::build(&split, None, &[]).unwrap();
        let half = Network::build(&split, None, &[Range::rect(0.0, 0.0, 1.0, 1.0)]).unwrap();
        assert!(half.n_channels() < all.n_channels());
        let e = Network::build(&split, None, &[Range::All])
            .unwrap_err()
            .to_string();
        assert!(e.contains("impermeable"), "{e}");
        // Only the joints along y = 0.5: one line of channels, 5 flow nodes.
        let line = Network::build(
            &split,
            Some(&Range::plane([0.0, 0.5, 0.0], [0.0, 1.0, 0.0], 1e-9)),
            &[],
        )
        .unwrap();
        assert_eq!(line.n_channels(), 4);
        assert_eq!(line.n_nodes(), 5);
        // A condition on a node off the network names the node.
        let e = half
            .select(
                &split,
                &Range::rect(0.0, 0.0, 0.1, 0.1),
                "pressure condition",
            )
            .unwrap_err()
            .to_string();
        assert!(e.contains("no node of the flow network"), "{e}");
    }
}
