//! The energy balance on the GPU backend (see [`crate::EnergyBalance`]).
//!
//! Two kernels, dispatched only while tracking is on: `energy_save` keeps v⁻ before
//! the velocity update, and `energy_work`, after the kinematic conditions, accumulates
//! the work of each physics, of gravity and of local damping with v̄ = (v⁻ + v⁺)/2, and
//! gives the kinematic conditions the rest of the node's kinetic-energy change. Each
//! node accumulates into its own NP + 3 entries of `energy_acc` (no atomics); at the end of a run the host reads
//! them, sums them in node order, adds them to the balance and zeroes the buffer. The
//! watchdog is therefore checked at the end of every `run` call on the GPU (every
//! [`crate::ENERGY_CHECK_EVERY`] steps on the CPU).

use super::program::{builtin, BufferDecl, Elem};
use super::{Access, GpuBuffer, Kernel};

const SAVE: &str = include_str!("shaders/energy_save.wgsl");
const WORK: &str = include_str!("shaders/energy_work.wgsl");

/// Buffers of the energy balance: v⁻ and the per-node accumulators.
pub(crate) struct EnergyBuffers {
    pub vel_prev: usize,
    pub acc: usize,
    /// Accumulators per node, NACC = NP + 3 (works), then NACC forward halves.
    pub per_node: usize,
}

/// Declares the two buffers (appended to `decls`).
pub(crate) fn declare(
    decls: &mut Vec<BufferDecl>,
    n_nodes: usize,
    d: usize,
    n_physics: usize,
) -> EnergyBuffers {
    let per_node = n_physics + 3;
    decls.push(BufferDecl {
        label: "energy: velocity before update".into(),
        elem: Elem::Real,
        len: n_nodes * d,
        data: None,
    });
    decls.push(BufferDecl {
        label: "energy: work per node".into(),
        elem: Elem::Real,
        len: n_nodes * 2 * per_node,
        data: None,
    });
    EnergyBuffers {
        vel_prev: decls.len() - 2,
        acc: decls.len() - 1,
        per_node,
    }
}

/// `fn phys_of(s: u32) -> u32`: the physics of force slot `s`, from the slot ranges.
fn phys_of(slot_ranges: &[std::ops::Range<usize>]) -> String {
    let mut f = String::from("fn phys_of(s: u32) -> u32 {\n");
    for (p, r) in slot_ranges
        .iter()
        .enumerate()
        .take(slot_ranges.len().saturating_sub(1))
    {
        f.push_str(&format!("    if s < {}u {{ return {p}u; }}\n", r.end));
    }
    f.push_str(&format!(
        "    return {}u;\n}}\n",
        slot_ranges.len().saturating_sub(1)
    ));
    f
}

/// The kernels `energy_save` and `energy_work`.
pub(crate) fn kernels(
    b: &EnergyBuffers,
    n_nodes: usize,
    d: usize,
    slot_ranges: &[std::ops::Range<usize>],
) -> [Kernel; 2] {
    let g = GpuBuffer;
    let np = slot_ranges.len() as u32;
    let common = |k: Kernel| {
        k.const_u32("D", d as u32)
            .const_u32("NP", np)
            .const_u32("NACC", b.per_node as u32)
    };
    [
        common(Kernel::new("energy_save", SAVE, n_nodes))
            .bind("vel", g(builtin::VELOCITY), Access::Read)
            .bind("vel_prev", g(b.vel_prev), Access::ReadWrite),
        common(Kernel::new(
            "energy_work",
            format!("{}{WORK}", phys_of(slot_ranges)),
            n_nodes,
        ))
        .bind("slots", g(builtin::SLOTS), Access::Read)
        .bind("gather_ptr", g(builtin::GATHER_PTR), Access::Read)
        .bind("gather_idx", g(builtin::GATHER_IDX), Access::Read)
        .bind("mass", g(builtin::MASS), Access::Read)
        .bind("vel", g(builtin::VELOCITY), Access::Read)
        .bind("vel_prev", g(b.vel_prev), Access::Read)
        .bind("energy_acc", g(b.acc), Access::ReadWrite),
    ]
}

/// Sums the per-node accumulators in node order: works (per physics, gravity, local
/// damping, kinematic conditions), then the last step's forward halves.
pub(crate) fn sum_nodes(acc: &[f64], per_node: usize) -> Vec<f64> {
    let mut sum = vec![0.0; 2 * per_node];
    for node in acc.chunks_exact(2 * per_node) {
        for (s, a) in sum.iter_mut().zip(node) {
            *s += a;
        }
    }
    sum
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::program::{assemble, validate_wgsl};
    use crate::Precision;

    #[test]
    fn energy_kernels_validate_with_naga() {
        let b = EnergyBuffers {
            vel_prev: builtin::COUNT,
            acc: builtin::COUNT + 1,
            per_node: 5,
        };
        let elem = |g: GpuBuffer| {
            if g.0 == builtin::GATHER_PTR || g.0 == builtin::GATHER_IDX {
                Elem::U32
            } else {
                Elem::Real
            }
        };
        for p in [Precision::F64, Precision::F32] {
            for d in [2, 3] {
                for k in kernels(&b, 10, d, &[0..4, 4..8]) {
                    let src = assemble(&k, p, &elem);
                    if let Err(e) = validate_wgsl(&src) {
                        panic!("{} ({}, {d}D) does not validate:\n{e}", k.label, p.name());
                    }
                }
            }
        }
    }

    #[test]
    fn phys_of_follows_the_slot_ranges() {
        let f = phys_of(&[0..4, 4..10, 10..12]);
        assert!(f.contains("if s < 4u { return 0u; }"), "{f}");
        assert!(f.contains("if s < 10u { return 1u; }"), "{f}");
        assert!(f.contains("return 2u;"), "{f}");
        assert!(!f.contains("12u"), "{f}");
    }
}
