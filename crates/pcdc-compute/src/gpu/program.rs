//! What physics declare for the GPU: buffers, kernels and per-step signals; and the
//! shader template every kernel is assembled into.

use pcdc_mesh::{Dim, Mesh};

use super::Precision;
use crate::{ComputeError, FieldStore};

/// Data uploaded once when the simulation is built.
#[derive(Clone, Debug, PartialEq)]
pub enum GpuData {
    /// Reals (stored as f64 or f32 by precision); WGSL type `array<Real>`.
    Real(Vec<f64>),
    /// Unsigned integers; WGSL type `array<u32>`.
    U32(Vec<u32>),
}

impl GpuData {
    pub(crate) fn len(&self) -> usize {
        match self {
            GpuData::Real(v) => v.len(),
            GpuData::U32(v) => v.len(),
        }
    }
}

/// Handle to a device buffer of a simulation (a field, a built-in array or uploaded data).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GpuBuffer(pub(crate) usize);

/// How a kernel binds a buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Access {
    /// `var<storage, read>`.
    Read,
    /// `var<storage, read_write>`.
    ReadWrite,
}

/// When a kernel runs within a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// Force phase: writes the physics' force slots (every slot, every step) and its fields.
    Forces,
    /// After the velocity update, before the position update: prescribed velocities and
    /// constraints overwrite `v`.
    Kinematics,
    /// After the position update, once per step ([`crate::Physics::post_update`]).
    PostUpdate,
    /// The physics' sub-cycled field stage ([`crate::Physics::field_step`]): its kernels
    /// run as a group, repeated [`crate::SubCycle::substeps`] times after every step (or
    /// once after every n-th step), each in order with a barrier between dispatches. The
    /// backend adds `const FIELD_DT_SCALE: Real` to these kernels: the field step is
    /// `p_dt() * FIELD_DT_SCALE`, exactly as on the CPU.
    Field,
}

/// A constant spliced into a kernel's source.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ConstValue {
    /// `const NAME: u32 = value;`
    U32(u32),
    /// `const NAME: Real = value;` (written with 17 significant digits).
    Real(f64),
}

/// A compute kernel: one invocation per entity `i < count`. `source` defines
/// `fn kernel(i: u32)`, and may define helpers; the backend prepends the prelude
/// ([`PRELUDE`]), the constants and one storage binding per entry of `bindings`.
#[derive(Clone, Debug)]
pub struct Kernel {
    /// Label (pipeline name in errors and traces).
    pub label: String,
    /// WGSL defining `fn kernel(i: u32)`.
    pub source: String,
    /// Number of invocations.
    pub count: u32,
    /// Bindings: WGSL name, buffer, access.
    pub bindings: Vec<(String, GpuBuffer, Access)>,
    /// Constants: WGSL name and value.
    pub constants: Vec<(String, ConstValue)>,
}

impl Kernel {
    /// A kernel with no bindings yet.
    pub fn new(label: impl Into<String>, source: impl Into<String>, count: usize) -> Self {
        Kernel {
            label: label.into(),
            source: source.into(),
            count: count as u32,
            bindings: Vec::new(),
            constants: Vec::new(),
        }
    }

    /// Binds `buffer` as `name`.
    pub fn bind(mut self, name: &str, buffer: GpuBuffer, access: Access) -> Self {
        self.bindings.push((name.to_string(), buffer, access));
        self
    }

    /// Adds a `u32` constant.
    pub fn const_u32(mut self, name: &str, v: u32) -> Self {
        self.constants.push((name.to_string(), ConstValue::U32(v)));
        self
    }

    /// Adds a `Real` constant.
    pub fn const_real(mut self, name: &str, v: f64) -> Self {
        self.constants.push((name.to_string(), ConstValue::Real(v)));
        self
    }
}

/// Element type of a device buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Elem {
    Real,
    U32,
    Atomic,
}

/// A buffer the simulation will create.
#[derive(Clone, Debug)]
pub(crate) struct BufferDecl {
    pub label: String,
    pub elem: Elem,
    pub len: usize,
    pub data: Option<GpuData>,
}

