//! The contact physics on the GPU (2D triangles and 3D tetrahedra): the broad phase as a
//! uniform grid built by counting sort, and the element-centric pair forces, in WGSL
//! kernels that repeat the CPU arithmetic in the same order (so f64 results match the
//! CPU to rounding).
//!
//! Every step runs, in order (the rebuild kernels return at once when no rebuild is
//! due; the rebuild flags alternate with the step's parity):
//!
//! 1. `moved` (per node): raise the rebuild flag when a node has moved more than half
//!    the skin since the last build (the CPU's criterion); lower the other step's flag;
//! 2. `boxes` (per element): inflated boxes (2 D reals: lows, then highs), the largest
//!    extent (integer atomicMax on the bits of an f32 rounded up); keep the old
//!    candidate lists and history;
//! 3. `count` (per element): bucket of each box centre on the grid of cell size = largest
//!    extent (cells (cx, cy, cz) hashed into a power-of-two table; cz = 0 in 2D),
//!    counted with integer atomics;
//! 4. `scan` (one invocation): prefix sum of the counts, counters cleared for the next
//!    build;
//! 5. `scatter` + `candidates` (per element): bucket items, then each element's sorted
//!    list of overlapping boxes that share no node with it, from the 3 × 3 (2D) or
//!    3 × 3 × 3 (3D) cells around it, with the pair history of partners that were already
//!    candidates: the sets of the CPU's [`crate::grid_candidates`] /
//!    [`crate::grid_candidates_3d`];
//! 6. `reference` (per node): positions of this build;
//! 7. `vertices` (per vertex of the bonded regions, only when bonds are declared): this
//!    step's intact and closed flags from the broken-bond field (the CPU's
//!    `BondedRegions::update`, see the `exclusion` module);
//! 8. `forces` (per element): Munjiza's potential force (`potential2d.wgsl`,
//!    `potential3d.wgsl`: [`crate::triangle_pair_force`], [`crate::tet_pair_force`]) and
//!    the contact law for every candidate (`contact_forces.wgsl`, `contact_forces_3d.wgsl`:
//!    the CPU's `apply_model` / `apply_model3`; in 3D a pair whose potential force is
//!    exactly zero skips the law and restarts its history, as on the CPU), the
//!    element's own share written to its slots; sealed elements and pairs that share an
//!    intact vertex are skipped (`regions.wgsl`).
//!
//! The broad-phase kernels are one source for both dimensions, specialised by the
//! constants `D` (dimension) and `NPE` (nodes per element). Integer atomics count and
//! raise flags; no float atomics. The order inside a bucket depends on scheduling, but
//! the lists are sorted, so the forces do not.
//!
//! The candidate lists, their counts and the pair histories are the contact physics'
//! fields (layout in the `physics` module docs, shared with the CPU path), so they are
//! uploaded with the host state at every run, read back at its end and saved by a
//! snapshot: a GPU run restored from a snapshot continues bit for bit, pair history
//! included. The lists hold element indices as reals (exact in f32 below 2^24 elements,
//! which the setup checks). Scratch buffers (boxes, buckets, the old lists and histories
//! a rebuild reads while it writes the new ones) are device-only and rewritten on every
//! rebuild step.
//!
//! Lists have a fixed capacity per element ([`crate::Contact::capacity`]; default
//! twice the largest initial list, at least 48): an element that finds more candidates
//! stops the run with an error naming it. The single-invocation `scan` loops over all
//! buckets; it runs on rebuild steps only.
//!
//! Resources: the forces kernel binds 12 storage buffers plus the step record (the
//! backend requests the adapter's own limits and reports a kernel that binds more than
//! the device allows); the 3D forces kernel keeps five clipping polygons of 12 vertices
//! in private memory (about 3.4 kB per invocation in f64), the `candidates` kernel a
//! sorted list of `CAP` indices.
//!
//! Limitations: the 3D pair force is heavy per invocation (face clipping with divergent
//! branches): on lavapipe (Vulkan on the CPU), with the 2 cores of this project's
//! machine shared, the 3D parity scene (96 tetrahedra) took 13 s for 456 steps.

