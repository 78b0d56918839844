//! The link model (`attitude::link`) and agents stepping through impaired
//! links (`attitude::agent`, `attitude::engine`).
//!
//! What is checked, against expectations computed independently of the
//! link's code (plain `Vec`s of what the sender published, counts and
//! textbook probabilities):
//! - constant delay of k steps: at slot (n, s) the receiver holds exactly the
//!   sender's stage-s message of step n − k, and the sender's initial state
//!   before that (bit-identical); a whole network run by the in-process
//!   engine equals, bit for bit, a hand-written method-of-steps run in which
//!   the test itself feeds each agent the sender's recorded stage states of
//!   step n − k over *ideal* links (for both an observer scheme and the
//!   observerless scheme, with different delays per link);
//! - the per-link period carries only the stage-0 messages of steps
//!   m with m % p == 0 (link level and network level);
//! - loss: a lost message leaves the held value unchanged; the same seed
//!   gives the same delivery pattern and counters, a different seed a
//!   different one; the Bernoulli loss rate is within 6 standard deviations
//!   of p and consecutive losses are independent; Gilbert–Elliott losses come
//!   in bursts of mean length 1/p_bg (again within 6 standard errors, with
//!   the Markov chain's variance);
//! - jitter: the held stamp never goes backwards although late messages do
//!   arrive after newer ones (they are counted and must be refused).
//!
//! Every random quantity is drawn from seeded streams, so the outcome is
//! deterministic; the bounds are nevertheless chosen at 6σ so that they hold
//! for any correct implementation and any seed.

use attitude::body::Inertia;
use attitude::control::ControlGains;
use attitude::engine::InProcess;
use attitude::link::{Link, LinkModel, LinkStats, Loss, link_seed};
use attitude::network::{
    AgentModel, AgentSpec, AgentState, Coupling, Exchanged, Neighbour, Network, Scheme,
};
use attitude::observer::ObserverGains;
use attitude::reference::{Leader, LeaderState};
use attitude::so3::rot;
use nalgebra::{Matrix3, Vector3};

const DT: f64 = 0.001;

// ------------------------------------------------------------ link level

/// A message that carries its own stamp, so what the receiver holds tells
/// which message it is.
fn tagged(m: u64, s: u32) -> Exchanged {
    Exchanged {
        r: Matrix3::identity(),
        w: Vector3::new(m as f64, f64::from(s), 0.0),
        s: Vector3::new(0.0, 0.0, 1.0),
    }
}

/// The stamp carried by a [`tagged`] message.
fn stamp_of(x: &Exchanged) -> (u64, u32) {
    (x.w[0] as u64, x.w[1] as u32)
}

fn model(delay: u64, jitter: u64, loss: Loss, period: Option<u64>, seed: u64) -> LinkModel {
    LinkModel {
        delay,
        jitter,
        loss,
        period,
        seed,
    }
}

/// What happened at one slot: how many messages the link delivered there,
/// and the value the receiver uses.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Slot {
    n: u64,
    s: u32,
    delivered: u64,
    held: Exchanged,
}

/// Drives `link` in lockstep for `steps` steps: at every slot the sender
/// offers its message (stamped and tagged with the slot), then the receiver
/// asks for the value it uses (as `Agent` does).
fn drive(link: &mut Link, steps: u64) -> Vec<Slot> {
    let mut out = Vec::with_capacity(4 * steps as usize);
    for n in 0..steps {
        for s in 0..4 {
            link.offer(n, s, tagged(n, s));
            let before = link.stats().delivered;
            let held = link
                .value_at(n, s, DT)
                .expect("something is held after the first offer");
            out.push(Slot {
                n,
                s,
                delivered: link.stats().delivered - before,
                held,
            });
        }
    }
    out
}

/// Loss pattern (true = lost) of a zero-delay link, one entry per message.
fn loss_pattern(loss: Loss, seed: u64, steps: u64) -> (Vec<bool>, LinkStats) {
    let mut link = Link::new(model(0, 0, loss, None, seed));
    let slots = drive(&mut link, steps);
    let pattern = slots
        .iter()
        .map(|x| {
            assert!(x.delivered <= 1, "zero delay: at most this slot's message");
            x.delivered == 0
        })
        .collect();
    (pattern, link.stats())
}