/// A per-step scalar evaluated on the host (e.g. a table value) and shipped with the
/// step parameters; arguments: time at the start of the step (s) and the step (s).
pub(crate) type Signal = Box<dyn Fn(f64, f64) -> f64 + Send + Sync>;

/// A physics error a kernel can raise (see [`GpuSetup::error`]): the physics' name and
/// the message for the reported entity.
pub(crate) type ErrorMessage = (String, Box<dyn Fn(u32) -> String + Send + Sync>);

/// Built-in buffers, in this order, before the fields and the uploaded data.
pub(crate) mod builtin {
    pub const COORDS: usize = 0;
    pub const DISPLACEMENT: usize = 1;
    pub const VELOCITY: usize = 2;
    pub const MASS: usize = 3;
    pub const MASS_PHYS: usize = 4;
    pub const FORCE: usize = 5;
    pub const SLOTS: usize = 6;
    pub const GATHER_PTR: usize = 7;
    pub const GATHER_IDX: usize = 8;
    pub const STATUS: usize = 9;
    pub const GROSS: usize = 10;
    pub const COUNT: usize = 11;
}

/// The GPU program of a simulation: buffers, kernels by phase and physics, signals.
pub(crate) struct Program {
    pub buffers: Vec<BufferDecl>,
    /// Buffer index of each field (FieldStore order).
    pub field_buffers: Vec<usize>,
    pub kernels: Vec<(Phase, Kernel)>,
    /// Index of the physics that declared each kernel.
    pub kernel_owner: Vec<usize>,
    pub signals: Vec<Signal>,
    /// Physics errors by code (index).
    pub errors: Vec<ErrorMessage>,
}

/// Handed to [`crate::Physics::gpu_setup`]: declare data, kernels and signals.
pub struct GpuSetup<'a, D: Dim> {
    /// The mesh.
    pub mesh: &'a Mesh<D>,
    /// The fields with their initial values.
    pub fields: &'a FieldStore,
    pub(crate) precision: Precision,
    pub(crate) slot_first: usize,
    pub(crate) slot_len: usize,
    pub(crate) program: &'a mut Program,
    pub(crate) physics: String,
    pub(crate) physics_index: usize,
}