use pcdc_compute::gpu::{splice_models, Access, GpuData, GpuSetup, Kernel, Phase, Precision};
use pcdc_compute::ComputeError;
use pcdc_mesh::Dim;

use crate::model::ContactModel;

const COMMON: &str = include_str!("shaders/broad_common.wgsl");
const CELLS: &str = include_str!("shaders/broad_cells.wgsl");
const REGIONS: &str = include_str!("shaders/regions.wgsl");

/// Bonded neighbours of one element: (neighbour, face), sorted by neighbour.
pub(crate) type BondList = Vec<(u32, u32)>;

/// What the contact physics hands to the GPU setup.
pub(crate) struct GpuContactInput<'a> {
    /// Skin distance (m).
    pub skin: f64,
    /// The law in force.
    pub model: &'a dyn ContactModel,
    /// Bonded neighbours per element (neighbour, face), sorted, and the broken-face
    /// field name.
    pub bonds: Option<(&'a [BondList], &'a str)>,
    /// Candidate capacity per element (the components of the candidate field).
    pub capacity: usize,
    /// History values per pair in the history field.
    pub stride: usize,
    /// The vertex topology of the bonded regions (with the bonds).
    pub regions: Option<&'a crate::exclusion::BondedRegions>,
}

/// Declares the contact kernels.
pub(crate) fn setup<D: Dim>(
    input: GpuContactInput<'_>,
    setup: &mut GpuSetup<'_, D>,
) -> Result<(), ComputeError> {
    let model = input.model;
    let wgsl = model.wgsl().ok_or_else(|| ComputeError::NoGpuKernel {
        physics: "contact".into(),
        reason: format!(
            "contact law '{}' has no WGSL body (implement ContactModel::wgsl; the built-in \
             contact-m-c needs an integer damping exponent b on the GPU)",
            model.name()
        ),
    })?;
    let mesh = setup.mesh;
    let ne = mesh.n_elements();
    let nn = mesh.n_nodes();
    if ne == 0 {
        return Ok(());
    }
    let (capacity, ns) = (input.capacity, input.stride);
    if setup.precision() == Precision::F32 && ne >= 1 << 24 {
        return Err(ComputeError::NoGpuKernel {
            physics: "contact".into(),
            reason: format!(
                "{ne} elements: f32 kernels hold candidate indices exactly only below 2^24 \
                 elements; use f64"
            ),
        });
    }
    let nbuckets = (2 * ne).next_power_of_two();
    let splice = splice_models(
        "contact_model",
        "s_try: Real, dslip: Real, h: Real, state: ptr<function, ContactState>, p: u32, c: u32, t: u32",
        "s_try, dslip, h, state, p, c, t",
        "ContactStress",
        None,
        [(wgsl.key.as_str(), wgsl.body.as_str())],
    );

    let conn = setup.upload("connectivity", GpuData::U32(mesh.elements().to_vec()));
    let flag = setup.atomics("rebuild flags", 2);
    let cell_bits = setup.atomics("largest box extent", 1);
    let boxes = setup.upload("boxes", GpuData::Real(vec![0.0; 2 * D::D * ne]));
    let grid = setup.upload("cell size", GpuData::Real(vec![0.0; 1]));
    let keys = setup.upload("bucket keys", GpuData::U32(vec![0; ne]));
    let count = setup.atomics("bucket counts", nbuckets);
    let fill = setup.atomics("bucket fill", nbuckets);
    let start = setup.upload("bucket starts", GpuData::U32(vec![0; nbuckets + 1]));
    let items = setup.upload("bucket items", GpuData::U32(vec![0; ne]));
    // The state: fields (uploaded and read back with the host state).
    let cand = setup.field(crate::CONTACT_CANDIDATES)?;
    let ncand = setup.field(crate::CONTACT_CANDIDATE_COUNT)?;
    let hist = setup.field(crate::CONTACT_HISTORY)?;
    let reference = setup.field(crate::CONTACT_REFERENCE)?;
    // Scratch of a rebuild: the old lists and histories.
    let cand_old = setup.upload("old candidates", GpuData::U32(vec![0; ne * capacity]));
    let ncand_old = setup.upload("old candidate counts", GpuData::U32(vec![0; ne]));
    let hist_old = setup.upload(
        "old pair history",
        GpuData::Real(vec![0.0; ne * capacity * ns]),
    );
    let model_data = setup.upload("law parameters", GpuData::Real(wgsl.params.clone()));
    // Bonds as CSR: per element its (neighbour, face) pairs sorted by neighbour.
    let (bond_ptr, bond_list, broken) = match input.bonds {
        Some((per, field)) => {
            let mut ptr = vec![0u32; ne + 1];
            let mut list = Vec::new();
            for (e, l) in per.iter().enumerate() {
                for &(f, face) in l {
                    list.push(f);
                    list.push(face);
                }
                ptr[e + 1] = (list.len() / 2) as u32;
            }
            list.resize(list.len().max(2), 0);
            (ptr, list, Some(setup.field(field)?))
        }
        None => (vec![0u32; ne + 1], vec![0u32; 2], None),
    };
    let bond_ptr = setup.upload("bond pointers", GpuData::U32(bond_ptr));
    let bond_list = setup.upload("bonds", GpuData::U32(bond_list));
    let broken = match broken {
        Some(b) => b,
        None => setup.upload("no bonds", GpuData::Real(vec![0.0])),
    };
    // The bonded regions: each element's vertices and this step's vertex flags (the
    // forces kernel binds them; one-entry placeholders without bonds, REGIONS = 0).
    let nv = input.regions.map_or(0, |r| r.n_vertices());
    let regions = nv > 0;
    let elem_vertex = setup.upload(
        "element vertices",
        GpuData::U32(input.regions.map_or(vec![0], |r| r.elem_vertex.clone())),
    );
    let vertex_flags = setup.upload("vertex flags", GpuData::U32(vec![0; nv.max(1)]));
    // The null model's flags (declared by the mechanics), or zeros without it.
    let element_null = match setup.field(pcdc_compute::names::ELEMENT_NULL) {
        Ok(b) => b,
        Err(_) => setup.upload("no null elements", GpuData::Real(vec![0.0; ne.max(1)])),
    };
    let overflow = setup.error(move |e| crate::physics::overflow_message(e, capacity));
    let tiny = match setup.precision() {
        Precision::F64 => f64::MIN_POSITIVE,
        Precision::F32 => 1e-30,
    };
    let half = 0.5 * input.skin;
    // The forces kernel: the law's pieces, the pair potential and the element loop of
    // the dimension.
    let (potential, forces) = if D::D == 3 {
        (
            include_str!("shaders/potential3d.wgsl"),
            include_str!("shaders/contact_forces_3d.wgsl"),
        )
    } else {
        (
            include_str!("shaders/potential2d.wgsl"),
            include_str!("shaders/contact_forces.wgsl"),
        )
    };
    let forces_source = format!(
        "alias ContactState = array<Real, NSTATE>;\nstruct ContactStress {{\n    normal: Real,\n    shear: Real,\n}}\nfn param(p: u32, k: u32) -> Real {{ return model_data[p + k]; }}\nfn pair_penalty(c: u32, t: u32, p: u32) -> Real {{\n{}\n}}\n{potential}{}{REGIONS}{forces}",
        wgsl.pair_penalty.as_deref().unwrap_or("return PENALTY;"),
        splice.source,
    );
    let common = |k: Kernel| {
        k.const_u32("D", D::D as u32)
            .const_u32("NPE", D::NODES_PER_ELEM as u32)
            .const_u32("NCELLS", if D::D == 3 { 27 } else { 9 })
            .const_u32("CAP", capacity as u32)
            .const_u32("NSTATE", ns as u32)
            .const_u32("NE", ne as u32)
            .const_u32("NBUCKETS", nbuckets as u32)
    };
    let broad = |label: &str, body: &str, n: usize| {
        common(Kernel::new(
            format!("contact {label}"),
            format!("{COMMON}{body}"),
            n,
        ))
        .bind("flag", flag, Access::ReadWrite)
    };
    // Kernels that locate box centres on the grid (they bind `boxes`).
    let cells = |label: &str, body: &str, n: usize| broad(label, &format!("{CELLS}{body}"), n);
    let mut kernels = vec![
        broad("moved", include_str!("shaders/broad_moved.wgsl"), nn)
            .const_real("LIMIT2", half * half)
            .bind("coords", setup.coords(), Access::Read)
            .bind("disp", setup.displacement(), Access::Read)
            .bind("reference", reference, Access::Read),
        broad("boxes", include_str!("shaders/broad_boxes.wgsl"), ne)
            .const_real("MARGIN", half)
            .bind("coords", setup.coords(), Access::Read)
            .bind("disp", setup.displacement(), Access::Read)
            .bind("conn", conn, Access::Read)
            .bind("boxes", boxes, Access::ReadWrite)
            .bind("cell_bits", cell_bits, Access::ReadWrite)
            .bind("cand", cand, Access::Read)
            .bind("ncand", ncand, Access::Read)
            .bind("hist", hist, Access::Read)
            .bind("cand_old", cand_old, Access::ReadWrite)
            .bind("ncand_old", ncand_old, Access::ReadWrite)
            .bind("hist_old", hist_old, Access::ReadWrite),
        cells("count", include_str!("shaders/broad_count.wgsl"), ne)
            .const_real("REAL_TINY", tiny)
            .bind("boxes", boxes, Access::Read)
            .bind("cell_bits", cell_bits, Access::ReadWrite)
            .bind("keys", keys, Access::ReadWrite)
            .bind("bucket_count", count, Access::ReadWrite),
        broad("scan", include_str!("shaders/broad_scan.wgsl"), 1)
            .const_real("REAL_TINY", tiny)
            .bind("cell_bits", cell_bits, Access::ReadWrite)
            .bind("grid", grid, Access::ReadWrite)
            .bind("bucket_count", count, Access::ReadWrite)
            .bind("bucket_fill", fill, Access::ReadWrite)
            .bind("bucket_start", start, Access::ReadWrite),
        broad("scatter", include_str!("shaders/broad_scatter.wgsl"), ne)
            .bind("keys", keys, Access::Read)
            .bind("bucket_fill", fill, Access::ReadWrite)
            .bind("bucket_start", start, Access::Read)
            .bind("bucket_items", items, Access::ReadWrite),
        cells(
            "candidates",
            include_str!("shaders/broad_candidates.wgsl"),
            ne,
        )
        .const_u32("OVERFLOW_CODE", overflow)
        .bind("conn", conn, Access::Read)
        .bind("boxes", boxes, Access::Read)
        .bind("grid", grid, Access::Read)
        .bind("bucket_start", start, Access::Read)
        .bind("bucket_items", items, Access::Read)
        .bind("cand", cand, Access::ReadWrite)
        .bind("ncand", ncand, Access::ReadWrite)
        .bind("hist", hist, Access::ReadWrite)
        .bind("cand_old", cand_old, Access::Read)
        .bind("ncand_old", ncand_old, Access::Read)
        .bind("hist_old", hist_old, Access::Read)
        .bind("status", setup.status(), Access::ReadWrite),
        broad(
            "reference",
            include_str!("shaders/broad_reference.wgsl"),
            nn,
        )
        .bind("coords", setup.coords(), Access::Read)
        .bind("disp", setup.displacement(), Access::Read)
        .bind("reference", reference, Access::ReadWrite),
        common(Kernel::new("contact forces", forces_source, ne))
            .const_u32("SLOT_FIRST", setup.slot_first())
            .const_u32("MODEL_KIND", splice.kinds[0])
            .const_u32("MODEL_AT", 0)
            .const_real("PENALTY", model.normal_penalty())
            .const_u32("REGIONS", regions as u32)
            .bind("coords", setup.coords(), Access::Read)
            .bind("disp", setup.displacement(), Access::Read)
            .bind("vel", setup.velocity(), Access::Read)
            .bind("conn", conn, Access::Read)
            .bind("cand", cand, Access::Read)
            .bind("ncand", ncand, Access::Read)
            .bind("hist", hist, Access::ReadWrite)
            .bind("bond_ptr", bond_ptr, Access::Read)
            .bind("bond_list", bond_list, Access::Read)
            .bind("broken", broken, Access::Read)
            .bind("model_data", model_data, Access::Read)
            .bind("elem_vertex", elem_vertex, Access::Read)
            .bind("vertex_flags", vertex_flags, Access::Read)
            .bind("element_null", element_null, Access::Read)
            .bind("slots", setup.slots(), Access::ReadWrite),
    ];
    if let Some(r) = input.regions.filter(|_| regions) {
        // The vertex flags, after the joints and before the forces.
        let mut faces = r.vertex_faces.clone();
        faces.resize(faces.len().max(1), 0);
        let vertices = common(Kernel::new(
            "contact vertices",
            include_str!("shaders/contact_vertices.wgsl"),
            nv,
        ))
        .bind(
            "vertex_ptr",
            setup.upload("vertex bond pointers", GpuData::U32(r.vertex_ptr.clone())),
            Access::Read,
        )
        .bind(
            "vertex_faces",
            setup.upload("vertex bond faces", GpuData::U32(faces)),
            Access::Read,
        )
        .bind(
            "vertex_static",
            setup.upload("vertex topology", GpuData::U32(r.vertex_static.clone())),
            Access::Read,
        )
        .bind("broken", broken, Access::Read)
        .bind("vertex_flags", vertex_flags, Access::ReadWrite);
        let at = kernels.len() - 1;
        kernels.insert(at, vertices);
    }
    for k in kernels {
        setup.kernel(Phase::Forces, k)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use crate::{Contact, ContactModel, ContactStress};
    use pcdc_compute::gpu::{offline_kernel_sources, validate_wgsl};
    use pcdc_compute::{ComputeError, Physics, Precision};
    use pcdc_mesh::{builders, split_nodes, Dim, Dim2, Dim3, Mesh, Range};

    fn two_blocks() -> Mesh<Dim2> {
        let a = builders::rectangle(0.0, 0.0, 0.1, 0.1, 0.02).unwrap();
        let b = builders::rectangle(0.102, 0.0, 0.1, 0.1, 0.02).unwrap();
        builders::union(&[&a, &b]).unwrap().0
    }

    fn two_cubes() -> Mesh<Dim3> {
        let a = builders::cuboid([0.0; 3], [0.05; 3], 0.025).unwrap();
        let b = builders::cuboid([0.051, 0.01, 0.005], [0.05; 3], 0.025).unwrap();
        builders::union(&[&a, &b]).unwrap().0
    }

    fn sources(contact: Contact, p: Precision) -> Result<Vec<(String, String)>, ComputeError> {
        let physics: Vec<Box<dyn Physics<Dim2>>> = vec![Box::new(contact)];
        offline_kernel_sources(&two_blocks(), physics, p)
    }

    /// Validates every contact kernel of `contact` on `mesh` with naga; checks that the
    /// forces kernel is the one of the mesh's dimension.
    fn validate_all<D: Dim>(mesh: &Mesh<D>, contact: Contact, p: Precision) {
        validate_n(mesh, vec![Box::new(contact)], p, 8);
    }

    /// Validates the contact kernels among `physics`, expecting `n` of them.
    fn validate_n<D: Dim>(
        mesh: &Mesh<D>,
        physics: Vec<Box<dyn Physics<D>>>,
        p: Precision,
        n: usize,
    ) {
        let all = offline_kernel_sources(mesh, physics, p).unwrap();
        let ours: Vec<_> = all
            .iter()
            .filter(|(l, _)| l.starts_with("contact"))
            .collect();
        assert_eq!(
            ours.len(),
            n,
            "{:?}",
            all.iter().map(|k| &k.0).collect::<Vec<_>>()
        );
        let pair_force = if D::D == 3 {
            "fn tet_pair_force("
        } else {
            "fn triangle_pair_force("
        };
        for (label, src) in ours {
            assert!(
                src.contains(&format!("const D: u32 = {}u;", D::D)),
                "{label}"
            );
            if label == "contact forces" {
                assert!(src.contains(pair_force), "{label} of {}D", D::D);
            }
            if let Err(e) = validate_wgsl(src) {
                panic!("{label} ({p:?}, {}D) does not validate:\n{e}", D::D);
            }
        }
    }

    /// Every contact kernel, 2D and 3D, with the built-in law (friction and damping, and
    /// friction alone) and with surface contact, validates with naga, f64 and f32.
    #[test]
    fn contact_kernels_validate() {
        let (m2, m3) = (two_blocks(), two_cubes());
        for p in [Precision::F64, Precision::F32] {
            let law = || Contact::new(1e10).friction(30.0, 1e11).damping(1e6, 2.0);
            validate_all(&m2, law(), p);
            validate_all(&m3, law(), p);
            // Friction without damping: one history value per pair.
            let friction = || Contact::new(1e10).friction(30.0, 1e11);
            validate_all(&m2, friction(), p);
            validate_all(&m3, friction(), p);
            let ne = m3.n_elements();
            let surface = Contact::new(1e10).surface_defaults(vec![25.0; ne], vec![1e10; ne]);
            validate_all(&m3, surface, p);
        }
    }

    /// Faces whose broken flag is read by the bonded-region kernels (the test owner).
    #[derive(Debug)]
    struct BrokenFlags;
    impl<D: Dim> Physics<D> for BrokenFlags {
        fn name(&self) -> &str {
            "broken flags"
        }
        fn fields(&self, _: &Mesh<D>) -> Vec<pcdc_compute::FieldUse> {
            vec![pcdc_compute::FieldUse {
                place: Some(pcdc_compute::Place::Face),
                components: Some(1),
                ..pcdc_compute::FieldUse::named("broken", pcdc_compute::FieldAccess::Own)
            }]
        }
        fn init(&mut self, _: &mut pcdc_compute::InitContext<'_, D>) -> Result<(), ComputeError> {
            Ok(())
        }
        fn compute_forces(
            &mut self,
            _: &mut pcdc_compute::ForceContext<'_, D>,
        ) -> Result<(), ComputeError> {
            Ok(())
        }
        fn gpu_setup(
            &mut self,
            _: &mut pcdc_compute::gpu::GpuSetup<'_, D>,
        ) -> Result<(), ComputeError> {
            Ok(())
        }
    }

    /// With bonded interfaces the vertex-flag kernel joins (9 kernels), 2D and 3D, f64
    /// and f32, and every kernel validates.
    #[test]
    fn bonded_region_kernels_validate() {
        let m2 = split_nodes(&two_blocks(), &Range::All).unwrap();
        let m3 = split_nodes(&two_cubes(), &Range::All).unwrap();
        for p in [Precision::F64, Precision::F32] {
            let c = || {
                Contact::new(1e10)
                    .friction(30.0, 1e11)
                    .bonded_interfaces("broken")
            };
            validate_n(&m2, vec![Box::new(BrokenFlags), Box::new(c())], p, 9);
            validate_n(&m3, vec![Box::new(BrokenFlags), Box::new(c())], p, 9);
        }
    }

    /// A zero candidate capacity is a parameter error, not an invalid shader.
    #[test]
    fn zero_capacity_is_named() {
        let e = sources(Contact::new(1e10).capacity(0), Precision::F64)
            .map(|_| ())
            .unwrap_err()
            .to_string();
        assert!(e.contains("Contact::capacity"), "{e}");
    }

    #[derive(Debug)]
    struct CpuOnly;
    impl ContactModel for CpuOnly {
        fn name(&self) -> &str {
            "cpu-only-contact"
        }
        fn normal_penalty(&self) -> f64 {
            1e10
        }
        fn update(&self, s_try: f64, _: f64, _: f64, _: &mut [f64]) -> ContactStress {
            ContactStress {
                normal: s_try,
                shear: 0.0,
            }
        }
    }

    /// A law without WGSL, or a damping exponent the GPU law cannot raise to, is a
    /// build-time error naming the law, never a silent fallback.
    #[test]
    fn laws_without_gpu_code_are_named() {
        for (contact, what) in [
            (Contact::new(1e10).with_model(CpuOnly), "cpu-only-contact"),
            (
                Contact::new(1e10).damping(1e6, 2.5),
                "integer damping exponent",
            ),
        ] {
            match sources(contact, Precision::F64) {
                Err(e @ ComputeError::NoGpuKernel { .. }) => {
                    assert!(e.to_string().contains(what), "{e}")
                }
                other => panic!("expected NoGpuKernel, got {:?}", other.map(|_| ())),
            }
        }
    }
}