/// Lengths of the maximal runs of `true`.
fn bursts(pattern: &[bool]) -> Vec<usize> {
    let mut out = Vec::new();
    let mut run = 0;
    for &lost in pattern {
        if lost {
            run += 1;
        } else if run > 0 {
            out.push(run);
            run = 0;
        }
    }
    if run > 0 {
        out.push(run);
    }
    out
}

#[test]
fn impaired_only_when_something_is_set() {
    assert!(!model(0, 0, Loss::None, None, 7).is_impaired());
    assert!(model(1, 0, Loss::None, None, 0).is_impaired());
    assert!(model(0, 1, Loss::None, None, 0).is_impaired());
    assert!(model(0, 0, Loss::Bernoulli { p: 0.0 }, None, 0).is_impaired());
    assert!(model(0, 0, Loss::None, Some(1), 0).is_impaired());
}

#[test]
fn constant_delay_holds_stage_s_of_step_n_minus_k() {
    let steps = 50;
    for k in [0u64, 1, 2, 5, 13] {
        let mut link = Link::new(model(k, 0, Loss::None, None, 1));
        let slots = drive(&mut link, steps);
        for x in &slots {
            let expected = if x.n >= k {
                tagged(x.n - k, x.s)
            } else {
                tagged(0, 0) // the sender's initial state
            };
            assert_eq!(x.held, expected, "k = {k}, slot ({}, {})", x.n, x.s);
            // Exactly one message arrives per slot once the pipe is full.
            assert_eq!(
                x.delivered,
                u64::from(x.n >= k),
                "k = {k}, slot ({}, {})",
                x.n,
                x.s
            );
        }
        let st = link.stats();
        assert_eq!(st.sent, 4 * steps, "k = {k}");
        assert_eq!(st.delivered, 4 * (steps - k), "k = {k}");
        assert_eq!(st.lost, 0, "k = {k}");
        assert_eq!(st.evaluations, 4 * steps, "k = {k}");
        // Age of information: k·dt once delayed messages arrive; before that
        // the age of the initial state, t_stage − 0, which peaks at k·dt too.
        let kdt = k as f64 * DT;
        assert!((st.age_max - kdt).abs() < 1e-12, "k = {k}: {st:?}");
        let mut sum = 0.0;
        for n in 0..steps {
            for c in [0.0, 0.5, 0.5, 1.0] {
                sum += if n >= k { kdt } else { (n as f64 + c) * DT };
            }
        }
        assert!((st.age_sum - sum).abs() < 1e-9, "k = {k}: {st:?} vs {sum}");
    }
}

#[test]
fn period_carries_only_stage_zero_of_every_pth_step() {
    let steps = 60;
    for (p, k) in [(1u64, 0u64), (4, 0), (5, 3), (3, 7)] {
        let mut link = Link::new(model(k, 0, Loss::None, Some(p), 9));
        let slots = drive(&mut link, steps);
        for x in &slots {
            // Largest m ≤ n − k with m % p == 0, its stage-0 message.
            let expected = if x.n >= k {
                tagged((x.n - k) / p * p, 0)
            } else {
                tagged(0, 0)
            };
            assert_eq!(
                x.held, expected,
                "p = {p}, k = {k}, slot ({}, {})",
                x.n, x.s
            );
            let arrives = x.s == 0 && x.n >= k && (x.n - k) % p == 0;
            assert_eq!(x.delivered, u64::from(arrives), "p = {p}, k = {k}");
        }
        let carried = (0..steps).filter(|m| m % p == 0).count() as u64;
        let st = link.stats();
        assert_eq!(st.sent, carried, "p = {p}: only (m, 0) with m % p == 0");
        assert_eq!(st.lost, 0);
        assert_eq!(
            st.delivered,
            (0..steps.saturating_sub(k)).filter(|m| m % p == 0).count() as u64
        );
    }
}

