//! The GPU kernels of [`crate::Hydro`] (`shaders/hydro.wgsl`): geometry and node volumes
//! after each position update (when the flow follows the solid), leak-off start, then
//! per fluid step the channel shares and the node update, the pore pressure on the mesh
//! nodes and, in two-way coupling, the pressure forces. The same arithmetic in the same
//! order as the CPU path, with no float atomics: nodes gather their channels' shares
//! in incidence order.

use pcdc_compute::gpu::{Access, GpuBuffer, GpuData, GpuSetup, Kernel, Phase};
use pcdc_compute::names::{JOINT_DAMAGE, PORE_PRESSURE};
use pcdc_compute::ComputeError;
use pcdc_mesh::Dim;

use crate::fields::{
    CHANNEL_APERTURE, CHANNEL_FLUX, CHANNEL_LEAK_AGE, FLOW_BALANCE, FLOW_PEAK_PRESSURE,
    FLOW_PRESSURE, FLOW_SATURATION, FLOW_STORED,
};
use crate::network::Network;
use crate::physics::{Coupling, Hydro};

/// The WGSL of every kernel: a shared head, then one section per kernel after a
/// `//!name` line.
pub(crate) const HYDRO_WGSL: &str = include_str!("shaders/hydro.wgsl");

/// The section of `HYDRO_WGSL` after the line `//!name` (empty if absent).
fn section(name: &str) -> &'static str {
    let marker = format!("//!{name}\n");
    let Some(at) = HYDRO_WGSL.find(&marker) else {
        return "";
    };
    let start = at + marker.len();
    let end = HYDRO_WGSL[start..]
        .find("//!")
        .map_or(HYDRO_WGSL.len(), |i| start + i);
    &HYDRO_WGSL[start..end]
}

/// The source of kernel `name`: the shared head, the points library for the kernels that
/// read positions, and that section.
pub(crate) fn kernel_source(name: &str) -> String {
    let head_end = HYDRO_WGSL.find("//!").unwrap_or(HYDRO_WGSL.len());
    let points = if matches!(name, "geometry_kernel" | "force_kernel") {
        section("points_library")
    } else {
        ""
    };
    format!("{}{points}{}", &HYDRO_WGSL[..head_end], section(name))
}

