//! `name`, `[simulation]` and `[output]`: the results directory's name, the
//! time step, the horizon and the exchange schedule, in steps.

use super::ctx::Ctx;
use crate::schema::{CouplingKind, Output, Simulation};
use attitude::network::Coupling;

/// The time grid of a run; `None` where the field was invalid.
pub(super) struct Timing {
    /// Integrator step, s (checked, but kept even if invalid).
    pub(super) dt: f64,
    /// Steps of the horizon.
    pub(super) steps: Option<u64>,
    /// Steps between rows of `errors.csv`.
    pub(super) sample_every: Option<u64>,
    /// Exchange semantics.
    pub(super) coupling: Option<Coupling>,
}

/// `name` must be usable as a directory name.
pub(super) fn name(c: &mut Ctx, name: Option<&String>) {
    let Some(name) = name else { return };
    let mut parts = std::path::Path::new(name).components();
    let plain = matches!(
        (parts.next(), parts.next()),
        (Some(std::path::Component::Normal(_)), None)
    );
    if !plain || name.contains(['/', '\\']) {
        c.err(
            "name",
            format!("{name:?} must be a plain directory name (no separators, not . or ..): it names the results directory"),
        );
    }
}

/// `[simulation]` and `[output]` in steps of `simulation.dt`.
pub(super) fn simulation(c: &mut Ctx, sim: &Simulation, out: &Output) -> Timing {
    let dt = sim.dt;
    if c.finite("simulation.dt", dt) && dt <= 0.0 {
        c.err("simulation.dt", format!("must be > 0, got {dt}"));
    }
    let steps = c.multiple_of_dt("simulation.duration", sim.duration, dt);
    let sample_every = c.multiple_of_dt("output.sample_period", out.sample_period, dt);
    let coupling = match (sim.coupling, sim.period) {
        (CouplingKind::Continuous, None) => Some(Coupling::Continuous),
        (CouplingKind::Continuous, Some(_)) => {
            c.err(
                "simulation.period",
                "is only used with coupling = \"sampled\"",
            );
            None
        }
        (CouplingKind::Sampled, None) => {
            c.err(
                "simulation.period",
                "is required with coupling = \"sampled\"",
            );
            None
        }
        (CouplingKind::Sampled, Some(p)) => c
            .multiple_of_dt("simulation.period", p, dt)
            .map(|every| Coupling::Sampled { every }),
    };
    Timing {
        dt,
        steps,
        sample_every,
        coupling,
    }
}
