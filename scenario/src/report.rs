//! The text `attsync check` prints.

use super::Loaded;
use super::resolve::kind_name;
use attitude::control::ControlLaw;
use attitude::network::Coupling;
use attitude::stiffness::Estimate;
use std::fmt::Write as _;

/// A human-readable description of a validated scenario.
#[must_use]
pub fn describe(l: &Loaded) -> String {
    let r = &l.resolved;
    let n = &r.network;
    // ~70 bytes per agent line and ~14 per edge: one allocation.
    let mut s = String::with_capacity(4096 + 90 * n.agents.len());
    let _ = writeln!(s, "{}: OK", l.file.display());
    let _ = writeln!(s, "name:      {}", l.name());
    let _ = writeln!(s, "scheme:    {}", kind_name(l.scenario.scheme.kind));
    let _ = writeln!(s, "law:       {}", law(l.scenario.scheme.law));
    let coupling = match n.coupling {
        Coupling::Continuous => "continuous (exchange at every stage)".to_string(),
        Coupling::Sampled { every } => {
            format!("sampled every {every} steps ({} s)", every as f64 * n.dt)
        }
    };
    let _ = writeln!(
        s,
        "time:      dt = {} s, {} steps, duration {} s, coupling {coupling}",
        n.dt,
        n.steps,
        n.steps as f64 * n.dt
    );
    let _ = writeln!(s, "agents:    {}", n.agents.len());
    agents(&mut s, n);
    let both = r.edges.iter().map(|(a, b)| format!("{a}–{b}"));
    let one_way = r.arcs.iter().map(|(a, b)| format!("{a}→{b}"));
    let _ = write!(
        s,
        "edges:     {}",
        both.chain(one_way).collect::<Vec<_>>().join(", ")
    );
    s.push_str("\nleader:    ");
    for (k, a) in r.leader_links.iter().enumerate() {
        let sep = if k == 0 { "" } else { ", " };
        let _ = write!(s, "{sep}0→{a}");
    }
    s.push('\n');
    if !r.outside_theory.is_empty() {
        s.push_str("outside the theory ([graph] assumptions = \"off\"):\n");
        for d in &r.outside_theory {
            let _ = writeln!(s, "  - {d}: {}", d.lost());
        }
    }
    bodies(&mut s, n);
    if !r.events.is_empty() {
        s.push_str("events:\n");
        for e in &r.events {
            let _ = writeln!(s, "  - {e}");
        }
    }
    let (lo, hi) = r.spectrum_extremes;
    let _ = writeln!(
        s,
        "spectrum of Ξ + LLᵀ: {} eigenvalues in [{lo:.6e}, {hi:.6e}]",
        n.agents.len()
    );
    if !r.spectrum.is_empty() {
        let spec: Vec<String> = r.spectrum.iter().map(|e| format!("{e:.6}")).collect();
        let _ = writeln!(s, "spectrum of Ξ + LLᵀ: [{}]", spec.join(", "));
    }
    if let Some(m) = r.appendix_d_min_eig {
        let _ = writeln!(
            s,
            "gain condition (Appendix D, F > 0): {} (λmin(F) = {m:.6e})",
            if m > 0.0 { "holds" } else { "FAILS" }
        );
    }
    if let Some(e) = &r.stiffness {
        stiffness(&mut s, e, n.dt);
    }
    for w in &r.warnings {
        let _ = writeln!(s, "warning: {w}");
    }
    s
}

/// One line per agent: id, the diagonal of `J`, neighbours, `+ leader`.
fn agents(s: &mut String, n: &attitude::network::Network) {
    for a in &n.agents {
        let (m, j) = (&a.model, &a.model.inertia.j);
        let _ = write!(
            s,
            "  agent {:>3}  J diag [{:?}, {:?}, {:?}]  neighbours [",
            m.id,
            j[(0, 0)],
            j[(1, 1)],
            j[(2, 2)]
        );
        for (k, x) in m.neighbours.iter().enumerate() {
            let sep = if k == 0 { "" } else { ", " };
            let _ = write!(s, "{sep}{}", x.id);
        }
        let leader = if m.leader_gain.is_some() {
            "  + leader"
        } else {
            ""
        };
        let _ = writeln!(s, "]{leader}");
    }
}

/// The bodies that aren't ideal, grouped by what they have:
/// `bodies:` then `  - agents 1, 2: torque ≤ 2 N·m; …` (nothing when
/// every body is ideal).
fn bodies(s: &mut String, n: &attitude::network::Network) {
    let mut groups: Vec<(String, Vec<u32>)> = Vec::new();
    for a in &n.agents {
        let Some(e) = a.model.effects.as_deref() else {
            continue;
        };
        let text = crate::body::describe(e);
        match groups.iter_mut().find(|(t, _)| *t == text) {
            Some((_, ids)) => ids.push(a.model.id),
            None => groups.push((text, vec![a.model.id])),
        }
    }
    if groups.is_empty() {
        return;
    }
    s.push_str("bodies:\n");
    for (text, ids) in groups {
        let noun = if ids.len() == 1 { "agent" } else { "agents" };
        let ids: Vec<String> = ids.iter().map(u32::to_string).collect();
        let _ = writeln!(s, "  - {noun} {}: {text}", ids.join(", "));
    }
}

/// The step-size estimate (`docs/stiffness.md`): per loop its fastest linear
/// mode and largest stable RK4 step, then the scenario's and its margin, and
/// the slowest error mode (how long the run needs to converge).
fn stiffness(s: &mut String, e: &Estimate, dt: f64) {
    let _ = writeln!(
        s,
        "step size (RK4 on the linearised loops, docs/stiffness.md):"
    );
    for l in &e.loops {
        let _ = writeln!(
            s,
            "  {:<12} fastest mode {:.3e} s⁻¹  largest stable dt {}",
            l.name,
            l.fastest_rate,
            seconds(l.dt_max)
        );
    }
    let _ = writeln!(
        s,
        "  largest stable dt {} for dt = {dt} s: margin dt_max/dt = {:.3}",
        seconds(e.dt_max),
        e.dt_max / dt
    );
    if let Some(l) = e.slowest() {
        let _ = writeln!(
            s,
            "  slowest mode {:.3e} s⁻¹ ({} loop): ln(1e6)/rate = {:.1} s to decay by 1e6",
            l.slowest_rate,
            l.name,
            1e6f64.ln() / l.slowest_rate
        );
    }
}

fn seconds(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.3e} s")
    } else {
        "unlimited".into()
    }
}

/// `scheme.law` as `check` shows it.
fn law(law: ControlLaw) -> String {
    match law {
        ControlLaw::Corrected => "corrected".into(),
        ControlLaw::AsPrinted => {
            "as-printed (the paper's printed Σᵢ, Γᵢ, known wrong: a negative control)".into()
        }
    }
}
