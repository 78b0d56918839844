//! The data a page shows: the network's bodies laid out on its graph, and
//! the decimated trajectory ([`Frames`]), serialised as the page's JSON.

use super::frames::Frames;
use super::graph::{self, Layout};
use super::shape;
use attitude::network::{Network, Scheme};
use serde::Serialize;

/// The largest box's longest half-side, as a fraction of the smallest
/// distance between two nodes of the layout.
const BODY_SIZE: f64 = 0.3;

/// Format of [`ViewData`] (the page checks it).
pub const FORMAT: u32 = 1;

/// How the run went, as the page's title line says.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunInfo {
    /// Scenario name.
    pub scenario: String,
    /// Engine (`processes`, `in-process`).
    pub engine: String,
    /// Whether the run reached its horizon.
    pub complete: bool,
    /// Why not, if not.
    pub incomplete_reason: Option<String>,
    /// Real-time factor, `None` for lockstep.
    pub realtime: Option<f64>,
    /// The scenario's events, marked on the timeline and the error plots
    /// (absent without).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub events: Vec<EventMark>,
}

/// An event on the page's timeline.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EventMark {
    /// When, s.
    pub t: f64,
    /// What happened (`cut 3–5`).
    pub label: String,
}

/// One body: where it stands and its box.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Body {
    /// Node id (0 = the leader).
    pub id: u32,
    /// Position, world frame (z up; the graph lies in z = 0).
    pub pos: [f64; 3],
    /// Half-side vectors of its box in its body frame (the leader: a cube).
    pub axes: [[f64; 3]; 3],
    /// BFS depth from the leader.
    pub depth: u32,
    /// Whether it reads the leader (`Ξᵢ = 1`).
    pub leader_link: bool,
}

/// Everything the page needs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ViewData {
    /// [`FORMAT`].
    pub format: u32,
    /// The run.
    pub run: RunInfo,
    /// `observer-time-varying`, `observer-constant` or `observerless`.
    pub scheme: &'static str,
    /// Whether agents run an observer (the frames hold `R̂ᵢ`).
    pub observer: bool,
    /// Leader, then agents in network order.
    pub bodies: Vec<Body>,
    /// Follower edges, as indices into `bodies`.
    pub edges: Vec<[usize; 2]>,
    /// The trajectory.
    pub frames: Frames,
    /// Each agent's look, as in `errors.svg` ([`crate::results::palette`]).
    pub palette: Palette,
}

/// [`crate::results::palette`], for the page.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Palette {
    /// Colours, `#RRGGBB`: agent `k` (0-based) has `colours[k mod len]`.
    pub colours: &'static [&'static str],
    /// Dash patterns (drawn, gap) px, `(0, 0)` solid: agent `k` has
    /// `dashes[(k div len(colours)) mod len]`.
    pub dashes: &'static [(u32, u32)],
}

/// The data of a run of `net` that recorded `frames`.
#[must_use]
pub fn view_data(net: &Network, run: RunInfo, frames: Frames) -> ViewData {
    let Layout {
        pos,
        depth,
        edges,
        leader_links,
    } = graph::layout(net);
    let boxes: Vec<[[f64; 3]; 3]> = (net.agents.iter())
        .map(|a| shape::box_axes(&a.model.inertia.j))
        .collect();
    let largest = boxes
        .iter()
        .map(shape::largest_half_side)
        .fold(0.0, f64::max);
    let room = BODY_SIZE * graph::min_distance(&pos);
    let scale = room / largest.max(f64::MIN_POSITIVE);
    let h = 0.6 * room;
    let cube = [[h, 0.0, 0.0], [0.0, h, 0.0], [0.0, 0.0, h]];
    let mut linked = vec![false; pos.len()];
    leader_links.iter().for_each(|&v| linked[v] = true);
    let mut bodies = vec![body(0, pos[0], cube, 0, false)];
    for (k, a) in net.agents.iter().enumerate() {
        let axes = boxes[k].map(|v| v.map(|x| x * scale));
        let linked = linked[k + 1];
        bodies.push(body(a.model.id, pos[k + 1], axes, depth[k + 1], linked));
    }
    let observer = net
        .agents
        .first()
        .is_some_and(|a| a.model.scheme.has_observer());
    ViewData {
        format: FORMAT,
        run,
        scheme: net
            .agents
            .first()
            .map_or("observerless", |a| scheme_name(&a.model.scheme)),
        observer,
        bodies,
        edges,
        frames,
        palette: Palette {
            colours: &crate::results::palette::COLOURS,
            dashes: &crate::results::palette::DASHES,
        },
    }
}

fn body(id: u32, p: [f64; 2], axes: [[f64; 3]; 3], depth: u32, leader_link: bool) -> Body {
    Body {
        id,
        pos: [round4(p[0]), round4(p[1]), 0.0],
        axes: axes.map(|v| v.map(round4)),
        depth,
        leader_link,
    }
}

/// `x` to 4 decimals (a shorter page; positions and sizes are only drawn).
fn round4(x: f64) -> f64 {
    (x * 1e4).round() / 1e4 + 0.0
}

/// The scheme's name as scenario files write it.
fn scheme_name(s: &Scheme) -> &'static str {
    match s {
        Scheme::ObserverTimeVarying { .. } => "observer-time-varying",
        Scheme::ObserverConstant { .. } => "observer-constant",
        Scheme::Observerless { .. } => "observerless",
    }
}
