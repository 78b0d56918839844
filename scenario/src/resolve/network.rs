//! `[network]` and `[[network.link]]`: the impairments of every directed
//! link, in steps of `simulation.dt`.

use super::ctx::Ctx;
use super::graph::{Edges, LeaderLinks};
use super::ids::Ids;
use crate::schema::{LossSpec, NetworkSpec};
use attitude::link::{LinkModel, Loss, link_seed};
use std::collections::{BTreeMap, BTreeSet};

/// Impairments of every directed link (sender, receiver) that has any.
pub(super) fn network(
    c: &mut Ctx,
    net: &NetworkSpec,
    dt: f64,
    edges: &Edges,
    links: &LeaderLinks,
    ids: &Ids,
) -> BTreeMap<(u32, u32), LinkModel> {
    let defaults = Impairments::read(
        c,
        "network",
        net.delay,
        net.jitter,
        net.loss.as_ref(),
        net.period,
        dt,
    );
    if net.links.is_empty() && !defaults.model(None, 0).is_impaired() {
        return BTreeMap::new(); // no link has an impairment: none to list
    }
    let mut directed: BTreeSet<(u32, u32)> = BTreeSet::new();
    for &(a, b) in &edges.pairs {
        directed.insert((a, b));
        directed.insert((b, a));
    }
    directed.extend(edges.arcs.iter().copied());
    for r in links.linked() {
        directed.insert((0, ids.id(r)));
    }
    let overrides = overrides(c, net, dt, &directed);
    let mut out = BTreeMap::new();
    for &(from, to) in &directed {
        let o = overrides.get(&(from, to)).map(|(_, i)| i);
        let model = defaults.model(o, link_seed(net.seed, from, to));
        if model.is_impaired() {
            out.insert((from, to), model);
        }
    }
    out
}

/// `[[network.link]]`: per-link overrides, by (sender, receiver), with
/// their index.
fn overrides(
    c: &mut Ctx,
    net: &NetworkSpec,
    dt: f64,
    directed: &BTreeSet<(u32, u32)>,
) -> BTreeMap<(u32, u32), (usize, Impairments)> {
    let mut overrides = BTreeMap::new();
    for (k, l) in net.links.iter().enumerate() {
        let f = format!("network.link[{k}]");
        if !directed.contains(&(l.from, l.to)) {
            c.err(
                f.clone(),
                format!("{} → {} is not a link of this network (follower edges go both ways, one-way edges from → to; the leader is 0 and only sends to its leader_link agents)", l.from, l.to),
            );
            continue;
        }
        let imp = Impairments::read(c, &f, l.delay, l.jitter, l.loss.as_ref(), l.period, dt);
        if let Some((first, _)) = overrides.insert((l.from, l.to), (k, imp)) {
            c.err(
                f,
                format!(
                    "duplicate override of link {} → {} (also network.link[{first}])",
                    l.from, l.to
                ),
            );
        }
    }
    overrides
}

/// Impairments as read from one table, in steps.
#[derive(Debug, Clone, Copy, Default)]
struct Impairments {
    delay: Option<u64>,
    jitter: Option<u64>,
    loss: Option<Loss>,
    period: Option<u64>,
}

impl Impairments {
    /// The link model of these defaults with the override `o`, if any.
    fn model(&self, o: Option<&Impairments>, seed: u64) -> LinkModel {
        let pick = |f: fn(&Impairments) -> Option<u64>| o.and_then(f).or_else(|| f(self));
        LinkModel {
            delay: pick(|i| i.delay).unwrap_or(0),
            jitter: pick(|i| i.jitter).unwrap_or(0),
            loss: o.and_then(|i| i.loss).or(self.loss).unwrap_or(Loss::None),
            period: pick(|i| i.period),
            seed,
        }
    }

    fn read(
        c: &mut Ctx,
        f: &str,
        delay: Option<f64>,
        jitter: Option<f64>,
        loss: Option<&LossSpec>,
        period: Option<f64>,
        dt: f64,
    ) -> Self {
        let steps = |c: &mut Ctx, name: &str, x: Option<f64>, zero_ok: bool| -> Option<u64> {
            let x = x?;
            let field = format!("{f}.{name}");
            if zero_ok && x == 0.0 {
                return Some(0);
            }
            c.multiple_of_dt(&field, x, dt)
        };
        let loss = loss.map(|l| read_loss(c, f, l));
        Self {
            delay: steps(c, "delay", delay, true),
            jitter: steps(c, "jitter", jitter, true),
            loss,
            period: steps(c, "period", period, false),
        }
    }
}

/// `{f}.loss`: a probability or a loss model table.
fn read_loss(c: &mut Ctx, f: &str, l: &LossSpec) -> Loss {
    let prob = |c: &mut Ctx, field: String, p: f64| -> f64 {
        if !(0.0..=1.0).contains(&p) {
            c.err(field, format!("must be a probability in [0, 1], got {p}"));
        }
        p
    };
    match l {
        LossSpec::Probability(p) => Loss::Bernoulli {
            p: prob(c, format!("{f}.loss"), *p),
        },
        LossSpec::Model(m) => match m.model.as_str() {
            "bernoulli" => Loss::Bernoulli {
                p: prob(c, format!("{f}.loss.p"), m.p.unwrap_or(0.0)),
            },
            "gilbert-elliott" => {
                let mut g = |name: &str, v: Option<f64>, default: Option<f64>| match v.or(default) {
                    Some(v) => prob(c, format!("{f}.loss.{name}"), v),
                    None => {
                        c.err(
                            format!("{f}.loss.{name}"),
                            "is required by the Gilbert–Elliott model",
                        );
                        0.0
                    }
                };
                Loss::GilbertElliott {
                    p_gb: g("p_gb", m.p_gb, None),
                    p_bg: g("p_bg", m.p_bg, None),
                    loss_good: g("loss_good", m.loss_good, Some(0.0)),
                    loss_bad: g("loss_bad", m.loss_bad, Some(1.0)),
                }
            }
            other => {
                c.err(
                    format!("{f}.loss.model"),
                    format!("unknown loss model {other:?} (bernoulli, gilbert-elliott)"),
                );
                Loss::None
            }
        },
    }
}