impl Hydro {
    /// Declares the buffers and kernels (see the module docs).
    pub(crate) fn gpu_program<D: Dim>(
        &mut self,
        setup: &mut GpuSetup<'_, D>,
    ) -> Result<(), ComputeError> {
        let Some(d) = self.derived.as_ref() else {
            return Err(ComputeError::Gpu("hydro: GPU setup before init".into()));
        };
        let geom = &self.geom;
        let net = &d.net;
        let (nc, nf, npc) = (net.n_channels(), net.n_nodes(), net.npc);
        let joints = &d.channel_joint_nodes;
        let slot_first = setup.slot_first();
        let mut info = Vec::with_capacity(nc * 3 * npc);
        for c in 0..nc {
            info.extend_from_slice(&joints[c * 2 * npc..(c + 1) * 2 * npc]);
            info.extend_from_slice(&net.channel_nodes[c * npc..(c + 1) * npc]);
        }
        let info = setup.upload("hydro channel info", GpuData::U32(info));
        let joint_of = setup.upload("hydro channel joint", GpuData::U32(net.joint.clone()));
        let delta0 = setup.upload("hydro initial aperture", GpuData::Real(d.delta0.clone()));
        let delta_ref = setup.upload(
            "hydro reference aperture",
            GpuData::Real(d.delta_ref.clone()),
        );
        let calib = setup.upload(
            "hydro calibrated weights",
            GpuData::Real(d.calib_weight.clone()),
        );
        let inc_ptr = setup.upload("hydro incidence ptr", GpuData::U32(net.inc_ptr.clone()));
        let inc = setup.upload("hydro incidence", GpuData::U32(net.incidence.clone()));
        let mesh_flow = setup.upload(
            "hydro mesh -> flow node",
            GpuData::U32(net.mesh_flow.clone()),
        );
        // Work buffers start from the geometry of init (flow-only runs keep it).
        let measure = setup.upload("hydro measure", GpuData::Real(geom.measure.clone()));
        let weight = setup.upload("hydro weights", GpuData::Real(geom.weight.clone()));
        let gpot = setup.upload("hydro g.m", GpuData::Real(geom.gravity_potential.clone()));
        let grad = setup.upload("hydro gradients", GpuData::Real(geom.grad.clone()));
        let volume = setup.upload("hydro node volume", GpuData::Real(geom.node_volume.clone()));
        let share = setup.upload("hydro shares", GpuData::Real(vec![0.0; nc * npc]));
        let leak = setup.upload("hydro leak", GpuData::Real(vec![0.0; nc]));
        // Conditions: per flow node (kind, signal), kind 0 none, 1 pressure, 2 head.
        let mut bc = vec![0u32; 2 * nf];
        let mut fixed_sig = Vec::with_capacity(d.fixed_values.len());
        for (_, v) in &d.fixed_values {
            let v = v.clone();
            fixed_sig.push(setup.signal(move |t, dt| v.at(t + dt)));
        }
        for l in 0..nf {
            let f = d.fixed[l];
            if f != Network::NONE {
                let (head, _) = d.fixed_values[f as usize];
                bc[2 * l] = if head { 2 } else { 1 };
                bc[2 * l + 1] = fixed_sig[f as usize];
            }
        }
        let mut rate_sig = Vec::with_capacity(d.rate_values.len());
        for v in &d.rate_values {
            let v = v.clone();
            rate_sig.push(setup.signal(move |t, dt| v.at(t + dt)));
        }
        // Rate entries per node, the CPU's list (same order).
        let rsig: Vec<u32> = d.rate_cond.iter().map(|&i| rate_sig[i as usize]).collect();
        let rate_ptr = d.rate_ptr.clone();
        let rshare = d.rate_share.clone();
        let bc = setup.upload("hydro conditions", GpuData::U32(bc));
        let elev = setup.upload("hydro elevation", GpuData::Real(d.elevation.clone()));
        let rate_ptr = setup.upload("hydro rate ptr", GpuData::U32(rate_ptr));
        let rsig = setup.upload("hydro rate signal", GpuData::U32(rsig));
        let rshare = setup.upload("hydro rate share", GpuData::Real(rshare));
        let err = setup.error(|l| {
            format!("divergence: fluid pressure not finite at flow node {l}. Hint: the fluid step is above the stable one (a fixed schedule too coarse?)")
        });

        let fl = self.model().fluid;
        let g = self.gravity;
        let g_abs = (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
        let ap = self.model().aperture;
        let leak_model = self.model().leak_off;
        let consts = |k: Kernel| -> Kernel {
            let k = k
                .const_u32("D", D::D as u32)
                .const_u32("NPC", npc as u32)
                .const_u32("INFO", 3 * npc as u32)
                .const_u32("SLOT_FIRST", slot_first)
                .const_u32("ERR_DIVERGED", err)
                .const_u32("LEAK", u32::from(leak_model.is_some()))
                .const_real("INV_NPC", 1.0 / npc as f64)
                .const_real("RHO", fl.density)
                .const_real("MU", fl.dynamic_viscosity())
                .const_real("BULK", self.bulk_modulus())
                .const_real("DMIN", ap.min)
                .const_real("DMAX", ap.max)
                .const_real("G0", g[0])
                .const_real("G1", g[1])
                .const_real("G2", g[2])
                .const_real("G_ABS", g_abs)
                .const_real("PI", std::f64::consts::PI);
            let l = leak_model.unwrap_or(crate::LeakOff {
                pore_pressure: 0.0,
                permeability: 0.0,
                pore_compressibility: 0.0,
                porosity: 0.0,
            });
            k.const_real("LEAK_PS", l.pore_pressure)
                .const_real("LEAK_KS", l.permeability)
                .const_real("LEAK_NS", l.porosity)
                .const_real("LEAK_CS", l.pore_compressibility)
        };
        let f = |key| setup.field(key);
        let (aperture, flux, age) = (f(CHANNEL_APERTURE)?, f(CHANNEL_FLUX)?, f(CHANNEL_LEAK_AGE)?);
        let peak = f(FLOW_PEAK_PRESSURE)?;
        let (pressure, saturation, stored, balance, pore) = (
            f(FLOW_PRESSURE)?,
            f(FLOW_SATURATION)?,
            f(FLOW_STORED)?,
            f(FLOW_BALANCE)?,
            f(PORE_PRESSURE)?,
        );
        let damage = if self.reads_damage() {
            Some(f(JOINT_DAMAGE)?)
        } else {
            None
        };
        let (coords, disp, slots, status) = (
            setup.coords(),
            setup.displacement(),
            setup.slots(),
            setup.status(),
        );
        let bind = |k: Kernel, names: &[(&str, GpuBuffer, Access)]| -> Kernel {
            names.iter().fold(k, |k, (n, b, a)| k.bind(n, *b, *a))
        };
        use Access::{Read as R, ReadWrite as W};
        let follows = self.coupling != Coupling::FlowOnly;
        if follows {
            let k = consts(Kernel::new(
                "hydro geometry",
                kernel_source("geometry_kernel"),
                nc,
            ));
            let k = bind(
                k,
                &[
                    ("coords", coords, R),
                    ("disp", disp, R),
                    ("hy_info", info, R),
                    ("hy_delta0", delta0, R),
                    ("hy_delta_ref", delta_ref, R),
                    ("hy_calib", calib, R),
                    ("hy_measure", measure, W),
                    ("hy_weight", weight, W),
                    ("hy_gpot", gpot, W),
                    ("hy_grad", grad, W),
                    ("channel_aperture", aperture, W),
                ],
            );
            setup.kernel(Phase::PostUpdate, k)?;
            let k = consts(Kernel::new(
                "hydro node volume",
                kernel_source("volume_kernel"),
                nf,
            ));
            let k = bind(
                k,
                &[
                    ("hy_inc_ptr", inc_ptr, R),
                    ("hy_inc", inc, R),
                    ("hy_measure", measure, R),
                    ("channel_aperture", aperture, R),
                    ("hy_volume", volume, W),
                ],
            );
            setup.kernel(Phase::PostUpdate, k)?;
        }
        if let Some(damage) = damage {
            let k = consts(Kernel::new(
                "hydro leak start",
                kernel_source("leak_start_kernel"),
                nc,
            ));
            let k = bind(
                k,
                &[
                    ("hy_joint", joint_of, R),
                    ("joint_damage", damage, R),
                    ("channel_leak_age", age, W),
                ],
            );
            setup.kernel(Phase::PostUpdate, k)?;
        }
        let k = consts(Kernel::new(
            "hydro channels",
            kernel_source("channel_kernel"),
            nc,
        ));
        let k = bind(
            k,
            &[
                ("hy_info", info, R),
                ("hy_gpot", gpot, R),
                ("hy_weight", weight, R),
                ("hy_grad", grad, R),
                ("hy_measure", measure, R),
                ("channel_aperture", aperture, R),
                ("flow_pressure", pressure, R),
                ("flow_saturation", saturation, R),
                ("channel_leak_age", age, W),
                ("channel_flux", flux, W),
                ("hy_share", share, W),
                ("hy_leak", leak, W),
            ],
        );
        setup.kernel(Phase::Field, k)?;
        let k = consts(Kernel::new("hydro nodes", kernel_source("node_kernel"), nf));
        let k = bind(
            k,
            &[
                ("hy_inc_ptr", inc_ptr, R),
                ("hy_inc", inc, R),
                ("hy_share", share, R),
                ("hy_leak", leak, R),
                ("hy_rate_ptr", rate_ptr, R),
                ("hy_rate_sig", rsig, R),
                ("hy_rate_share", rshare, R),
                ("hy_bc", bc, R),
                ("hy_elev", elev, R),
                ("hy_volume", volume, R),
                ("flow_stored", stored, W),
                ("flow_balance", balance, W),
                ("flow_pressure", pressure, W),
                ("flow_peak_pressure", peak, W),
                ("flow_saturation", saturation, W),
                ("status", status, W),
            ],
        );
        setup.kernel(Phase::Field, k)?;
        let n_mesh = net.mesh_flow.len();
        let pore_k = consts(Kernel::new(
            "hydro pore pressure",
            kernel_source("pore_kernel"),
            n_mesh,
        ));
        let pore_k = bind(
            pore_k,
            &[
                ("hy_mesh_flow", mesh_flow, R),
                ("flow_pressure", pressure, R),
                ("pore_pressure", pore, W),
            ],
        );
        // The pore pressure changes only with the fluid step: copied after it.
        setup.kernel(Phase::Field, pore_k)?;
        if self.coupling == Coupling::TwoWay {
            let k = consts(Kernel::new(
                "hydro pressure forces",
                kernel_source("force_kernel"),
                nc,
            ));
            let k = bind(
                k,
                &[
                    ("coords", coords, R),
                    ("disp", disp, R),
                    ("hy_info", info, R),
                    ("flow_pressure", pressure, R),
                    ("slots", slots, W),
                ],
            );
            setup.kernel(Phase::Forces, k)?;
        }
        Ok(())
    }
}

#[cfg(all(test, feature = "gpu"))]
mod tests {
    use pcdc_compute::gpu::{offline_kernel_sources, validate_wgsl};
    use pcdc_compute::{Physics, Precision};
    use pcdc_mesh::{builders, split_nodes, Dim, Mesh, Range};