impl<D: Dim> GpuSetup<'_, D> {
    /// Kernel precision.
    pub fn precision(&self) -> Precision {
        self.precision
    }

    /// Uploads constant data (connectivity, geometry, parameters).
    pub fn upload(&mut self, label: &str, data: GpuData) -> GpuBuffer {
        let elem = match data {
            GpuData::Real(_) => Elem::Real,
            GpuData::U32(_) => Elem::U32,
        };
        self.program.buffers.push(BufferDecl {
            label: format!("{}: {label}", self.physics),
            elem,
            len: data.len(),
            data: Some(data),
        });
        GpuBuffer(self.program.buffers.len() - 1)
    }

    /// The device buffer of a declared field (`array<Real>`, same layout as on the host).
    pub fn field(&self, name: impl AsRef<str>) -> Result<GpuBuffer, ComputeError> {
        let id = self.fields.id(name)?;
        Ok(GpuBuffer(self.program.field_buffers[id.index()]))
    }

    /// Reference node coordinates (m), `array<Real>`, stride D.
    pub fn coords(&self) -> GpuBuffer {
        GpuBuffer(builtin::COORDS)
    }

    /// Node displacement (m), `array<Real>`, stride D.
    pub fn displacement(&self) -> GpuBuffer {
        GpuBuffer(builtin::DISPLACEMENT)
    }

    /// Node velocity (m/s), `array<Real>`, stride D.
    pub fn velocity(&self) -> GpuBuffer {
        GpuBuffer(builtin::VELOCITY)
    }

    /// Physical lumped node mass (kg), `array<Real>`.
    pub fn mass(&self) -> GpuBuffer {
        GpuBuffer(builtin::MASS_PHYS)
    }

    /// All force slots (N), `array<Real>`, stride D; this physics owns slots
    /// `slot_first()..slot_first() + slot_count()` and must write each of them every step.
    pub fn slots(&self) -> GpuBuffer {
        GpuBuffer(builtin::SLOTS)
    }

    /// First slot of this physics.
    pub fn slot_first(&self) -> u32 {
        self.slot_first as u32
    }

    /// Number of slots of this physics.
    pub fn slot_count(&self) -> usize {
        self.slot_len
    }

    /// A zero-initialised scratch buffer of `len` integer atomics (`array<atomic<u32>>`),
    /// for counting and flags (integer atomics only: never accumulate forces with them).
    pub fn atomics(&mut self, label: &str, len: usize) -> GpuBuffer {
        self.program.buffers.push(BufferDecl {
            label: format!("{}: {label}", self.physics),
            elem: Elem::Atomic,
            len,
            data: None,
        });
        GpuBuffer(self.program.buffers.len() - 1)
    }

    /// The run's status words (`array<atomic<u32>>`, 4 entries; bind it as `status`,
    /// read-write). Entries 0-1 belong to the divergence watchdog; a kernel raises a
    /// physics error from [`GpuSetup::error`] with
    /// `atomicMin(&status[2], CODE); atomicMin(&status[3], entity);`.
    pub fn status(&self) -> GpuBuffer {
        GpuBuffer(builtin::STATUS)
    }

    /// Registers an error a kernel of this physics can raise and returns its code: after
    /// the run (one read-back, as usual) the simulation returns
    /// `ComputeError::Physics { physics, message: message(entity) }` for the smallest
    /// raised code, with the smallest raised entity.
    pub fn error(&mut self, message: impl Fn(u32) -> String + Send + Sync + 'static) -> u32 {
        self.program
            .errors
            .push((self.physics.clone(), Box::new(message)));
        (self.program.errors.len() - 1) as u32
    }

    /// A per-step scalar: `f(t, dt)` is evaluated on the host for every step (t = time at
    /// the start of the step) and read in WGSL as `signal(index)`. Use it for time tables.
    pub fn signal(&mut self, f: impl Fn(f64, f64) -> f64 + Send + Sync + 'static) -> u32 {
        self.program.signals.push(Box::new(f));
        (self.program.signals.len() - 1) as u32
    }

    /// Adds a kernel to a phase; kernels run in the order they are added, physics in
    /// the order they were composed.
    pub fn kernel(&mut self, phase: Phase, kernel: Kernel) -> Result<(), ComputeError> {
        for (name, b, _) in &kernel.bindings {
            if b.0 >= self.program.buffers.len() {
                return Err(ComputeError::Gpu(format!(
                    "kernel '{}' binds '{name}' to an unknown buffer",
                    kernel.label
                )));
            }
        }
        self.program.kernels.push((phase, kernel));
        self.program.kernel_owner.push(self.physics_index);
        Ok(())
    }
}

/// The prelude of every module (after `alias Real = ...;`): the per-step parameters and
/// the entry point that calls `kernel(i)` for `i < COUNT`.
///
/// Per-step record (`params`, bound with a dynamic offset): `p_time()` time at the start
/// of the step (s), `p_dt()` step (s), `p_damping()` element viscous damping on,
/// `p_alpha()` local damping coefficient, `p_gravity(k)` (m/s²), `p_step()` global step
/// number, `signal(i)` host-evaluated scalars.
pub const PRELUDE: &str = r#"
@group(0) @binding(0) var<storage, read> params: array<Real>;
fn p_time() -> Real { return params[0]; }
fn p_dt() -> Real { return params[1]; }
fn p_damping() -> bool { return params[2] != 0.0; }
fn p_alpha() -> Real { return params[3]; }
fn p_gravity(k: u32) -> Real { return params[4u + k]; }
fn p_step() -> u32 { return u32(params[7]) * 4096u + u32(params[8]); }
fn signal(i: u32) -> Real { return params[PARAM_HEADER + i]; }

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * 64u;
    if i < COUNT {
        kernel(i);
    }
}
"#;

/// Reals in the fixed head of a step record.
pub(crate) const PARAM_HEADER: usize = 9;

fn real_literal(v: f64, p: Precision) -> String {
    let v = if p == Precision::F32 {
        v as f32 as f64
    } else {
        v
    };
    if v.is_finite() {
        let s = format!("{v:.17e}");
        format!("Real({s})")
    } else if v > 0.0 {
        "REAL_MAX".into()
    } else {
        "(-REAL_MAX)".into()
    }
}