#[test]
fn lost_message_keeps_the_last_value() {
    for k in [0u64, 3] {
        let mut link = Link::new(model(k, 0, Loss::Bernoulli { p: 0.4 }, None, 42));
        let slots = drive(&mut link, 2000);
        let (mut kept, mut replaced) = (0, 0);
        for w in slots.windows(2) {
            let (prev, x) = (w[0], w[1]);
            if x.n < k {
                continue;
            }
            match x.delivered {
                // The message stamped (n − k, s) arrived: it is the freshest.
                1 => {
                    assert_eq!(x.held, tagged(x.n - k, x.s), "slot ({}, {})", x.n, x.s);
                    replaced += 1;
                }
                // It was lost: the receiver keeps what it had.
                0 => {
                    assert_eq!(x.held, prev.held, "slot ({}, {})", x.n, x.s);
                    kept += 1;
                }
                d => panic!("{d} messages delivered at one slot with a constant delay"),
            }
        }
        assert!(
            kept > 1000 && replaced > 1000,
            "{kept} kept, {replaced} replaced"
        );
        let st = link.stats();
        assert_eq!(st.sent, 8000);
        // Lost messages are counted when offered; at most the last k steps'
        // messages are still on their way at the end.
        assert!(st.lost + st.delivered <= st.sent, "k = {k}: {st:?}");
        assert!(st.lost + st.delivered >= st.sent - 4 * k, "k = {k}: {st:?}");
    }
}

#[test]
fn same_seed_same_pattern_other_seed_other_pattern() {
    let losses = [
        Loss::Bernoulli { p: 0.2 },
        Loss::GilbertElliott {
            p_gb: 0.05,
            p_bg: 0.3,
            loss_good: 0.02,
            loss_bad: 0.9,
        },
    ];
    for loss in losses {
        let (a, sa) = loss_pattern(loss, 1234, 1000);
        let (b, sb) = loss_pattern(loss, 1234, 1000);
        let (c, sc) = loss_pattern(loss, 1235, 1000);
        assert_eq!(a, b, "{loss:?}: same seed, same pattern");
        assert_eq!(sa, sb, "{loss:?}: same seed, same counters");
        assert!(a.iter().any(|&l| l), "{loss:?}: something is lost");
        assert_ne!(a, c, "{loss:?}: another seed, another pattern");
        assert_ne!(sa.lost, 0);
        assert_eq!(sc.sent, sa.sent);
    }
    // Jitter is drawn from the same stream: the sequence of held values too.
    let held = |seed| {
        let mut link = Link::new(model(2, 4, Loss::Bernoulli { p: 0.1 }, None, seed));
        let v: Vec<(u64, u32)> = drive(&mut link, 500)
            .iter()
            .map(|x| stamp_of(&x.held))
            .collect();
        (v, link.stats())
    };
    assert_eq!(held(77), held(77));
    assert_ne!(held(77).0, held(78).0);
}

#[test]
fn link_seeds_differ_per_direction_and_streams_are_independent() {
    let seed = 2024;
    let (s12, s21, s13) = (
        link_seed(seed, 1, 2),
        link_seed(seed, 2, 1),
        link_seed(seed, 1, 3),
    );
    assert_ne!(s12, s21);
    assert_ne!(s12, s13);
    assert_ne!(s21, s13);
    assert_eq!(s12, link_seed(seed, 1, 2), "a function of its arguments");
    assert_ne!(s12, link_seed(seed + 1, 1, 2));
    // Two links of one scenario lose independently: they agree on a message
    // with probability p² + (1 − p)².
    let p = 0.3;
    let steps = 25_000;
    let (a, _) = loss_pattern(Loss::Bernoulli { p }, s12, steps);
    let (b, _) = loss_pattern(Loss::Bernoulli { p }, s21, steps);
    let n = a.len() as f64;
    let q = p * p + (1.0 - p) * (1.0 - p);
    let agree = a.iter().zip(&b).filter(|(x, y)| x == y).count() as f64;
    let sd = (n * q * (1.0 - q)).sqrt();
    assert!(
        (agree - n * q).abs() < 6.0 * sd,
        "agreement {agree} vs expected {} ± {}",
        n * q,
        6.0 * sd
    );
}