    use crate::{Aperture, Coupling, FlowModel, Fluid, Hydro, LeakOff};

    fn flows() -> Vec<Hydro> {
        let model = FlowModel::new(Fluid::water(), Aperture::new(1e-5, 1e-6, 1e-3).unwrap());
        let leaky = model.with_leak_off(LeakOff {
            pore_pressure: 0.0,
            permeability: 1e-18,
            pore_compressibility: 1e-9,
            porosity: 0.1,
        });
        vec![
            Hydro::new(model)
                .coupling(Coupling::FlowOnly)
                .rate(Range::All, 1e-6),
            Hydro::new(model).coupling(Coupling::OneWay),
            Hydro::new(leaky)
                .gravity([0.0, -9.81, 0.0])
                .head(Range::All, 1.0)
                .fracture(Range::All, 1e-4),
        ]
    }

    fn check<D: Dim>(mesh: &Mesh<D>, with_damage: bool) {
        for p in [Precision::F64, Precision::F32] {
            for (i, h) in flows().into_iter().enumerate() {
                let mut physics: Vec<Box<dyn Physics<D>>> = Vec::new();
                if with_damage && i == 2 {
                    // Leak-off in a coupled mode reads the joints' damage.
                    physics.push(Box::new(pcdc_cohesive_stub::Damage));
                }
                physics.push(Box::new(h));
                let kernels = offline_kernel_sources(mesh, physics, p).unwrap();
                let mine: Vec<_> = kernels
                    .iter()
                    .filter(|(l, _)| l.starts_with("hydro"))
                    .collect();
                assert!(
                    mine.len() >= 3,
                    "{:?}",
                    kernels.iter().map(|k| &k.0).collect::<Vec<_>>()
                );
                for (label, src) in mine {
                    if let Err(e) = validate_wgsl(src) {
                        panic!("{label} ({p:?}): {e}\n{src}");
                    }
                }
            }
        }
    }

