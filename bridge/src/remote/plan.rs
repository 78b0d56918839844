//! Which host runs which node ([`Plan`], from HOSTS.toml's placement), and
//! the state links between machines ([`links`]): one per sender and
//! machine of its receivers, so that a state crosses to a machine once.

use super::Side;
use super::wire::StateLink;
use attitude::agent::Agent;
use msgs::config::{NodeConfig, Role};
use std::collections::BTreeMap;

/// A host and the nodes placed on it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlannedHost {
    /// Its name.
    pub name: String,
    /// Its daemon's endpoint (`tcp/…`).
    pub endpoint: String,
    /// Node ids placed on it (0: the leader).
    pub nodes: Vec<u32>,
}

/// Every host of a run; nodes on none run on the orchestrator's machine.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Plan {
    /// The hosts.
    pub hosts: Vec<PlannedHost>,
    /// How the orchestrator's links to them are secured.
    pub security: crate::trust::Security,
}

impl Plan {
    /// The hosts of `p` (HOSTS.toml placed on a network) and their nodes,
    /// reached as `security` says.
    #[must_use]
    pub fn of(p: &crate::hosts::Placement, security: crate::trust::Security) -> Self {
        let hosts = (p.hosts().iter().enumerate())
            .map(|(i, h)| PlannedHost {
                name: h.name.clone(),
                endpoint: h.endpoint.clone(),
                nodes: p.nodes_on(i).to_vec(),
            })
            .collect();
        Self { hosts, security }
    }

    /// Where node `id` runs.
    #[must_use]
    pub fn side_of(&self, id: u32) -> Side {
        (self.hosts.iter())
            .find(|h| h.nodes.contains(&id))
            .map_or(Side::Orchestrator, |h| Side::Host(h.name.clone()))
    }
}

/// The state links of `configs` placed by `plan`: for each sender, one per
/// other machine with receivers of it (receivers ascending).
#[must_use]
pub fn links(configs: &[NodeConfig], plan: &Plan) -> Vec<StateLink> {
    let mut by: BTreeMap<(u32, Side), (Vec<u32>, u64)> = BTreeMap::new();
    for c in configs {
        let to = plan.side_of(c.id);
        for (&from, ahead) in c.inputs.iter().zip(lookahead(c)) {
            if plan.side_of(from) != to {
                let (receivers, least) = by.entry((from, to.clone())).or_insert((vec![], ahead));
                receivers.push(c.id);
                *least = (*least).min(ahead);
            }
        }
    }
    (by.into_iter())
        .map(|((from, to_side), (mut receivers, ahead))| {
            receivers.sort_unstable();
            StateLink {
                from,
                from_side: plan.side_of(from),
                to_side,
                receivers,
                ahead,
            }
        })
        .collect()
}

/// How many steps ahead each input of `c` may be taken, as its node
/// computes it (`Agent::lookahead`); 0 for the leader's none and for a
/// process that takes over from a crashed one.
fn lookahead(c: &NodeConfig) -> Vec<u64> {
    match &c.role {
        Role::Agent { model, initial } if c.resume.is_none() => {
            let a = Agent::new((**model).clone(), *initial, c.dt);
            (0..c.inputs.len()).map(|k| a.lookahead(k)).collect()
        }
        _ => vec![0; c.inputs.len()],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(id: u32, inputs: Vec<u32>) -> NodeConfig {
        let mut c: NodeConfig = serde_json::from_str(SAMPLE).expect("sample");
        c.id = id;
        c.inputs = inputs;
        c
    }

    const SAMPLE: &str = include_str!("sample_config.json");

    #[test]
    fn a_state_crosses_once_per_machine_of_its_receivers() {
        // Leader 0 → 1, 2; 1 ↔ 2; 2 ↔ 3. Host a: {2, 3}; the rest local.
        let configs = vec![
            config(0, vec![]),
            config(1, vec![2, 0]),
            config(2, vec![1, 3, 0]),
            config(3, vec![2]),
        ];
        let plan = Plan {
            hosts: vec![PlannedHost {
                name: "a".into(),
                endpoint: "tcp/127.0.0.1:1".into(),
                nodes: vec![2, 3],
            }],
            security: crate::trust::Security::Insecure,
        };
        let a = Side::Host("a".into());
        let got: Vec<(u32, Side, Vec<u32>)> = links(&configs, &plan)
            .into_iter()
            .map(|l| (l.from, l.to_side, l.receivers))
            .collect();
        assert_eq!(
            got,
            vec![
                (0, a.clone(), vec![2]),
                (1, a, vec![2]),
                (2, Side::Orchestrator, vec![1]),
            ]
        );
    }
}
