//! Device buffers, pipelines and batched stepping of one simulation on the GPU.

use pcdc_mesh::{Dim, Mesh};

use super::program::{assemble, builtin, validate_wgsl, BufferDecl, Elem, Program, PARAM_HEADER};
use super::{Access, GpuBuffer, GpuData, GpuSetup, Kernel, Phase, Precision, WgpuBackend};
use crate::{ComputeError, FieldStore, Physics, Simulation};

/// Steps recorded per submission (one parameter record each).
const BATCH: usize = 128;

const GATHER_INTEGRATE: &str = include_str!("shaders/gather_integrate.wgsl");
const GATHER_FORCES: &str = include_str!("shaders/gather_forces.wgsl");
const UPDATE_WATCHDOG: &str = include_str!("shaders/update_watchdog.wgsl");

/// The built-in kernels: gather + velocity update, gather for force evaluation, position
/// update + watchdog.
pub(crate) fn builtin_kernels<D: Dim>(n_nodes: usize) -> Vec<Kernel> {
    let d = D::D as u32;
    let b = |i: usize| GpuBuffer(i);
    let gather = |k: Kernel| {
        k.const_u32("D", d)
            .bind("slots", b(builtin::SLOTS), Access::Read)
            .bind("gather_ptr", b(builtin::GATHER_PTR), Access::Read)
            .bind("gather_idx", b(builtin::GATHER_IDX), Access::Read)
            .bind("force", b(builtin::FORCE), Access::ReadWrite)
    };
    vec![
        gather(Kernel::new("gather_integrate", GATHER_INTEGRATE, n_nodes))
            .bind("mass", b(builtin::MASS), Access::Read)
            .bind("mass_phys", b(builtin::MASS_PHYS), Access::Read)
            .bind("vel", b(builtin::VELOCITY), Access::ReadWrite),
        gather(Kernel::new("gather_forces", GATHER_FORCES, n_nodes)).bind(
            "gross",
            b(builtin::GROSS),
            Access::ReadWrite,
        ),
        Kernel::new("update_watchdog", UPDATE_WATCHDOG, n_nodes)
            .const_u32("D", d)
            .bind("disp", b(builtin::DISPLACEMENT), Access::ReadWrite)
            .bind("vel", b(builtin::VELOCITY), Access::Read)
            .bind("status", b(builtin::STATUS), Access::ReadWrite),
    ]
}

fn decl(label: &str, elem: Elem, len: usize, data: Option<GpuData>) -> BufferDecl {
    BufferDecl {
        label: label.to_string(),
        elem,
        len,
        data,
    }
}

/// Declares the built-in and field buffers and lets every physics add its kernels.
pub(crate) fn build_program<D: Dim>(
    mesh: &Mesh<D>,
    physics: &mut [Box<dyn Physics<D>>],
    fields: &FieldStore,
    layout: &crate::simulation::Layout,
    precision: Precision,
) -> Result<Program, ComputeError> {
    // Every node: the mesh's, then those physics added.
    let nd = layout.coords.len();
    let n_nodes = nd / D::D;
    let mut buffers = vec![
        decl(
            "coords",
            Elem::Real,
            nd,
            Some(GpuData::Real(layout.coords.clone())),
        ),
        decl("displacement", Elem::Real, nd, None),
        decl("velocity", Elem::Real, nd, None),
        decl("mass", Elem::Real, n_nodes, None),
        decl("mass_phys", Elem::Real, n_nodes, None),
        decl("force", Elem::Real, nd, None),
        decl("slots", Elem::Real, layout.n_slots * D::D, None),
        decl(
            "gather_ptr",
            Elem::U32,
            layout.gather_ptr.len(),
            Some(GpuData::U32(layout.gather_ptr.clone())),
        ),
        decl(
            "gather_idx",
            Elem::U32,
            layout.gather_idx.len(),
            Some(GpuData::U32(layout.gather_idx.clone())),
        ),
        decl("status", Elem::Atomic, 4, None),
        decl("gross", Elem::Real, nd, None),
    ];
    debug_assert_eq!(buffers.len(), builtin::COUNT);
    let mut field_buffers = Vec::new();
    for spec in fields.specs() {
        let id = fields.id(&spec.name)?;
        buffers.push(decl(
            &format!("field {}", spec.name),
            Elem::Real,
            fields.get(id).len(),
            None,
        ));
        field_buffers.push(buffers.len() - 1);
    }
    let mut program = Program {
        buffers,
        field_buffers,
        kernels: Vec::new(),
        kernel_owner: Vec::new(),
        signals: Vec::new(),
        errors: Vec::new(),
    };
    for (index, (p, r)) in physics.iter_mut().zip(&layout.slot_ranges).enumerate() {
        let name = p.name().to_string();
        let mut setup = GpuSetup {
            mesh,
            fields,
            precision,
            slot_first: r.start,
            slot_len: r.len(),
            program: &mut program,
            physics: name.clone(),
            physics_index: index,
        };
        p.gpu_setup(&mut setup)?;
    }
    Ok(program)
}