#[test]
fn bernoulli_loss_rate_and_independence() {
    let steps = 50_000; // 200 000 messages
    for (p, seed) in [(0.05, 1u64), (0.3, 2), (0.7, 3), (0.0, 4), (1.0, 5)] {
        let (lost, st) = loss_pattern(Loss::Bernoulli { p }, seed, steps);
        let n = lost.len() as f64;
        let k = lost.iter().filter(|&&l| l).count() as f64;
        assert_eq!(st.lost as f64, k, "p = {p}");
        assert_eq!(st.sent as f64, n);
        assert_eq!(st.delivered + st.lost, st.sent);
        let sd = (n * p * (1.0 - p)).sqrt();
        assert!(
            (k - n * p).abs() <= 6.0 * sd,
            "p = {p}: {k} lost of {n}, expected {} ± {}",
            n * p,
            6.0 * sd
        );
        // Pairs of consecutive losses: expected (n − 1) p²; the indicators of
        // overlapping pairs are 1-dependent, so
        // Var = (n−1) q(1−q) + 2 (n−2) (p³ − p⁴) with q = p².
        let pairs = lost.windows(2).filter(|w| w[0] && w[1]).count() as f64;
        let q = p * p;
        let var = (n - 1.0) * q * (1.0 - q) + 2.0 * (n - 2.0) * (p.powi(3) - p.powi(4));
        assert!(
            (pairs - (n - 1.0) * q).abs() <= 6.0 * var.sqrt(),
            "p = {p}: {pairs} consecutive pairs, expected {} ± {}",
            (n - 1.0) * q,
            6.0 * var.sqrt()
        );
    }
}

#[test]
fn gilbert_elliott_loses_in_bursts_of_mean_length_one_over_p_bg() {
    let steps = 50_000; // 200 000 messages
    for (p_gb, p_bg, seed) in [(0.05, 0.25, 11u64), (0.01, 0.1, 12), (0.1, 0.5, 13)] {
        let loss = Loss::GilbertElliott {
            p_gb,
            p_bg,
            loss_good: 0.0,
            loss_bad: 1.0,
        };
        let (lost, _) = loss_pattern(loss, seed, steps);
        let n = lost.len() as f64;
        // Stationary fraction of the bad state; with loss_good = 0 and
        // loss_bad = 1 a message is lost iff the chain is bad.
        let pi_b = p_gb / (p_gb + p_bg);
        let lambda = 1.0 - p_gb - p_bg; // second eigenvalue of the chain
        let var_rate = pi_b * (1.0 - pi_b) * (1.0 + lambda) / (1.0 - lambda) / n;
        let rate = lost.iter().filter(|&&l| l).count() as f64 / n;
        assert!(
            (rate - pi_b).abs() <= 6.0 * var_rate.sqrt(),
            "p_gb {p_gb}, p_bg {p_bg}: loss rate {rate}, expected {pi_b} ± {}",
            6.0 * var_rate.sqrt()
        );
        // Sojourns in the bad state are geometric with mean 1/p_bg and
        // standard deviation √(1 − p_bg)/p_bg.
        let b = bursts(&lost);
        let mean = b.iter().sum::<usize>() as f64 / b.len() as f64;
        let se = (1.0 - p_bg).sqrt() / p_bg / (b.len() as f64).sqrt();
        assert!(
            (mean - 1.0 / p_bg).abs() <= 6.0 * se,
            "p_bg {p_bg}: mean burst {mean} over {} bursts, expected {} ± {}",
            b.len(),
            1.0 / p_bg,
            6.0 * se
        );
        // Bernoulli loss at the same rate has bursts of mean 1/(1 − rate),
        // far shorter: the bursts are the chain's, not chance.
        let (iid, _) = loss_pattern(Loss::Bernoulli { p: pi_b }, seed, steps);
        let bi = bursts(&iid);
        let mean_iid = bi.iter().sum::<usize>() as f64 / bi.len() as f64;
        assert!(
            mean_iid < 0.75 * mean,
            "Bernoulli bursts {mean_iid} vs Gilbert–Elliott {mean}"
        );
    }
}