    /// A stand-in owner of the joints' damage field (this crate does not depend on
    /// pcdc-cohesive).
    mod pcdc_cohesive_stub {
        use pcdc_compute::names::JOINT_DAMAGE;
        use pcdc_compute::{ComputeError, FieldUse, ForceContext, InitContext, Physics};
        use pcdc_mesh::{Dim, Mesh};

        pub struct Damage;

        impl<D: Dim> Physics<D> for Damage {
            fn name(&self) -> &str {
                "damage"
            }
            fn fields(&self, _mesh: &Mesh<D>) -> Vec<FieldUse> {
                vec![JOINT_DAMAGE.own::<D>()]
            }
            fn init(&mut self, _ctx: &mut InitContext<'_, D>) -> Result<(), ComputeError> {
                Ok(())
            }
            fn compute_forces(
                &mut self,
                _ctx: &mut ForceContext<'_, D>,
            ) -> Result<(), ComputeError> {
                Ok(())
            }
            fn gpu_setup(
                &mut self,
                _setup: &mut pcdc_compute::gpu::GpuSetup<'_, D>,
            ) -> Result<(), ComputeError> {
                Ok(())
            }
        }
    }

    #[test]
    fn hydro_kernels_validate_with_naga() {
        let m2 = split_nodes(
            &builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.25).unwrap(),
            &Range::All,
        )
        .unwrap();
        let m3 = split_nodes(
            &builders::cuboid([0.0; 3], [1.0; 3], 0.5).unwrap(),
            &Range::All,
        )
        .unwrap();
        check(&m2, true);
        check(&m3, true);
    }

    #[test]
    fn every_kernel_section_is_found() {
        for name in [
            "geometry_kernel",
            "volume_kernel",
            "leak_start_kernel",
            "channel_kernel",
            "node_kernel",
            "pore_kernel",
            "force_kernel",
        ] {
            let src = super::kernel_source(name);
            assert_eq!(src.matches("fn kernel(").count(), 1, "{name}");
        }
    }
}
