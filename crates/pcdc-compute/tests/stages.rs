//! Stages: a post-update stage that runs once per step and a sub-cycled field stage
//! (first-order decay dT/dt = -k T by forward Euler, a closed form per field step),
//! scheduled by hand and automatically from the field's own stable step, on the CPU and
//! on the GPU.

use pcdc_compute::gpu::{Access, GpuSetup, Kernel, Phase};
use pcdc_compute::{
    Backend, Components, ComputeError, Entity, EntityKind, FieldContext, FieldKey, FieldSchedule,
    FieldStore, FieldUse, ForceContext, InitContext, Kinematics, Physics, Place, Simulation,
    StableStep, SubCycle,
};
use pcdc_mesh::{builders, Dim2, Mesh};

const DECAY: FieldKey = FieldKey::new("decay", Place::Node, Components::Fixed(1));
const POSTS: FieldKey = FieldKey::new("post_updates", Place::Node, Components::Fixed(1));

/// Unit masses, no forces; a decaying node scalar (T0 = 1) and a post-update counter.
struct Decay {
    k: f64,
    schedule: FieldSchedule,
}

impl Physics<Dim2> for Decay {
    fn name(&self) -> &str {
        "decay"
    }
    fn fields(&self, _mesh: &Mesh<Dim2>) -> Vec<FieldUse> {
        vec![DECAY.own::<Dim2>().initial(1.0), POSTS.own::<Dim2>()]
    }
    fn init(&mut self, _ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn add_mass(&self, _m: &Mesh<Dim2>, _f: &FieldStore, mass: &mut [f64], _s: Option<f64>) {
        mass.iter_mut().for_each(|m| *m += 1.0);
    }
    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn post_update(&mut self, ctx: &mut FieldContext<'_, Dim2>) -> Result<(), ComputeError> {
        let id = ctx.fields.id(POSTS)?;
        ctx.fields.get_mut(id).iter_mut().for_each(|c| *c += 1.0);
        Ok(())
    }
    fn field_schedule(&self) -> Option<FieldSchedule> {
        Some(self.schedule)
    }
    fn field_stable_step(
        &self,
        _kin: &Kinematics<'_, Dim2>,
        _f: &FieldStore,
    ) -> Option<StableStep> {
        // Forward Euler on dT/dt = -k T is stable for dt < 2/k.
        Some(StableStep {
            dt: 2.0 / self.k,
            entity: Entity::new(EntityKind::Node, 0),
            physics: "decay".into(),
        })
    }
    fn field_step(&mut self, ctx: &mut FieldContext<'_, Dim2>) -> Result<(), ComputeError> {
        let (k, dt) = (self.k, ctx.dt);
        let id = ctx.fields.id(DECAY)?;
        ctx.fields
            .get_mut(id)
            .iter_mut()
            .for_each(|t| *t = *t - k * dt * *t);
        Ok(())
    }
    fn gpu_setup(&mut self, setup: &mut GpuSetup<'_, Dim2>) -> Result<(), ComputeError> {
        let n = setup.mesh.n_nodes();
        let decay = Kernel::new(
            "decay",
            "fn kernel(i: u32) { decay[i] = decay[i] - K * (p_dt() * FIELD_DT_SCALE) * decay[i]; }",
            n,
        )
        .bind("decay", setup.field(DECAY)?, Access::ReadWrite)
        .const_real("K", self.k);
        setup.kernel(Phase::Field, decay)?;
        let posts = Kernel::new(
            "post_updates",
            "fn kernel(i: u32) { posts[i] = posts[i] + Real(1.0); }",
            n,
        )
        .bind("posts", setup.field(POSTS)?, Access::ReadWrite);
        setup.kernel(Phase::PostUpdate, posts)
    }
}

const DT: f64 = 1e-3;

fn sim(backend: Backend, k: f64, schedule: FieldSchedule) -> Simulation<Dim2> {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    Simulation::builder(mesh, backend)
        .time_step(DT)
        .physics(Decay { k, schedule })
        .build()
        .unwrap()
}

/// T after `field_steps` forward-Euler steps of `dt_f`, multiplied out in the same order.
fn euler(k: f64, dt_f: f64, field_steps: u64) -> f64 {
    let mut t = 1.0f64;
    for _ in 0..field_steps {
        t = t - k * dt_f * t;
    }
    t
}

#[test]
fn substeps_run_n_field_steps_per_step_and_post_update_once() {
    let (k, steps) = (40.0, 50u64);
    let mut s = sim(
        Backend::cpu(1).unwrap(),
        k,
        FieldSchedule::Fixed(SubCycle::Substeps(4)),
    );
    s.run(steps).unwrap();
    let expect = euler(k, DT * 0.25, 4 * steps);
    let t = s.field(DECAY).unwrap();
    assert!(t.iter().all(|&x| x == expect), "{} vs {expect}", t[0]);
    assert!(s.field(POSTS).unwrap().iter().all(|&c| c == steps as f64));
    // And the scheme approaches the closed form exp(-k t) = e^-2, to O(k dt_f) = 1 %.
    let exact = (-k * DT * steps as f64).exp();
    assert!((expect - exact).abs() < 0.02 * exact, "{expect} vs {exact}");
}

#[test]
fn every_n_runs_one_longer_field_step_after_every_nth_step() {
    let (k, steps) = (10.0, 25u64);
    let mut s = sim(
        Backend::cpu(1).unwrap(),
        k,
        FieldSchedule::Fixed(SubCycle::Every(10)),
    );
    s.run(steps).unwrap();
    // Field steps after steps 10 and 20 only.
    assert_eq!(s.field(DECAY).unwrap()[0], euler(k, 10.0 * DT, 2));
    assert_eq!(s.field(POSTS).unwrap()[0], steps as f64);
}

#[test]
fn auto_schedule_follows_the_fields_own_stable_step() {
    // dt_f = 0.5 (safety) * 2/k = 1/k. k = 3500: dt_f = 2.9e-4 < DT, so ceil(3.5) = 4
    // sub-steps; k = 100: dt_f = 1e-2 > DT, so one step every 10.
    for (k, cycle) in [
        (3500.0, SubCycle::Substeps(4)),
        (100.0, SubCycle::Every(10)),
    ] {
        let s = sim(Backend::cpu(1).unwrap(), k, FieldSchedule::Auto);
        let stages = s.field_stages();
        assert_eq!(stages.len(), 1);
        assert_eq!(stages[0].cycle, cycle, "k = {k}");
        assert_eq!(stages[0].dt, DT * cycle.scale());
        let limit = stages[0].limit.as_ref().unwrap();
        assert_eq!(limit.entity, Entity::new(EntityKind::Node, 0));
        // The field's limit does not limit the mechanical step.
        assert_eq!(s.dt(), DT);
    }
}

#[test]
fn a_zero_ratio_is_an_error() {
    let mesh = builders::rectangle(0.0, 0.0, 1.0, 1.0, 0.5).unwrap();
    let r = Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .time_step(DT)
        .physics(Decay {
            k: 1.0,
            schedule: FieldSchedule::Fixed(SubCycle::Substeps(0)),
        })
        .build();
    let e = r.err().expect("a zero ratio must not build").to_string();
    assert!(e.contains("sub-cycling of physics 'decay'"), "{e}");
}

#[cfg(feature = "gpu")]
#[test]
fn gpu_runs_the_same_stages() {
    let Some(gpu) = pcdc_compute::gpu::gpu_test_backend(Some(pcdc_compute::Precision::F64)) else {
        return;
    };
    for (k, schedule, steps) in [
        (400.0, FieldSchedule::Fixed(SubCycle::Substeps(4)), 300u64),
        (10.0, FieldSchedule::Fixed(SubCycle::Every(7)), 300),
        (3500.0, FieldSchedule::Auto, 20),
    ] {
        let mut c = sim(Backend::cpu(1).unwrap(), k, schedule);
        let mut g = sim(gpu.clone(), k, schedule);
        c.run(steps).unwrap();
        g.run(steps).unwrap();
        assert_eq!(g.field_stages()[0].cycle, c.field_stages()[0].cycle);
        let (tc, tg) = (c.field(DECAY).unwrap(), g.field(DECAY).unwrap());
        let rel = (tc[0] - tg[0]).abs() / tc[0].abs();
        assert!(
            rel < 1e-13,
            "{schedule:?}: cpu {} gpu {} ({rel:e})",
            tc[0],
            tg[0]
        );
        assert_eq!(g.field(POSTS).unwrap(), c.field(POSTS).unwrap());
    }
}