struct Pipeline {
    label: String,
    /// Bytes streamed per dispatch if every bound buffer is read once (written once more
    /// when read-write).
    bytes: u64,
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    count: u32,
}

/// A simulation's device state: buffers, pipelines and the per-step parameter records.
pub(crate) struct GpuRun {
    backend: WgpuBackend,
    precision: Precision,
    buffers: Vec<wgpu::Buffer>,
    field_buffers: Vec<usize>,
    signals: Vec<super::program::Signal>,
    errors: Vec<super::program::ErrorMessage>,
    forces: Vec<Pipeline>,
    kinematics: Vec<Pipeline>,
    post_update: Vec<Pipeline>,
    /// Field stages: each physics' kernel group with its sub-cycling.
    field: Vec<(crate::SubCycle, Vec<Pipeline>)>,
    gather_integrate: Pipeline,
    gather_forces: Pipeline,
    update: Pipeline,
    params: wgpu::Buffer,
    params_group: wgpu::BindGroup,
    record_reals: usize,
    record_bytes: u64,
    staging: wgpu::Buffer,
    max_groups: u32,
    /// Energy-balance kernels and buffers, when tracking is on.
    energy: Option<GpuEnergy>,
}

/// The energy-balance kernels of a run (see `gpu/energy.rs`).
struct GpuEnergy {
    save: Pipeline,
    work: Pipeline,
    buffers: super::energy::EnergyBuffers,
    staging: wgpu::Buffer,
}

fn real_bytes(v: &[f64], p: Precision) -> Vec<u8> {
    match p {
        Precision::F64 => bytemuck::cast_slice(v).to_vec(),
        Precision::F32 => {
            let f: Vec<f32> = v.iter().map(|&x| x as f32).collect();
            bytemuck::cast_slice(&f).to_vec()
        }
    }
}

fn reals_from(bytes: &[u8], p: Precision, out: &mut [f64]) {
    match p {
        Precision::F64 => {
            for (o, c) in out.iter_mut().zip(bytes.chunks_exact(8)) {
                *o = f64::from_le_bytes(c.try_into().expect("8 bytes"));
            }
        }
        Precision::F32 => {
            for (o, c) in out.iter_mut().zip(bytes.chunks_exact(4)) {
                *o = f32::from_le_bytes(c.try_into().expect("4 bytes")) as f64;
            }
        }
    }
}