#[test]
fn jitter_never_lets_an_older_message_replace_a_newer_one() {
    let steps = 5000;
    for (delay, jitter, seed) in [(0u64, 3u64, 5u64), (4, 6, 6), (1, 1, 7)] {
        let mut link = Link::new(model(delay, jitter, Loss::None, None, seed));
        let slots = drive(&mut link, steps);
        let mut refused_late = 0;
        let mut delayed_more = 0;
        let mut prev = (0u64, 0u32);
        for x in &slots {
            let held = stamp_of(&x.held);
            assert_eq!(x.held, tagged(held.0, held.1), "an unmodified message");
            assert!(
                held >= prev,
                "slot ({}, {}): held {held:?} after {prev:?}",
                x.n,
                x.s
            );
            // Never fresher than the constant delay allows; never staler than
            // delay + jitter (every message is delivered by then).
            if x.n >= delay {
                assert!(
                    held <= (x.n - delay, x.s),
                    "slot ({}, {}): {held:?}",
                    x.n,
                    x.s
                );
            }
            if x.n >= delay + jitter {
                assert!(
                    held >= (x.n - delay - jitter, x.s),
                    "slot ({}, {}): {held:?}",
                    x.n,
                    x.s
                );
                if held < (x.n - delay, x.s) {
                    delayed_more += 1;
                }
            }
            // Something arrived but the held stamp did not change: a late
            // message older than what the receiver already had.
            if x.delivered > 0 && held == prev && held != (0, 0) {
                refused_late += 1;
            }
            prev = held;
        }
        assert!(delayed_more > 0, "jitter {jitter} changed nothing");
        assert!(
            refused_late > 100,
            "jitter {jitter}: only {refused_late} late arrivals, the check is vacuous"
        );
        // Without loss every message is eventually delivered.
        let st = link.stats();
        assert_eq!(st.sent, 4 * steps);
        assert!(st.delivered >= 4 * (steps - delay - jitter), "{st:?}");
        assert!(st.age_max <= (delay + jitter) as f64 * DT + 1e-12, "{st:?}");
        assert!(st.age_max > delay as f64 * DT + 1e-12, "{st:?}");
    }
}

// ---------------------------------------------------------- network level

/// The leader of `docs/scenarios.md`'s example: a time-varying reference, so that what
/// the leader publishes changes at every stage.
fn leader() -> (Matrix3<f64>, LeaderState) {
    let c = std::f64::consts::FRAC_1_SQRT_2;
    let p = Matrix3::new(-1.0, 0.0, 0.0, 0.0, 0.0, -c, 0.0, c, 0.0);
    let state = LeaderState {
        r0: rot(
            0.8 * std::f64::consts::PI,
            &Vector3::new(1.0, 4.0, 2.0).normalize(),
        ),
        w0: Vector3::new(1.0, 2.0, 0.0),
        s0: Vector3::new(1.0, 1.0, 0.0),
    };
    (p, state)
}

fn scheme(observerless: bool) -> Scheme {
    if observerless {
        Scheme::Observerless {
            control: ControlGains { k_r: 1.9, k_w: 1.9 },
        }
    } else {
        Scheme::ObserverTimeVarying {
            observer: ObserverGains {
                k_r: 9.0,
                k_w: 14.0,
                k_sigma: 12.0,
            },
            control: ControlGains {
                k_r: 8.0,
                k_w: 13.0,
            },
        }
    }
}

fn diag(a: f64, b: f64, c: f64) -> Matrix3<f64> {
    Matrix3::from_diagonal(&Vector3::new(a, b, c))
}

/// Links of the test network: 0 → 1, 2 → 1, 1 → 2, 3 → 2 and 2 → 3.
#[derive(Debug, Clone, Copy)]
struct Links {
    l01: Option<LinkModel>,
    l21: Option<LinkModel>,
    l12: Option<LinkModel>,
    l32: Option<LinkModel>,
    l23: Option<LinkModel>,
}

impl Links {
    fn ideal() -> Self {
        Self {
            l01: None,
            l21: None,
            l12: None,
            l32: None,
            l23: None,
        }
    }
}

