//! Contact: laws (penalties, friction, damping, surface properties), the broad phase's
//! skin, the candidate capacity and bonded pairs; each is an error naming the
//! parameter when the simulation is built.

use pcdc_compute::{
    Backend, Components, ComputeError, FieldKey, FieldUse, ForceContext, InitContext, Physics,
    Place, Simulation,
};
use pcdc_contact::Contact;
use pcdc_mech::{LinearElastic, Mechanics};
use pcdc_mesh::{builders, Dim2, Mesh, Range};

use crate::{case, run};

const E: f64 = 30e9;

/// Owns a face flag field named `broken_face` (what the cohesive joints own in FDEM
/// regions), so that bonded pairs have a field to read.
struct FaceFlags;

const FLAGS: FieldKey = FieldKey::new("broken_face", Place::Face, Components::Fixed(1));

impl Physics<Dim2> for FaceFlags {
    fn name(&self) -> &str {
        "face flags"
    }
    fn fields(&self, _mesh: &Mesh<Dim2>) -> Vec<FieldUse> {
        vec![FLAGS.own::<Dim2>()]
    }
    fn init(&mut self, _ctx: &mut InitContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
    fn compute_forces(&mut self, _ctx: &mut ForceContext<'_, Dim2>) -> Result<(), ComputeError> {
        Ok(())
    }
}

/// Builds two elastic triangles' worth of mesh with `contact`.
fn build(contact: Contact) -> Result<(), ComputeError> {
    let mesh = builders::rectangle(0.0, 0.0, 0.1, 0.05, 0.05).unwrap();
    let rock = LinearElastic::new(E, 0.25, 2600.0).unwrap();
    Simulation::builder(mesh, Backend::cpu(1).unwrap())
        .physics(Mechanics::new().material(Range::All, rock))
        .physics(FaceFlags)
        .physics(contact)
        .build()
        .map(|_| ())
}

#[test]
fn bad_contact_is_a_named_error() {
    run(
        "contact",
        vec![
            case("zero penalty", "contact penalty", || {
                build(Contact::new(0.0))
            }),
            case("negative penalty", "contact penalty", || {
                build(Contact::new(-E))
            }),
            case("NaN penalty", "contact penalty", || {
                build(Contact::new(f64::NAN))
            }),
            case("infinite penalty", "contact penalty", || {
                build(Contact::new(f64::INFINITY))
            }),
            case("friction angle 90", "contact friction angle", || {
                build(Contact::new(E).friction(90.0, E))
            }),
            case("negative friction angle", "contact friction angle", || {
                build(Contact::new(E).friction(-5.0, E))
            }),
            case("zero shear penalty", "contact shear penalty", || {
                build(Contact::new(E).friction(30.0, 0.0))
            }),
            case("NaN shear penalty", "contact shear penalty", || {
                build(Contact::new(E).friction(30.0, f64::NAN))
            }),
            case("damping exponent below 1", "damping exponent b", || {
                build(Contact::new(E).damping(1e6, 0.5))
            }),
            case(
                "zero damping transition",
                "damping transition stress T",
                || build(Contact::new(E).damping(0.0, 2.0)),
            ),
            case(
                "surface properties of the wrong length",
                "surface contact properties",
                || build(Contact::new(E).surface_defaults(vec![30.0; 3], vec![E; 3])),
            ),
            case(
                "surface friction angle out of range",
                "friction angle of element 1",
                || {
                    let mut phi = vec![30.0; 4];
                    phi[1] = 95.0;
                    build(Contact::new(E).surface_defaults(phi, vec![E; 4]))
                },
            ),
            case(
                "surface penalty negative",
                "contact penalty of element 2",
                || {
                    let mut p = vec![E; 4];
                    p[2] = -1.0;
                    build(Contact::new(E).surface_defaults(vec![30.0; 4], p))
                },
            ),
            case("negative skin", "contact skin", || {
                build(Contact::new(E).skin(-1e-3))
            }),
            case("NaN skin", "contact skin", || {
                build(Contact::new(E).skin(f64::NAN))
            }),
            case(
                "bonded pairs with an odd element list",
                "contact bonded pairs",
                || build(Contact::new(E).bonded_pairs(&[0, 1, 2], &[0], "broken_face")),
            ),
            case(
                "bonded element out of range",
                "contact bonded element",
                || build(Contact::new(E).bonded_pairs(&[0, 99], &[0], "broken_face")),
            ),
            case("bonded face out of range", "contact bonded face", || {
                build(Contact::new(E).bonded_pairs(&[0, 1], &[9999], "broken_face"))
            }),
            case("zero candidate capacity", "Contact::capacity", || {
                build(Contact::new(E).capacity(0))
            }),
            case(
                "broken-bond field is one of contact's own",
                "contact_candidate_count",
                || build(Contact::new(E).bonded_pairs(&[0, 1], &[0], "contact_candidate_count")),
            ),
            case(
                "broken-bond field nobody owns",
                "reads field 'no_such_field', but no composed physics owns it",
                || build(Contact::new(E).bonded_pairs(&[0, 1], &[0], "no_such_field")),
            ),
        ],
    );
}