impl GpuRun {
    /// Creates buffers and pipelines for a freshly built simulation.
    pub(crate) fn new<D: Dim>(
        backend: &WgpuBackend,
        sim: &mut Simulation<D>,
        layout: &crate::simulation::Layout,
    ) -> Result<Self, ComputeError> {
        let precision = backend.precision();
        let program = build_program(
            &sim.mesh,
            &mut sim.physics,
            &sim.state.fields,
            layout,
            precision,
        )?;
        let device = backend.device();
        let limits = backend.limits().clone();
        let Program {
            buffers: mut decls,
            field_buffers,
            kernels,
            kernel_owner,
            signals,
            errors,
        } = program;
        // Energy balance buffers, only when tracking is on.
        let energy_buffers = sim.energy.is_some().then(|| {
            super::energy::declare(&mut decls, sim.n_nodes(), D::D, layout.slot_ranges.len())
        });
        let eb = |e: Elem| match e {
            Elem::Real => precision.bytes(),
            Elem::U32 | Elem::Atomic => 4,
        };
        let mut buffers = Vec::with_capacity(decls.len());
        for dcl in &decls {
            let size = ((dcl.len * eb(dcl.elem)).max(16) as u64).next_multiple_of(16);
            if size > limits.max_storage_buffer_binding_size || size > limits.max_buffer_size {
                return Err(ComputeError::Gpu(format!(
                    "buffer '{}' needs {size} bytes, above the device's storage-buffer limit ({} bytes)",
                    dcl.label, limits.max_storage_buffer_binding_size
                )));
            }
            let buf = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(&dcl.label),
                size,
                usage: wgpu::BufferUsages::STORAGE
                    | wgpu::BufferUsages::COPY_DST
                    | wgpu::BufferUsages::COPY_SRC,
                mapped_at_creation: false,
            });
            match &dcl.data {
                Some(GpuData::Real(v)) => {
                    backend
                        .queue()
                        .write_buffer(&buf, 0, &real_bytes(v, precision))
                }
                Some(GpuData::U32(v)) if !v.is_empty() => {
                    backend
                        .queue()
                        .write_buffer(&buf, 0, bytemuck::cast_slice(v))
                }
                _ => {}
            }
            buffers.push(buf);
        }
        // Step records: fixed head + signals, padded to the dynamic-offset alignment.
        let align = limits.min_storage_buffer_offset_alignment.max(16) as usize;
        let record_bytes =
            ((PARAM_HEADER + signals.len()) * precision.bytes()).next_multiple_of(align);
        let record_reals = record_bytes / precision.bytes();
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("step records"),
            size: (record_bytes * BATCH) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let params_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("step record layout"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: true,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let params_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("step records"),
            layout: &params_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                    buffer: &params,
                    offset: 0,
                    size: std::num::NonZeroU64::new(record_bytes as u64),
                }),
            }],
        });
        let elem_of = |b: GpuBuffer| decls[b.0].elem;
        let make = |k: &Kernel| -> Result<Pipeline, ComputeError> {
            if k.bindings.len() + 1 > limits.max_storage_buffers_per_shader_stage as usize {
                return Err(ComputeError::Gpu(format!(
                    "kernel '{}' binds {} storage buffers; the device allows {} per stage",
                    k.label,
                    k.bindings.len() + 1,
                    limits.max_storage_buffers_per_shader_stage
                )));
            }
            let src = assemble(k, precision, &elem_of);
            validate_wgsl(&src).map_err(|e| {
                ComputeError::Gpu(format!("kernel '{}' does not validate:\n{e}", k.label))
            })?;
            let scope = device.push_error_scope(wgpu::ErrorFilter::Validation);
            let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
                label: Some(&k.label),
                source: wgpu::ShaderSource::Wgsl(src.into()),
            });
            let entries: Vec<wgpu::BindGroupLayoutEntry> = k
                .bindings
                .iter()
                .enumerate()
                .map(|(i, (_, _, acc))| wgpu::BindGroupLayoutEntry {
                    binding: i as u32,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage {
                            read_only: *acc == Access::Read,
                        },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                    count: None,
                })
                .collect();
            let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(&k.label),
                entries: &entries,
            });
            let pl = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: Some(&k.label),
                bind_group_layouts: &[Some(&params_layout), Some(&layout)],
                immediate_size: 0,
            });
            let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(&k.label),
                layout: Some(&pl),
                module: &module,
                entry_point: Some("main"),
                compilation_options: Default::default(),
                cache: None,
            });
            let bg_entries: Vec<wgpu::BindGroupEntry> = k
                .bindings
                .iter()
                .enumerate()
                .map(|(i, (_, b, _))| wgpu::BindGroupEntry {
                    binding: i as u32,
                    resource: buffers[b.0].as_entire_binding(),
                })
                .collect();
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(&k.label),
                layout: &layout,
                entries: &bg_entries,
            });
            if let Some(e) = pollster::block_on(scope.pop()) {
                return Err(ComputeError::Gpu(format!("kernel '{}': {e}", k.label)));
            }
            let bytes = k
                .bindings
                .iter()
                .map(|(_, b, acc)| {
                    let size = (decls[b.0].len * eb(decls[b.0].elem)) as u64;
                    if *acc == Access::ReadWrite {
                        2 * size
                    } else {
                        size
                    }
                })
                .sum();
            Ok(Pipeline {
                bytes,
                label: k.label.clone(),
                pipeline,
                bind_group,
                count: k.count,
            })
        };
        let mut forces = Vec::new();
        let mut kinematics = Vec::new();
        let mut post_update = Vec::new();
        let mut field: Vec<(usize, crate::SubCycle, Vec<Pipeline>)> = Vec::new();
        for ((phase, k), &owner) in kernels.iter().zip(&kernel_owner) {
            match phase {
                Phase::Forces => forces.push(make(k)?),
                Phase::Kinematics => kinematics.push(make(k)?),
                Phase::PostUpdate => post_update.push(make(k)?),
                Phase::Field => {
                    let stage = sim.field_stages.get(owner).and_then(|s| s.as_ref());
                    let Some(stage) = stage else {
                        return Err(ComputeError::Gpu(format!(
                            "kernel '{}' is in the field phase, but physics '{}' has no field stage (Physics::field_schedule)",
                            k.label,
                            sim.physics[owner].name()
                        )));
                    };
                    let p = make(&k.clone().const_real("FIELD_DT_SCALE", stage.cycle.scale()))?;
                    match field.last_mut() {
                        Some(g) if g.0 == owner => g.2.push(p),
                        _ => field.push((owner, stage.cycle, vec![p])),
                    }
                }
            }
        }
        let field = field.into_iter().map(|(_, c, p)| (c, p)).collect();
        let mut builtins = builtin_kernels::<D>(sim.n_nodes())
            .into_iter()
            .map(|k| {
                let k = if k.label == "update_watchdog" {
                    k.const_real("RUNAWAY2", sim.runaway * sim.runaway)
                } else {
                    k
                };
                make(&k)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let energy = match energy_buffers {
            Some(b) => {
                let [save, work] =
                    super::energy::kernels(&b, sim.n_nodes(), D::D, &layout.slot_ranges);
                let staging = device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("energy read-back"),
                    size: buffers[b.acc].size(),
                    usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                });
                Some(GpuEnergy {
                    save: make(&save)?,
                    work: make(&work)?,
                    buffers: b,
                    staging,
                })
            }
            None => None,
        };
        let update = builtins.pop().expect("three built-ins");
        let gather_forces = builtins.pop().expect("three built-ins");
        let gather_integrate = builtins.pop().expect("three built-ins");
        // Read-back layout: u, v, force, status, gross, fields.
        let mut staging_size = 0u64;
        for i in [
            builtin::DISPLACEMENT,
            builtin::VELOCITY,
            builtin::FORCE,
            builtin::STATUS,
            builtin::GROSS,
        ]
        .into_iter()
        .chain(field_buffers.iter().copied())
        {
            staging_size += buffers[i].size();
        }
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("read-back"),
            size: staging_size,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let run = GpuRun {
            backend: backend.clone(),
            precision,
            buffers,
            field_buffers,
            signals,
            errors,
            forces,
            kinematics,
            post_update,
            field,
            gather_integrate,
            gather_forces,
            update,
            params,
            params_group,
            record_reals,
            record_bytes: record_bytes as u64,
            staging,
            max_groups: limits.max_compute_workgroups_per_dimension.max(1),
            energy,
        };
        let mass_phys = real_bytes(&sim.mass_phys, precision);
        backend
            .queue()
            .write_buffer(&run.buffers[builtin::MASS_PHYS], 0, &mass_phys);
        Ok(run)
    }

    fn write_reals(&self, buffer: usize, v: &[f64]) {
        if !v.is_empty() {
            self.backend.queue().write_buffer(
                &self.buffers[buffer],
                0,
                &real_bytes(v, self.precision),
            );
        }
    }

    /// Host state → device (the host state is the truth between runs).
    fn upload<D: Dim>(&self, sim: &Simulation<D>) {
        self.write_reals(builtin::DISPLACEMENT, &sim.state.u);
        self.write_reals(builtin::VELOCITY, &sim.state.v);
        self.write_reals(builtin::MASS, &sim.mass);
        // Changes with the null model (Simulation::refresh_mass).
        self.write_reals(builtin::MASS_PHYS, &sim.mass_phys);
        for (spec, &b) in sim.state.fields.specs().iter().zip(&self.field_buffers) {
            let id = sim.state.fields.id(&spec.name).expect("declared field");
            self.write_reals(b, sim.state.fields.get(id));
        }
    }

    /// Clears the watchdog status (start of every run).
    fn reset_status(&self) {
        self.backend.queue().write_buffer(
            &self.buffers[builtin::STATUS],
            0,
            bytemuck::cast_slice(&[u32::MAX; 4]),
        );
    }

    /// Uploads the host state unless the simulation knows the device already holds it
    /// (`device_fresh`, set only by internal loops right after a read-back).
    fn sync_to_device<D: Dim>(&self, sim: &mut Simulation<D>) {
        if !std::mem::take(&mut sim.device_fresh) {
            self.upload(sim);
        }
    }

    fn record<D: Dim>(&self, sim: &Simulation<D>, t: f64, step: u64, out: &mut Vec<f64>) {
        let start = out.len();
        out.resize(start + self.record_reals, 0.0);
        let r = &mut out[start..];
        let g = sim.gravity;
        let s32 = (step & 0xffff_ffff) as u32;
        r[..PARAM_HEADER].copy_from_slice(&[
            t,
            sim.dt,
            sim.damping as u8 as f64,
            sim.local_damping,
            g[0],
            g[1],
            g[2],
            (s32 / 4096) as f64,
            (s32 % 4096) as f64,
        ]);
        for (i, s) in self.signals.iter().enumerate() {
            r[PARAM_HEADER + i] = s(t, sim.dt);
        }
    }

    fn dispatch(&self, pass: &mut wgpu::ComputePass<'_>, p: &Pipeline) {
        if p.count == 0 {
            return;
        }
        let groups = p.count.div_ceil(64);
        let x = groups.min(self.max_groups);
        let y = groups.div_ceil(x);
        pass.set_pipeline(&p.pipeline);
        pass.set_bind_group(1, &p.bind_group, &[]);
        pass.dispatch_workgroups(x, y, 1);
    }

    /// Runs `n` explicit steps on the device, then reads the state back once.
    pub(crate) fn run<D: Dim>(
        &mut self,
        sim: &mut Simulation<D>,
        n: u64,
    ) -> Result<(), ComputeError> {
        if n == 0 {
            return Ok(());
        }
        self.sync_to_device(sim);
        self.reset_status();
        // Energy balance: on while the simulation tracks it (paused during relaxation).
        let energy_on = self.energy.is_some() && sim.energy.is_some();
        if energy_on {
            if let Some(mut t) = sim.energy.take() {
                sim.energy_baseline(&mut t);
                sim.energy = Some(t);
            }
        }
        let (t0, step0) = (sim.state.time, sim.state.step);
        let (mut t, mut step) = (t0, step0);
        let mut left = n;
        let mut records = Vec::new();
        while left > 0 {
            let k = left.min(BATCH as u64) as usize;
            records.clear();
            let mut tt = t;
            for j in 0..k {
                self.record(sim, tt, step + j as u64 + 1, &mut records);
                tt += sim.dt;
            }
            self.backend.queue().write_buffer(
                &self.params,
                0,
                &real_bytes(&records, self.precision),
            );
            let mut enc =
                self.backend
                    .device()
                    .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                        label: Some("steps"),
                    });
            {
                let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("steps"),
                    timestamp_writes: None,
                });
                for j in 0..k {
                    pass.set_bind_group(
                        0,
                        &self.params_group,
                        &[(j as u64 * self.record_bytes) as u32],
                    );
                    for p in &self.forces {
                        self.dispatch(&mut pass, p);
                    }
                    let energy = self.energy.as_ref().filter(|_| energy_on);
                    if let Some(e) = energy {
                        self.dispatch(&mut pass, &e.save);
                    }
                    self.dispatch(&mut pass, &self.gather_integrate);
                    for p in &self.kinematics {
                        self.dispatch(&mut pass, p);
                    }
                    if let Some(e) = energy {
                        self.dispatch(&mut pass, &e.work);
                    }
                    self.dispatch(&mut pass, &self.update);
                    for p in &self.post_update {
                        self.dispatch(&mut pass, p);
                    }
                    let done = step + j as u64 + 1;
                    for (cycle, group) in &self.field {
                        if !cycle.runs_after(done) {
                            continue;
                        }
                        for _ in 0..cycle.substeps() {
                            for p in group {
                                self.dispatch(&mut pass, p);
                            }
                        }
                    }
                }
            }
            self.backend.queue().submit([enc.finish()]);
            t = tt;
            step += k as u64;
            left -= k as u64;
        }
        let (status, _) = self.read_back(sim, false)?;
        sim.state.time = t;
        sim.state.step = step;
        self.physics_error(&status)?;
        if status[0] != u32::MAX {
            // Step numbers are kept modulo 2^32 on the device.
            let lo = (step0 + 1) as u32;
            let bad_step = step0 + 1 + status[0].wrapping_sub(lo) as u64;
            let mut tb = t0;
            for _ in step0..bad_step {
                tb += sim.dt;
            }
            let node = status[1] / 2;
            let nonfinite = status[1] % 2 == 0;
            return Err(sim.divergence(bad_step, tb, node as usize, nonfinite));
        }
        if energy_on {
            let works = self.read_energy()?;
            if let Some(mut t) = sim.energy.take() {
                t.add_batch(&works);
                let verdict = sim.energy_check(&mut t);
                sim.energy = Some(t);
                verdict?;
            }
        }
        Ok(())
    }

    /// Reads the energy accumulators, sums them in node order and zeroes them.
    fn read_energy(&self) -> Result<Vec<f64>, ComputeError> {
        let e = self.energy.as_ref().expect("energy kernels");
        let device = self.backend.device();
        let acc = &self.buffers[e.buffers.acc];
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("energy read-back"),
        });
        enc.copy_buffer_to_buffer(acc, 0, &e.staging, 0, acc.size());
        enc.clear_buffer(acc, 0, None);
        self.backend.queue().submit([enc.finish()]);
        let slice = e.staging.slice(..);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|err| ComputeError::Gpu(format!("device lost while waiting: {err}")))?;
        rx.recv()
            .map_err(|err| ComputeError::Gpu(format!("energy read-back failed: {err}")))?
            .map_err(|err| ComputeError::Gpu(format!("energy read-back failed: {err}")))?;
        let n = (acc.size() as usize) / self.precision.bytes();
        let mut values = vec![0.0; n];
        {
            let data = slice.get_mapped_range().map_err(|err| {
                ComputeError::Gpu(format!("energy read-back mapping failed: {err}"))
            })?;
            reals_from(&data, self.precision, &mut values);
        }
        e.staging.unmap();
        let per = e.buffers.per_node;
        let used = (n / (2 * per)) * 2 * per;
        Ok(super::energy::sum_nodes(&values[..used], per))
    }

    /// Evaluates the forces at the current state (no step), reads back state, node force
    /// and, with `gross`, the sum of absolute slot contributions per dof.
    pub(crate) fn evaluate<D: Dim>(
        &mut self,
        sim: &mut Simulation<D>,
        gross: bool,
    ) -> Result<Option<Vec<f64>>, ComputeError> {
        self.sync_to_device(sim);
        self.reset_status();
        let mut records = Vec::new();
        self.record(sim, sim.state.time, sim.state.step, &mut records);
        self.backend
            .queue()
            .write_buffer(&self.params, 0, &real_bytes(&records, self.precision));
        let mut enc =
            self.backend
                .device()
                .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                    label: Some("forces"),
                });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("forces"),
                timestamp_writes: None,
            });
            pass.set_bind_group(0, &self.params_group, &[0]);
            for p in &self.forces {
                self.dispatch(&mut pass, p);
            }
            self.dispatch(&mut pass, &self.gather_forces);
        }
        self.backend.queue().submit([enc.finish()]);
        let (status, g) = self.read_back(sim, gross)?;
        self.physics_error(&status)?;
        Ok(g)
    }

    /// The physics error a kernel raised (status words 2-3), if any.
    fn physics_error(&self, status: &[u32; 4]) -> Result<(), ComputeError> {
        match self.errors.get(status[2] as usize) {
            Some((physics, message)) if status[2] != u32::MAX => {
                Err(ComputeError::physics(physics.clone(), message(status[3])))
            }
            _ => Ok(()),
        }
    }

    /// Copies u, v, force, status (and gross) and the fields into the staging buffer and
    /// reads them into the host state: one device-to-host read.
    fn read_back<D: Dim>(
        &mut self,
        sim: &mut Simulation<D>,
        gross: bool,
    ) -> Result<([u32; 4], Option<Vec<f64>>), ComputeError> {
        let device = self.backend.device();
        let mut enc = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("read-back"),
        });
        let mut order = vec![
            builtin::DISPLACEMENT,
            builtin::VELOCITY,
            builtin::FORCE,
            builtin::STATUS,
        ];
        if gross {
            order.push(builtin::GROSS);
        }
        order.extend(self.field_buffers.iter().copied());
        let mut offsets = Vec::with_capacity(order.len());
        let mut off = 0u64;
        for &i in &order {
            let size = self.buffers[i].size();
            enc.copy_buffer_to_buffer(&self.buffers[i], 0, &self.staging, off, size);
            offsets.push(off);
            off += size;
        }
        self.backend.queue().submit([enc.finish()]);
        let slice = self.staging.slice(..off);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| ComputeError::Gpu(format!("device lost while waiting: {e}")))?;
        rx.recv()
            .map_err(|e| ComputeError::Gpu(format!("read-back failed: {e}")))?
            .map_err(|e| ComputeError::Gpu(format!("read-back failed: {e}")))?;
        self.backend.count_readback();
        let p = self.precision;
        let eb = p.bytes();
        let mut status = [u32::MAX; 4];
        let mut gross_out = None;
        {
            let data = slice
                .get_mapped_range()
                .map_err(|e| ComputeError::Gpu(format!("read-back mapping failed: {e}")))?;
            let at = |k: usize, len: usize, elem: usize| -> &[u8] {
                let o = offsets[k] as usize;
                &data[o..o + len * elem]
            };
            let nd = sim.state.u.len();
            reals_from(at(0, nd, eb), p, &mut sim.state.u);
            reals_from(at(1, nd, eb), p, &mut sim.state.v);
            reals_from(at(2, nd, eb), p, &mut sim.force);
            for (j, c) in at(3, 4, 4).chunks_exact(4).enumerate() {
                status[j] = u32::from_le_bytes(c.try_into().expect("4 bytes"));
            }
            let mut k = 4;
            if gross {
                let mut g = vec![0.0; nd];
                reals_from(at(4, nd, eb), p, &mut g);
                gross_out = Some(g);
                k = 5;
            }
            let names: Vec<String> = sim
                .state
                .fields
                .specs()
                .iter()
                .map(|s| s.name.clone())
                .collect();
            for name in names {
                let id = sim.state.fields.id(&name)?;
                let dst = sim.state.fields.get_mut(id);
                let len = dst.len();
                reals_from(at(k, len, eb), p, dst);
                k += 1;
            }
        }
        self.staging.unmap();
        Ok((status, gross_out))
    }
}

impl GpuRun {
    /// Bytes one explicit step streams through device memory if every bound buffer is read
    /// once and read-write buffers are written once more: the traffic floor to compare
    /// an achieved step rate with memory bandwidth.
    pub(crate) fn bytes_per_step(&self) -> u64 {
        self.forces
            .iter()
            .chain(std::iter::once(&self.gather_integrate))
            .chain(&self.kinematics)
            .chain(std::iter::once(&self.update))
            .chain(&self.post_update)
            .map(|p| p.bytes)
            .sum::<u64>()
            + self
                .field
                .iter()
                .map(|(c, g)| c.substeps() as u64 * g.iter().map(|p| p.bytes).sum::<u64>())
                .sum::<u64>()
    }

    /// Labels of the compiled kernels in dispatch order (for reports).
    pub(crate) fn kernel_labels(&self) -> Vec<String> {
        self.forces
            .iter()
            .chain(std::iter::once(&self.gather_integrate))
            .chain(&self.kinematics)
            .chain(std::iter::once(&self.update))
            .chain(&self.post_update)
            .chain(self.field.iter().flat_map(|(_, g)| g))
            .map(|p| p.label.clone())
            .collect()
    }
}
