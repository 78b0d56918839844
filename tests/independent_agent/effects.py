"""PROTOCOL.md § 10.12-10.14: disturbance torques, sensor errors and the
law's inertia, from the configuration's ``model.effects`` alone."""

import math

import arith as m
from link import C_STAGE, SplitMix64


def normal(rng):
    """§ 10.12: a standard normal deviate, two draws."""
    u1 = 1.0 - rng.unit()
    u2 = rng.unit()
    return math.sqrt(-2.0 * math.log(u1)) * math.cos(math.tau * u2)


def normal3(rng):
    return (normal(rng), normal(rng), normal(rng))


class GaussMarkov:
    """§ 10.12 ``noise``: x <- phi x + s g once per step."""

    def __init__(self, shape, dt):
        self.rng = SplitMix64(shape["seed"])
        self.phi = math.exp(-math.tau * float(shape["bandwidth"]) * dt)
        self.std = m.vec(shape["std"])
        self.s = m.scale(self.std, math.sqrt(1.0 - self.phi * self.phi))
        self.x = m.Z3

    def step(self, n):
        g = normal3(self.rng)
        if n == 0:
            self.x = tuple(a * b for a, b in zip(self.std, g))
        else:
            self.x = tuple(x * self.phi + s * gk for x, s, gk in zip(self.x, self.s, g))


class Effects:
    """A body's effects: what the law measures, the inertia it assumes and
    the disturbance the body feels."""

    def __init__(self, effects, dt):
        effects = effects or {}
        self.h = dt
        self.disturbances = effects.get("disturbances", [])
        self.noise = [GaussMarkov(d, dt) for d in self.disturbances if d["kind"] == "noise"]
        self.sensor = effects.get("sensor")
        self.rng = SplitMix64(self.sensor["seed"]) if self.sensor else None
        self.e, self.nu = m.I3, m.Z3
        law = effects.get("law_inertia")
        self.law_j = m.from_config(law["j"]) if law else None
        self.n = 0

    def step_start(self, n):
        """§ 10.12-10.13: what step n holds, drawn at its start."""
        self.n = n
        for p in self.noise:
            p.step(n)
        if self.sensor:
            self.e = m.exp(self._draw(self.sensor["attitude"]))
            self.nu = self._draw(self.sensor["rate"])

    def _draw(self, noise):
        bias = m.vec(noise.get("bias", [0.0, 0.0, 0.0]))
        std = float(noise.get("std", 0.0))
        if std > 0.0:
            return m.add(bias, m.scale(normal3(self.rng), std))
        return bias

    def measure(self, r, w):
        """§ 10.13: (R exp(eta), w + nu)."""
        if not self.sensor:
            return r, w
        return m.mm(r, self.e), m.add(w, self.nu)

    def disturbance(self, s, r):
        """§ 10.12: d in the body frame at stage s of the current step, or
        None without disturbances."""
        if not self.disturbances:
            return None
        n, h = self.n, self.h
        t = (float(n) + C_STAGE[s]) * h
        held = iter(self.noise)
        d = m.Z3
        for one in self.disturbances:
            kind = one["kind"]
            if kind == "constant":
                x = m.vec(one["torque"])
            elif kind == "sine":
                k = math.sin(math.tau * float(one["frequency"]) * t + float(one["phase"]))
                x = m.scale(m.vec(one["amplitude"]), k)
            elif kind == "noise":
                x = next(held).x
            elif int(one["step"]) == n:
                x = tuple(a / h for a in m.vec(one["impulse"]))
            else:
                x = m.Z3
            if one.get("frame", "body") == "inertial":
                x = m.mv(m.tr(r), x)
            d = m.add(d, x)
        return d