/// A chain leader → 1 — 2 — 3 (agent 1 hears the leader).
fn network(observerless: bool, links: Links, steps: u64) -> Network {
    let (p, l) = leader();
    let u = Vector3::new(1.0, 1.0, 0.0).normalize();
    let agent = |id: u32,
                 nbrs: Vec<Neighbour>,
                 lead: Option<(Matrix3<f64>, Option<LinkModel>)>|
     -> AgentSpec {
        let i = f64::from(id);
        let r = rot(i * std::f64::consts::PI / 10.0, &u);
        AgentSpec {
            model: AgentModel {
                id,
                inertia: Inertia::new(diag(i / 10.0, (i + 2.0) / 10.0, 2.0 * i / 10.0)),
                a_bar: diag(10.0 + i, 11.0 + i, 12.0 + i),
                neighbours: nbrs,
                leader_gain: lead.map(|x| x.0),
                leader_link: lead.and_then(|x| x.1),
                scheme: scheme(observerless),
                p,
                law: Default::default(),
                timeline: Default::default(),
                effects: None,
            },
            initial: AgentState {
                r,
                w: Vector3::new(i + 0.5, i, i + 1.0),
                r_hat: rot(-i * std::f64::consts::PI / 10.0, &u),
                w_hat: Vector3::new(1.0, 1.5, 2.0),
                s_hat: Vector3::new(2.0, 1.5, 1.0),
            },
        }
    };
    let nb = |id, a, link| Neighbour { id, a, link };
    let (a12, a23) = (diag(9.0, 8.0, 7.0), diag(8.0, 7.0, 6.0));
    Network {
        agents: vec![
            agent(
                1,
                vec![nb(2, a12, links.l21)],
                Some((diag(6.0, 7.0, 8.0), links.l01)),
            ),
            agent(2, vec![nb(1, a12, links.l12), nb(3, a23, links.l32)], None),
            agent(3, vec![nb(2, a23, links.l23)], None),
        ],
        p,
        leader: l,
        dt: DT,
        steps,
        coupling: Coupling::Continuous,
        sample_every: 1,
        guard: Default::default(),
        repoint: Vec::new(),
    }
}

/// Every agent's state at every step, as bit patterns.
type Trajectory = Vec<Vec<Vec<u64>>>;

/// States of every agent after every step, as bit patterns.
fn run_engine(net: &Network) -> (Trajectory, Vec<Vec<(u32, LinkStats)>>) {
    let mut engine = InProcess::new(net);
    let mut out = Vec::new();
    engine.run(|snap| {
        out.push(snap.agents.iter().map(bits).collect());
        true
    });
    let stats = engine.agents().iter().map(|a| a.link_stats()).collect();
    (out, stats)
}

fn bits(x: &AgentState) -> Vec<u64> {
    x.r.iter()
        .chain(x.w.iter())
        .chain(x.r_hat.iter())
        .chain(x.w_hat.iter())
        .chain(x.s_hat.iter())
        .map(|v| v.to_bits())
        .collect()
}

/// What a receiver uses at slot (n, s) of a link that only delays by whole
/// steps and carries every `period`-th step's stage 0: computed from the
/// sender's published history, nothing else.
fn delayed(
    hist: &[[Exchanged; 4]],
    n: u64,
    s: usize,
    delay: u64,
    period: Option<u64>,
) -> Exchanged {
    if n < delay {
        return hist[0][0]; // the sender's initial state
    }
    let m = n - delay;
    match period {
        None => hist[m as usize][s],
        Some(p) => hist[(m / p * p) as usize][0],
    }
}

fn delay_of(l: Option<LinkModel>) -> (u64, Option<u64>) {
    l.map_or((0, None), |l| (l.delay, l.period))
}

/// The method of steps by hand: every node over ideal links, the test
/// feeding each receiver the value its link should deliver, from plain
/// histories of what every node published at every stage.
fn method_of_steps(observerless: bool, links: Links, steps: u64) -> Trajectory {
    use attitude::agent::Agent;
    let net = network(observerless, Links::ideal(), steps);
    let mut lead = Leader::new(net.p, net.leader, DT);
    let mut agents: Vec<Agent> = net
        .agents
        .iter()
        .map(|a| Agent::new(a.model.clone(), a.initial, DT))
        .collect();
    let mut hist: Vec<Vec<[Exchanged; 4]>> = vec![Vec::new(); 4]; // leader, 1, 2, 3
    let mut out = vec![agents.iter().map(|a| bits(a.state())).collect()];
    for n in 0..steps {
        for h in &mut hist {
            h.push([Exchanged::identity(); 4]);
        }
        for s in 0..4 {
            hist[0][n as usize][s] = lead.stage_exchange();
            for (k, a) in agents.iter().enumerate() {
                hist[k + 1][n as usize][s] = a.stage_exchange();
            }
            let feed = |from: usize, l: Option<LinkModel>| {
                let (d, p) = delay_of(l);
                delayed(&hist[from], n, s, d, p)
            };
            let (x01, x21, x12, x32, x23) = (
                feed(0, links.l01),
                feed(2, links.l21),
                feed(1, links.l12),
                feed(3, links.l32),
                feed(2, links.l23),
            );
            agents[0].receive_neighbour(0, x21);
            agents[0].receive_leader(x01);
            agents[1].receive_neighbour(0, x12);
            agents[1].receive_neighbour(1, x32);
            agents[2].receive_neighbour(0, x23);
            lead.advance();
            for a in &mut agents {
                a.advance();
            }
        }
        out.push(agents.iter().map(|a| bits(a.state())).collect());
    }
    out
}

