//! `wrong_sign_agent --config FILE`: the built-in attsync agent with the sign
//! of one gain of its law flipped, a fixture for rule `law` of
//! `attsync conform` (PROTOCOL.md § 12). It speaks the protocol perfectly
//! (it runs `attsync_agent::run`), so it passes the nine protocol rules, but
//! its control law uses `−k_R` where the paper has `k_R` (`scheme.control.k_r`,
//! in every scheme), which only `law` can see.

use attitude::network::Scheme;
use attsync_agent::args::node_main;
use msgs::config::{NodeConfig, Role};
use std::process::ExitCode;
use std::sync::atomic::AtomicBool;

/// `cfg` with the attitude gain of the control law negated.
fn wrong_sign(cfg: &NodeConfig) -> NodeConfig {
    let mut cfg = cfg.clone();
    if let Role::Agent { model, .. } = &mut cfg.role {
        match &mut model.scheme {
            Scheme::ObserverTimeVarying { control, .. }
            | Scheme::ObserverConstant { control, .. }
            | Scheme::Observerless { control } => control.k_r = -control.k_r,
        }
    }
    cfg
}

fn main() -> ExitCode {
    node_main(
        "wrong_sign_agent",
        |cfg| format!("agent_{}", cfg.id),
        |node, cfg| {
            Ok(attsync_agent::run(
                node,
                &wrong_sign(cfg),
                &AtomicBool::new(false),
            )?)
        },
    )
}
