"""PROTOCOL.md § 10.9: a simulated impaired link, applied by the receiver."""

MASK = (1 << 64) - 1
C_STAGE = (0.0, 0.5, 0.5, 1.0)


class SplitMix64:
    def __init__(self, seed):
        self.state = int(seed) & MASK

    def next(self):
        self.state = (self.state + 0x9E3779B97F4A7C15) & MASK
        z = self.state
        z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & MASK
        z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & MASK
        return z ^ (z >> 31)

    def unit(self):
        return float(self.next() >> 11) * (1.0 / 9007199254740992.0)


class Link:
    """One impaired input: its random stream, messages in flight and the
    held (stamp, value)."""

    def __init__(self, spec, outages=()):
        # § 10.9 / § 10.10: steps [from, to) in which the link carries nothing.
        self.outages = list(outages)
        self.delay = int(spec.get("delay") or 0)
        self.jitter = int(spec.get("jitter") or 0)
        self.period = spec.get("period")
        self.loss = spec.get("loss") or {"kind": "none"}
        self.rng = SplitMix64(spec["seed"])
        self.bad = False
        self.flight = []  # (due, stamp, value)
        self.held = None  # (stamp, value)
        # LinkStats counters: carried (past the period filter), dropped by
        # the loss model, taken out of flight.
        self.sent = 0
        self.lost = 0
        self.delivered = 0

    def _lost(self):
        kind = self.loss["kind"]
        if kind == "none":
            return False
        if kind == "bernoulli":
            return self.rng.unit() < float(self.loss["p"])
        if kind == "gilbert-elliott":
            f = self.rng.unit()
            self.bad = (f >= float(self.loss["p_bg"])) if self.bad else (f < float(self.loss["p_gb"]))
            p = self.loss["loss_bad"] if self.bad else self.loss["loss_good"]
            return self.rng.unit() < float(p)
        raise ValueError(f"unknown loss kind {kind!r}")

    def offer(self, n, s, x):
        """A valid message stamped (n, s) arrives at an exchange."""
        if self.held is None:
            self.held = ((0, 0), x)
        if self.period is not None and (s != 0 or n % int(self.period) != 0):
            return
        self.sent += 1
        if self._lost():
            self.lost += 1
            return
        j = self.rng.next() % (self.jitter + 1) if self.jitter > 0 else 0
        if any(o["from"] <= n < o["to"] for o in self.outages):
            self.lost += 1
            return
        self.flight.append(((n + self.delay + j, s), (n, s), x))

    def forgotten_at(self, n):
        """§ 10.9: whether an outage with ``forget`` leaves the input out of the law at step n."""
        return any(o.get("forget", False) and o["from"] <= n < o["to"] for o in self.outages)

    def value_at(self, n, s):
        """Delivers what is due at (n, s); the held value, or None."""
        due = sorted(m for m in self.flight if m[0] <= (n, s))
        if due:
            self.flight = [m for m in self.flight if m[0] > (n, s)]
            for _due, stamp, x in due:
                self.delivered += 1
                if stamp >= self.held[0]:
                    self.held = (stamp, x)
        return None if self.held is None else self.held[1]
