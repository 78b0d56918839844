//! The bytes an agent's stage touches in the in-process engine (issue 11
//! item 5; BENCHMARKS.md "In-process engine at scale (session 7)"): from
//! 10⁴ agents on the engine is bound by memory traffic, so these sizes are
//! the working set per agent. Printed (`-- --nocapture`) and held to their
//! present values, so a change that grows them is seen.

use attitude::agent::Agent;
use attitude::integrate::Stages;
use attitude::network::{AgentModel, AgentState, Exchanged};
use std::mem::size_of;

#[test]
fn an_agents_working_set_does_not_grow() {
    let sizes = [
        ("Agent (inline)", size_of::<Agent>(), 1408),
        // 528 B before issue 35: + two boxed pointers (the timeline, the
        // body's effects); the Agent did not grow (it no longer keeps `dt`
        // beside its integrator's; the stage-0 torque it now keeps took the
        // bytes its verdicts' and refusal counters' representations gave up).
        ("AgentModel (in Agent)", size_of::<AgentModel>(), 544),
        (
            "AgentState (step start, stage point)",
            size_of::<AgentState>(),
            216,
        ),
        (
            "Stages<2, 3> (RKMK4 bookkeeping)",
            size_of::<Stages<2, 3>>(),
            256,
        ),
        ("Exchanged (a published value)", size_of::<Exchanged>(), 120),
    ];
    for (name, size, most) in sizes {
        println!("{name}: {size} B");
        assert!(size <= most, "{name} grew to {size} B (was {most} B)");
    }
}