/// The full WGSL module of a kernel: precision alias, constants, bindings, prelude and
/// the kernel's source. `elems` gives the element type of each bound buffer.
pub(crate) fn assemble(
    kernel: &Kernel,
    precision: Precision,
    elems: &dyn Fn(GpuBuffer) -> Elem,
) -> String {
    let mut s = String::new();
    s.push_str(&format!("alias Real = {};\n", precision.name()));
    let eps = match precision {
        Precision::F64 => "2.220446049250313e-16",
        Precision::F32 => "1.1920929e-7",
    };
    s.push_str(&format!("const REAL_EPS: Real = Real({eps});\n"));
    // Largest finite magnitude we test against (NaN fails every comparison).
    let max = match precision {
        Precision::F64 => "1.0e300",
        Precision::F32 => "3.0e38",
    };
    s.push_str(&format!("const REAL_MAX: Real = Real({max});\n"));
    s.push_str(&format!("const COUNT: u32 = {}u;\n", kernel.count));
    s.push_str(&format!("const PARAM_HEADER: u32 = {PARAM_HEADER}u;\n"));
    for (name, v) in &kernel.constants {
        match v {
            ConstValue::U32(x) => s.push_str(&format!("const {name}: u32 = {x}u;\n")),
            ConstValue::Real(x) => s.push_str(&format!(
                "const {name}: Real = {};\n",
                real_literal(*x, precision)
            )),
        }
    }
    for (i, (name, b, access)) in kernel.bindings.iter().enumerate() {
        let acc = match access {
            Access::Read => "read",
            Access::ReadWrite => "read_write",
        };
        let ty = match elems(*b) {
            Elem::Real => "array<Real>",
            Elem::U32 => "array<u32>",
            Elem::Atomic => "array<atomic<u32>>",
        };
        s.push_str(&format!(
            "@group(1) @binding({i}) var<storage, {acc}> {name}: {ty};\n"
        ));
    }
    s.push_str(PRELUDE);
    s.push_str(&kernel.source);
    s
}

/// Assembles a kernel as the backend would, for a buffer-type lookup given by the caller
/// (tests of physics crates use [`offline_kernel_sources`] instead).
pub fn assemble_source(
    kernel: &Kernel,
    precision: Precision,
    real_buffers: &[GpuBuffer],
) -> String {
    assemble(kernel, precision, &|b| {
        if real_buffers.contains(&b) {
            Elem::Real
        } else {
            Elem::U32
        }
    })
}

/// Plugin WGSL spliced into a kernel template: see [`splice_models`].
#[derive(Clone, Debug, PartialEq)]
pub struct ModelSplice {
    /// One function `{prefix}_{k}` per distinct model key, then the dispatcher
    /// `fn call_{prefix}(kind: u32, <params>) -> <ret>`.
    pub source: String,
    /// Kind (index into the distinct keys) of every model, in input order.
    pub kinds: Vec<u32>,
}

/// Splices plugin models (constitutive, joint, contact) into a kernel template: models
/// given as `(key, body)` that share a key share one WGSL function
/// `fn {prefix}_{k}({params}) -> {ret} {{ body }}`, and a dispatcher
/// `fn call_{prefix}(kind: u32, {params}) -> {ret}` switches on the kind; an unknown
/// kind returns `fallback` (a WGSL expression, or the zero value when `None`). `args` is
/// `params` without the types (the names passed on).
pub fn splice_models<'a>(
    prefix: &str,
    params: &str,
    args: &str,
    ret: &str,
    fallback: Option<&str>,
    models: impl IntoIterator<Item = (&'a str, &'a str)>,
) -> ModelSplice {
    let mut keys: Vec<&str> = Vec::new();
    let mut source = String::new();
    let mut kinds = Vec::new();
    for (key, body) in models {
        let kind = match keys.iter().position(|k| *k == key) {
            Some(k) => k,
            None => {
                keys.push(key);
                source.push_str(&format!(
                    "// model '{key}'\nfn {prefix}_{}({params}) -> {ret} {{\n{body}\n}}\n",
                    keys.len() - 1
                ));
                keys.len() - 1
            }
        };
        kinds.push(kind as u32);
    }
    let init = match fallback {
        Some(e) => format!("var out: {ret} = {e};"),
        None => format!("var out: {ret};"),
    };
    source.push_str(&format!(
        "fn call_{prefix}(kind: u32, {params}) -> {ret} {{\n    {init}\n    switch kind {{\n"
    ));
    for k in 0..keys.len() {
        source.push_str(&format!(
            "        case {k}u: {{ out = {prefix}_{k}({args}); }}\n"
        ));
    }
    source.push_str("        default: {}\n    }\n    return out;\n}\n");
    ModelSplice { source, kinds }
}

