"""PROTOCOL.md § 10.5-10.8: an agent's state, held values and stages.

No IPC here: :class:`Agent` is fed the received states and says what to
publish, so the model can be read (and tested) without iceoryx2.
"""

import arith as m
from effects import Effects

SCHEMES = ("observer-time-varying", "observer-constant", "observerless")


class ConfigRefused(Exception):
    """The configuration asks for something this agent does not do."""


class Agent:
    """An agent of one of the three schemes, stepped stage by stage."""

    def __init__(self, cfg):
        role = cfg["role"]
        model, initial = role["model"], role["initial"]
        self.scheme = model["scheme"]["kind"]
        if self.scheme not in SCHEMES:
            raise ConfigRefused(f"unknown scheme {self.scheme!r}")
        self.observer = model["scheme"].get("observer")
        self.control = model["scheme"]["control"]
        self.j = m.from_config(model["inertia"]["j"])
        self.j_inv = m.from_config(model["inertia"]["j_inv"])
        self.a_bar = m.from_config(model["a_bar"]) if model.get("a_bar") else None
        self.p = m.from_config(model["p"]) if model.get("p") else None
        self.gains = [m.from_config(n["a"]) for n in model["neighbours"]]
        lg = model.get("leader_gain")
        self.leader_gain = m.from_config(lg) if lg is not None else None
        self.inputs = list(cfg["inputs"])
        hears = 1 if self.leader_gain is not None else 0
        if len(self.gains) + hears != len(self.inputs):
            raise ConfigRefused(
                f"inputs {self.inputs} do not match {len(self.gains)} neighbours"
                f" and leader_gain {lg}"
            )
        # § 10.5 / § 8: before anything valid arrives an input holds (I, 0, 0).
        self.held = [(m.I3, m.Z3, m.Z3) for _ in self.inputs]
        rots = [m.from_config(initial["r"]), m.from_config(initial["r_hat"])]
        vecs = [m.vec(initial["w"]), m.vec(initial["w_hat"]), m.vec(initial["s_hat"])]
        self.rk = m.Rkmk4(rots, vecs, float(cfg["dt"]))
        self.peak_torque = 0.0
        # § 10.11: the torque applied at the last stage 0 (the rate limit's
        # anchor; after stage 0, the torque of § 5 kind 7).
        self.torque = m.Z3
        self.point = None
        # § 10.11: the limits of the torque the body receives.
        self.saturation = (model.get("effects") or {}).get("saturation")
        self.rate_limit = (model.get("effects") or {}).get("rate_limit")
        # § 10.12-10.14: disturbances, sensors, the law's inertia.
        self.effects = Effects(model.get("effects"), float(cfg["dt"]))
        self.law_j = self.effects.law_j or self.j
        # § 10.10: gains from a step on; inputs left out of the law now.
        self.retunes = model.get("timeline", {}).get("retune", [])
        self.absent = [False] * len(self.inputs)

    def saturate(self, tau):
        """§ 10.11: the torque the body receives."""
        sat = self.saturation
        if sat is None:
            return tau
        if sat["kind"] == "norm":
            n, mx = m.norm(tau), float(sat["max"])
            return m.scale(tau, mx / n) if n > mx else tau
        return tuple(mx if t > mx else -mx if t < -mx else t for t, mx in zip(tau, sat["max"]))

    def rate_limited(self, tau, s):
        """§ 10.11: at most rho·dt from the torque applied at the last stage 0."""
        if self.rate_limit is None:
            return tau
        step = m.sub(tau, self.torque)
        n = m.norm(step)
        mx = (float(self.rate_limit["max"]) * self.rk.h) * (1.0, 0.5, 0.5, 1.0)[s]
        return m.add(self.torque, m.scale(step, mx / n)) if n > mx else tau

    def step_start(self, n, absent):
        """§ 10.10 at the start of step n: the last retune due by n, and the
        inputs an outage with ``forget`` leaves out."""
        for r in self.retunes:
            if r["step"] <= n:
                self.observer = r["scheme"].get("observer")
                self.control = r["scheme"]["control"]
        self.absent = absent
        self.effects.step_start(n)

    # --- what travels ------------------------------------------------------

    def stage_point(self, s):
        """Computes (and keeps) stage ``s``'s point; returns what to publish
        at that exchange: (r, w, s) per § 10.5."""
        rots, vecs = self.rk.point(s)
        self.point = (rots, vecs)
        r, rh = rots
        w, wh, sh = vecs
        if self.scheme == "observerless":
            r, w = self.effects.measure(r, w)  # § 10.13: it publishes what it measures
            return r, w, m.Z3
        return rh, wh, sh

    def sample(self):
        """(r, w, r_hat, w_hat, s_hat) at the start of the current step."""
        (r, rh), (w, wh, sh) = self.rk.r0, self.rk.x0
        return r, w, rh, wh, sh

    # --- one stage (§ 10.8) --------------------------------------------------

    def evaluate(self, s):
        """Evaluates stage ``s`` at the point of :meth:`stage_point` with the
        held values, and advances the integrator."""
        (r, rh), (w, wh, sh) = self.point
        k_nb = len(self.gains)
        neighbours = [
            (g, h) for g, h, out in zip(self.gains, self.held[:k_nb], self.absent) if not out
        ]
        leader = None
        if self.leader_gain is not None and not self.absent[k_nb]:
            leader = (self.leader_gain, self.held[k_nb])
        r_true, w_true = r, w
        r, w = self.effects.measure(r, w)
        if self.scheme == "observer-time-varying":
            wh_dot, sh_dot = m.observer_time_varying(
                self.observer, self.p, rh, wh, sh, leader, neighbours
            )
            tau = m.control_observer(
                self.control, self.law_j, self.a_bar, r, w, rh, wh, wh_dot, True
            )
        elif self.scheme == "observer-constant":
            wh_dot, sh_dot = m.observer_constant(self.observer, rh, wh, leader, neighbours)
            tau = m.control_observer(
                self.control, self.law_j, self.a_bar, r, w, rh, wh, wh_dot, False
            )
        else:
            wh_dot, sh_dot = m.Z3, m.Z3
            tau = m.control_observerless(self.control, r, w, leader, neighbours)
        tau = self.rate_limited(self.saturate(tau), s)
        r, w = r_true, w_true
        d = self.effects.disturbance(s, r)
        body_tau = tau if d is None else m.add(tau, d)
        w_dot = m.mv(self.j_inv, m.sub(body_tau, m.cross(w, m.mv(self.j, w))))
        omegas = [w, m.Z3 if self.scheme == "observerless" else wh]
        if s == 0:
            self.peak_torque = max(self.peak_torque, m.norm(tau))
            self.torque = tau
        self.rk.update(s, omegas, [w_dot, wh_dot, sh_dot])