fn delay_link(delay: u64, period: Option<u64>) -> Option<LinkModel> {
    Some(model(delay, 0, Loss::None, period, 99))
}

#[test]
fn delayed_network_is_the_method_of_steps_bit_for_bit() {
    let steps = 400;
    let links = Links {
        l01: delay_link(5, None),
        l21: delay_link(3, None),
        l12: delay_link(1, None),
        l32: delay_link(7, None),
        l23: delay_link(2, None),
    };
    for observerless in [true, false] {
        let (got, stats) = run_engine(&network(observerless, links, steps));
        let want = method_of_steps(observerless, links, steps);
        assert_eq!(got.len(), want.len());
        for (n, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g, w, "observerless = {observerless}: step {n} differs");
        }
        // Not vacuous: the delays change the trajectory.
        let (ideal, _) = run_engine(&network(observerless, Links::ideal(), steps));
        assert_ne!(ideal.last(), got.last(), "the delays changed nothing");
        // And the hand-written feed of the ideal network is the ideal run.
        assert_eq!(ideal, method_of_steps(observerless, Links::ideal(), steps));
        // Counters: every stage's message is offered; all but the last k
        // steps' messages arrive; none is lost.
        let expect = [
            vec![(2u32, 3u64), (0, 5)],
            vec![(1, 1), (3, 7)],
            vec![(2, 2)],
        ];
        for (agent, (st, ex)) in stats.iter().zip(&expect).enumerate() {
            let got: Vec<(u32, u64, u64, u64)> = st
                .iter()
                .map(|(from, s)| (*from, s.sent, s.delivered, s.lost))
                .collect();
            let want: Vec<(u32, u64, u64, u64)> = ex
                .iter()
                .map(|&(from, k)| (from, 4 * steps, 4 * (steps - k), 0))
                .collect();
            assert_eq!(got, want, "agent {}", agent + 1);
        }
    }
}

#[test]
fn periodic_links_are_the_method_of_steps_bit_for_bit() {
    let steps = 300;
    let links = Links {
        l01: delay_link(2, Some(4)),
        l21: delay_link(0, Some(3)),
        l12: delay_link(5, Some(1)),
        l32: None,
        l23: delay_link(1, Some(10)),
    };
    for observerless in [true, false] {
        let (got, _) = run_engine(&network(observerless, links, steps));
        let want = method_of_steps(observerless, links, steps);
        for (n, (g, w)) in got.iter().zip(&want).enumerate() {
            assert_eq!(g, w, "observerless = {observerless}: step {n} differs");
        }
        let (ideal, _) = run_engine(&network(observerless, Links::ideal(), steps));
        assert_ne!(ideal.last(), got.last(), "the periods changed nothing");
    }
}

#[test]
fn an_unimpaired_link_model_is_not_filtered() {
    // A link model with nothing set is dropped: the run is the ideal run.
    let steps = 200;
    let none = Some(model(0, 0, Loss::None, None, 5));
    let links = Links {
        l01: none,
        l21: none,
        l12: none,
        l32: none,
        l23: none,
    };
    for observerless in [true, false] {
        let (got, stats) = run_engine(&network(observerless, links, steps));
        let (ideal, _) = run_engine(&network(observerless, Links::ideal(), steps));
        assert_eq!(got, ideal);
        assert!(stats.iter().all(Vec::is_empty), "{stats:?}");
    }
}