/// Parses and validates a WGSL module with naga (with f64 support), as wgpu would;
/// returns the diagnostic with source context on failure.
#[cfg(feature = "gpu")]
pub fn validate_wgsl(source: &str) -> Result<(), String> {
    let module = naga::front::wgsl::parse_str(source).map_err(|e| e.emit_to_string(source))?;
    let mut v = naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::FLOAT64,
    );
    v.validate(&module)
        .map(|_| ())
        .map_err(|e| e.emit_to_string(source))
}

impl Program {
    pub(crate) fn elem_of(&self, b: GpuBuffer) -> Elem {
        self.buffers[b.0].elem
    }
}

/// Builds the GPU program of `physics` on `mesh` without a device and returns every
/// assembled kernel as `(label, WGSL)`, built-in kernels included: what a unit test
/// feeds to [`validate_wgsl`]. Errors are those the simulation build would report.
#[cfg(feature = "gpu")]
pub fn offline_kernel_sources<D: Dim>(
    mesh: &Mesh<D>,
    physics: Vec<Box<dyn crate::Physics<D>>>,
    precision: Precision,
) -> Result<Vec<(String, String)>, ComputeError> {
    let mut physics = physics;
    let layout = crate::simulation::prepare_layout(mesh, &mut physics)?;
    let program =
        crate::gpu::run::build_program(mesh, &mut physics, &layout.fields, &layout, precision)?;
    let mut out = Vec::new();
    for (phase, k) in &program.kernels {
        // Field kernels get their sub-cycling scale from the schedule, as in a run.
        let k = if *phase == Phase::Field {
            k.clone().const_real("FIELD_DT_SCALE", 1.0)
        } else {
            k.clone()
        };
        out.push((
            k.label.clone(),
            assemble(&k, precision, &|b| program.elem_of(b)),
        ));
    }
    for k in crate::gpu::run::builtin_kernels::<D>(layout.coords.len() / D::D) {
        let k = k.const_real("RUNAWAY2", 1.0);
        out.push((
            k.label.clone(),
            assemble(&k, precision, &|b| program.elem_of(b)),
        ));
    }
    Ok(out)
}

#[cfg(all(test, feature = "gpu"))]
mod tests {
    use super::*;
    use pcdc_mesh::builders;

    #[test]
    fn builtin_kernels_validate_with_naga() {
        let m2 = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
        let m3 = builders::cuboid([0.0; 3], [1.0; 3], 0.5).unwrap();
        for p in [Precision::F64, Precision::F32] {
            let s2 = offline_kernel_sources(&m2, Vec::new(), p).unwrap();
            let s3 = offline_kernel_sources(&m3, Vec::new(), p).unwrap();
            assert_eq!(s2.len(), 3);
            for (label, src) in s2.iter().chain(&s3) {
                assert!(src.starts_with(&format!("alias Real = {};", p.name())));
                if let Err(e) = validate_wgsl(src) {
                    panic!("{label} ({}) does not validate:\n{e}", p.name());
                }
            }
        }
    }

    #[test]
    fn invalid_wgsl_is_reported_with_context() {
        let err = validate_wgsl("fn kernel(i: u32) { let x: Real = 1.0; }").unwrap_err();
        assert!(err.contains("Real"), "{err}");
    }

    #[test]
    fn real_constants_keep_full_precision() {
        let k = Kernel::new("k", "fn kernel(i: u32) {}", 1).const_real("X", 0.1);
        let src = assemble_source(&k, Precision::F64, &[]);
        let line = src.lines().find(|l| l.starts_with("const X")).unwrap();
        let v: f64 = line
            .trim_start_matches("const X: Real = Real(")
            .trim_end_matches(");")
            .parse()
            .unwrap();
        assert_eq!(v, 0.1);
    }
}
