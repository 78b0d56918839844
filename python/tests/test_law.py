"""A control law written in Python (``attsync.run(scenario, law=f)``):
a transcription of the built-in observerless law (eq. `districontrol`)
gives the built-in bits; numpy's version matches closely; bad laws raise
``LawError`` naming the agent, the step and the cause."""

import os
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import attsync

REPO = Path(os.environ["ATTSYNC_REPO"])
OBSERVERLESS = REPO / "scenarios/paper/constant-observerless.toml"
PAPER = REPO / "scenarios/paper/timevarying.toml"


# PROTOCOL.md § 10.1's arithmetic in plain floats, as the independent agent
# transcribed it (tests/independent_agent/arith.py: mm sums in nalgebra's order).
sys.path.insert(0, str(REPO / "tests/independent_agent"))
from arith import mm, psi, tr  # noqa: E402


def districontrol(c):
    """Eq. `districontrol`, operation by operation as the built-in law:
    τ = −k_ω ω − Σ k_R ψ(a_ij R_jᵀ R), the leader first."""
    R, w = tuple(c.R.ravel().tolist()), c.omega.tolist()
    tau = [-w[0] * c.k_omega, -w[1] * c.k_omega, -w[2] * c.k_omega]
    for h in ([c.leader] if c.leader is not None else []) + c.neighbours:
        p = psi(mm(mm(tuple(h.a.ravel().tolist()), tr(tuple(h.R.ravel().tolist()))), R))
        tau = [tau[i] - p[i] * c.k_r for i in range(3)]
    return tau


def districontrol_numpy(c):
    """The same law in ten lines of numpy."""
    def vex_skew(m):
        return 0.5 * np.array([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]])

    tau = -c.k_omega * c.omega
    for h in ([c.leader] if c.leader is not None else []) + c.neighbours:
        tau = tau - c.k_r * vex_skew(h.a @ h.R.T @ c.R)
    return tau


def short(path=OBSERVERLESS, duration=2):
    return attsync.load(path).set("simulation.duration", duration)


def same_files(a, b):
    return all((a.dir / f).read_bytes() == (b.dir / f).read_bytes() for f in ["errors.csv", "states.bin"])


def test_a_transcription_of_the_observerless_law_gives_the_built_in_bits(tmp_path):
    built_in = attsync.run(short(), out=tmp_path / "a")
    ours = attsync.run(short(), law=districontrol, out=tmp_path / "b")
    assert same_files(built_in, ours)
    # With a delay and a saturation too: the law sees what the links deliver.
    sc = short().set("network.delay", 0.05).set("actuator.max_torque", 3.0)
    assert same_files(attsync.run(sc, out=tmp_path / "c"), attsync.run(sc, law=districontrol, out=tmp_path / "d"))


def test_the_numpy_law_matches_to_1e_12(tmp_path):
    a = attsync.run(short(), out=tmp_path / "a").states
    b = attsync.run(short(), law=districontrol_numpy, out=tmp_path / "b").states
    assert np.abs(a.R - b.R).max() < 1e-12
    assert np.abs(a.omega - b.omega).max() < 1e-12


def test_a_law_changes_the_run_and_sees_time_and_ids(tmp_path):
    seen = set()

    def half_gain(c):
        seen.add((c.agent, c.stage))
        assert c.t == pytest.approx(c.step * c.dt + [0, 0.5, 0.5, 1][c.stage] * c.dt)
        return 0.5 * np.asarray(districontrol(c))

    r = attsync.run(short(duration=0.5), law=half_gain, out=tmp_path / "r")
    base = attsync.run(short(duration=0.5), out=tmp_path / "b")
    assert not same_files(r, base)
    assert seen == {(i, s) for i in range(1, 8) for s in range(4)}


def test_monte_carlo_with_a_law(tmp_path):
    a = attsync.mc(short(duration=1), 4, seed=5)
    b = attsync.mc(short(duration=1), 4, seed=5, law=districontrol)
    pd.testing.assert_frame_equal(a, b)


@pytest.mark.parametrize(
    "law, says",
    [
        (lambda c: 1 / 0 if (c.agent, c.step) == (3, 10) else districontrol(c), "agent 3, step 10"),
        (lambda c: [np.nan, 0.0, 0.0], "not finite"),
        (lambda c: [1.0, 2.0], "shape (2,)"),
        (lambda c: "torque", "could not convert"),
    ],
)
def test_a_bad_law_raises_naming_the_agent_and_step(tmp_path, law, says):
    with pytest.raises(attsync.LawError, match=None) as e:
        attsync.run(short(duration=0.5), law=law, out=tmp_path / "r")
    assert says in str(e.value), str(e.value)
    assert "agent " in str(e.value) and "step " in str(e.value)
    r = attsync.open(tmp_path / "r")
    assert not r.complete, "the run stopped where the law failed"
    # The interpreter goes on: a good run afterwards.
    assert attsync.run(short(duration=0.2), law=districontrol).complete


def test_division_by_zero_is_named(tmp_path):
    with pytest.raises(attsync.LawError, match="ZeroDivisionError"):
        attsync.run(short(duration=0.5), law=lambda c: 1 / 0, out=tmp_path / "r")


def test_a_law_runs_in_process_only(tmp_path):
    with pytest.raises(attsync.RunError, match="in-process only"):
        attsync.run(short(duration=0.2), engine="processes", law=districontrol, out=tmp_path / "r")


def test_observer_schemes_hand_the_observer_state(tmp_path):
    got = {}

    def probe(c):
        got.setdefault(c.agent, (c.R_hat.copy(), c.omega_hat.copy(), c.omega_hat_dot.copy(), c.inertia.copy()))
        return np.zeros(3)

    r = attsync.run(short(PAPER, duration=0.01), law=probe, out=tmp_path / "r")
    s = r.states
    for k, i in enumerate(s.agent_ids):
        R_hat, w_hat, _, J = got[int(i)]
        assert np.array_equal(R_hat, s.R_hat[0, k]) and np.array_equal(w_hat, s.omega_hat[0, k])
        assert np.all(np.linalg.eigvalsh(J) > 0)