#[test]
fn lossy_network_runs_are_reproducible_from_the_seed() {
    let steps = 300;
    let lossy = |seed: u64| {
        let l = |from: u32, to: u32| {
            Some(model(
                1,
                2,
                Loss::Bernoulli { p: 0.3 },
                None,
                link_seed(seed, from, to),
            ))
        };
        Links {
            l01: l(0, 1),
            l21: l(2, 1),
            l12: l(1, 2),
            l32: l(3, 2),
            l23: l(2, 3),
        }
    };
    for observerless in [true, false] {
        let a = run_engine(&network(observerless, lossy(8), steps));
        let b = run_engine(&network(observerless, lossy(8), steps));
        let c = run_engine(&network(observerless, lossy(9), steps));
        assert_eq!(a.0, b.0, "same seed, same trajectory");
        assert_eq!(a.1, b.1, "same seed, same link counters");
        assert_ne!(a.0.last(), c.0.last(), "another seed, another trajectory");
        assert_ne!(a.1, c.1, "another seed, other counters");
        for st in a.1.iter().flatten() {
            let s = st.1;
            assert_eq!(s.sent, 4 * steps);
            assert!(s.lost > 0 && s.delivered > 0, "{st:?}");
            assert!(s.lost + s.delivered <= s.sent, "{st:?}");
        }
    }
}

// ------------------------------------------------------- untrusted values

/// A NaN or a non-rotation is refused by the receiving agent, counted per
/// link, and leaves the agent exactly as if nothing had arrived.
#[test]
fn untrusted_values_are_refused_counted_and_change_nothing() {
    let net = network(true, Links::ideal(), 10);
    let spec = &net.agents[1]; // agent 2: neighbours 1 and 3
    let mut a = attitude::agent::Agent::new(spec.model.clone(), spec.initial, DT);
    let mut b = a.clone();
    let good = Exchanged {
        r: rot(0.3, &Vector3::new(0.0, 0.6, 0.8)),
        w: Vector3::new(0.1, -0.2, 0.3),
        s: Vector3::zeros(),
    };
    let mut nan = good;
    nan.w[1] = f64::NAN;
    let mut skew = good;
    skew.r[(0, 1)] += 1e-3;
    for n in 0..10u64 {
        for s in 0..4u32 {
            for k in 0..2 {
                let bad = match (n, s, k) {
                    (3, 0, 0) => Some(nan),
                    (6, 2, 1) => Some(skew),
                    _ => None,
                };
                match bad {
                    Some(x) => a.receive_neighbour(k, x), // refused; b hears nothing
                    None => {
                        a.receive_neighbour(k, good);
                        b.receive_neighbour(k, good);
                    }
                }
            }
            a.advance();
            b.advance();
        }
    }
    assert_eq!(bits(a.state()), bits(b.state()));
    let stats = a.link_stats();
    assert_eq!(stats.len(), 2, "{stats:?}");
    assert_eq!((stats[0].0, stats[0].1.rejected), (1, 1));
    assert_eq!((stats[1].0, stats[1].1.rejected), (3, 1));
    assert!(b.link_stats().is_empty());
    assert!(good.trust().is_ok() && nan.trust().is_err() && skew.trust().is_err());
}

/// `--until settled` extends a run's horizon in chunks
/// (`InProcess::extend_to`): a run extended at steps that are multiples of
/// `sample_every` is the run given the longer horizon from the start, bit
/// for bit and sample for sample — on one thread and on several, with
/// delayed links (whose held values and queues must carry over).
#[test]
fn a_run_extended_in_chunks_is_the_longer_run_bit_for_bit() {
    let links = Links {
        l01: delay_link(5, None),
        l21: delay_link(3, None),
        l12: delay_link(1, None),
        l32: delay_link(7, None),
        l23: delay_link(2, None),
    };
    for observerless in [true, false] {
        for threads in [1, 3] {
            let mut net = network(observerless, links, 300);
            net.sample_every = 20;
            let record = |engine: &mut InProcess, out: &mut Trajectory| {
                engine.run(|snap| {
                    out.push(snap.agents.iter().map(bits).collect());
                    true
                })
            };
            let mut whole = Vec::new();
            let mut once = InProcess::new(&net).with_exact_threads(threads);
            assert!(record(&mut once, &mut whole).is_none());
            let mut chunked = Vec::new();
            net.steps = 100;
            let mut engine = InProcess::new(&net).with_exact_threads(threads);
            for horizon in [100, 160, 300] {
                engine.extend_to(horizon);
                assert!(record(&mut engine, &mut chunked).is_none());
                assert_eq!(engine.step_index(), horizon);
            }
            assert_eq!(whole.len(), 300 / 20 + 1);
            assert_eq!(
                chunked, whole,
                "observerless = {observerless}, threads = {threads}"
            );
        }
    }
}
