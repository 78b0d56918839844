"""A reader of ``states.bin`` (docs/states-format.md), written from its
documented layout with numpy alone: the whole file is one read, records are
viewed in place (no copy per record)."""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

MAGIC = b"ATTSYNCS"
#: The layout versions read: 1 (no torques) and 2.
VERSIONS = (1, 2)


class StatesFormatError(ValueError):
    """``states.bin`` is not a states file, or is cut short or corrupt."""


@dataclass(frozen=True)
class States:
    """A run's states at its output samples, as numpy arrays.

    Axes: ``time`` (the samples), ``agent`` (``agent_ids`` order, the
    network's), then components. Matrices map body to inertial frame;
    rates are body-frame, rad/s.
    """

    #: Scenario name.
    scenario: str
    #: Integrator step, s.
    dt: float
    #: Steps between samples.
    sample_every: int
    #: Whether the agents run an observer (scheme 1 or 2).
    has_observer: bool
    #: Agent ids, shape (agent,).
    agent_ids: np.ndarray
    #: Step of each sample, shape (time,).
    step: np.ndarray
    #: Time of each sample, s, shape (time,).
    t: np.ndarray
    #: Attitudes Rᵢ, shape (time, agent, 3, 3).
    R: np.ndarray
    #: Body rates ωᵢ, shape (time, agent, 3).
    omega: np.ndarray
    #: Observer attitudes R̂ᵢ, shape (time, agent, 3, 3).
    R_hat: np.ndarray
    #: Observer rates ω̂ᵢ, shape (time, agent, 3).
    omega_hat: np.ndarray
    #: Observer σ̂ᵢ, shape (time, agent, 3).
    sigma_hat: np.ndarray
    #: Torque τᵢ at stage 0 of the sample's step, N·m (NaN: none applied), shape (time, agent, 3).
    tau: np.ndarray
    #: Leader attitude R₀, shape (time, 3, 3).
    R0: np.ndarray
    #: Leader rate ω₀, shape (time, 3).
    omega0: np.ndarray
    #: Leader σ₀, shape (time, 3).
    sigma0: np.ndarray

    def to_xarray(self):
        """The states as an ``xarray.Dataset`` (needs xarray)."""
        import xarray as xr

        coords = {"time": self.t, "agent": self.agent_ids, "row": [0, 1, 2], "col": [0, 1, 2], "axis": [0, 1, 2]}
        m, v = ("time", "agent", "row", "col"), ("time", "agent", "axis")
        return xr.Dataset(
            {
                "R": (m, self.R),
                "omega": (v, self.omega),
                "R_hat": (m, self.R_hat),
                "omega_hat": (v, self.omega_hat),
                "sigma_hat": (v, self.sigma_hat),
                "tau": (v, self.tau),
                "R0": (("time", "row", "col"), self.R0),
                "omega0": (("time", "axis"), self.omega0),
                "sigma0": (("time", "axis"), self.sigma0),
            },
            coords=coords,
            attrs={"scenario": self.scenario, "dt": self.dt, "sample_every": self.sample_every},
        )


class _Cursor:
    def __init__(self, data: bytes, path: Path):
        self.data, self.at, self.path = data, 0, path

    def take(self, n: int) -> bytes:
        if self.at + n > len(self.data):
            raise StatesFormatError(f"{self.path}: the header is cut short at byte {self.at}")
        b = self.data[self.at : self.at + n]
        self.at += n
        return b

    def unpack(self, fmt: str):
        return struct.unpack("<" + fmt, self.take(struct.calcsize("<" + fmt)))


def read_states(path) -> States:
    """Reads ``states.bin`` at ``path`` (a file, or a results directory)."""
    path = Path(path)
    if path.is_dir():
        path = path / "states.bin"
    data = path.read_bytes()
    c = _Cursor(data, path)
    if c.take(8) != MAGIC:
        raise StatesFormatError(f"{path}: not a states file (no ATTSYNCS magic)")
    (version,) = c.unpack("I")
    if version not in VERSIONS:
        raise StatesFormatError(f"{path}: layout version {version}, this reader knows {VERSIONS}")
    (name_len,) = c.unpack("Q")
    scenario = c.take(name_len).decode("utf-8")
    dt, sample_every, n_ids = c.unpack("dQQ")
    agent_ids = np.frombuffer(c.take(4 * n_ids), dtype="<u4").copy()
    (has_observer,) = c.unpack("?")
    words = 30 if version == 2 else 27
    n = len(agent_ids)
    record = np.dtype(
        [("step", "<u8"), ("leader", "<f8", (15,)), ("n", "<u8"), ("agents", "<f8", (n, words))]
    )
    body = len(data) - c.at
    if body % record.itemsize:
        raise StatesFormatError(
            f"{path}: {body} bytes of records is not a whole number of {record.itemsize}-byte records"
        )
    recs = np.frombuffer(data, dtype=record, offset=c.at)
    if len(recs) and not np.all(recs["n"] == n):
        raise StatesFormatError(f"{path}: a record does not hold {n} agents")
    a, lead = recs["agents"], recs["leader"]
    T = len(recs)
    tau = a[:, :, 27:30] if version == 2 else np.full((T, n, 3), np.nan)
    step = recs["step"].copy()
    return States(
        scenario=scenario,
        dt=dt,
        sample_every=sample_every,
        has_observer=has_observer,
        agent_ids=agent_ids,
        step=step,
        t=step * dt,
        R=a[:, :, 0:9].reshape(T, n, 3, 3),
        omega=a[:, :, 9:12],
        R_hat=a[:, :, 12:21].reshape(T, n, 3, 3),
        omega_hat=a[:, :, 21:24],
        sigma_hat=a[:, :, 24:27],
        tau=tau,
        R0=lead[:, 0:9].reshape(T, 3, 3),
        omega0=lead[:, 9:12],
        sigma0=lead[:, 12:15],
    )
