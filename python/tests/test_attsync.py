"""Tests of the attsync Python package (issue 36, part 1): scenarios,
runs, results as DataFrames and arrays, byte-identity with the CLI.

Run by tests/tests/python_package.rs, which assembles the package from the
workspace's build and sets ATTSYNC_BIN_DIR (the CLI, for comparisons) and
ATTSYNC_REPO (the repository, for its scenarios)."""

import math
import os
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import attsync

REPO = Path(os.environ["ATTSYNC_REPO"])
CLI = Path(os.environ["ATTSYNC_BIN_DIR"]) / "attsync"
PAPER = REPO / "scenarios/paper/timevarying.toml"
OBSERVERLESS = REPO / "scenarios/paper/constant-observerless.toml"


def cli(*args, cwd=None):
    return subprocess.run([str(CLI), *map(str, args)], capture_output=True, text=True, cwd=cwd)


def short(path=PAPER, duration=2):
    return attsync.load(path).set("simulation.duration", duration)


def test_set_is_validated_and_to_toml_holds_it():
    sc = short().set("agent[2].omega", np.array([0.5, 0.0, -0.25]))
    text = sc.to_toml()
    assert "duration = 2" in text
    assert "[0.5, 0.0, -0.25]" in text
    assert sc.name == "paper-timevarying"
    before = list(sc.sets)
    with pytest.raises(attsync.ScenarioError) as e:
        sc.set("simulation.dt", -1.0)
    assert e.value.file.endswith("timevarying.toml")
    assert e.value.field == "simulation.dt"
    assert "> 0" in e.value.reason
    assert sc.sets == before, "a refused set leaves the scenario as it was"


def test_unknown_fields_and_missing_files_raise_scenario_error():
    with pytest.raises(attsync.ScenarioError) as e:
        short().set("simulation.durration", 3)
    assert any("durration" in f or "durration" in r for f, r in e.value.issues), e.value.issues
    with pytest.raises(attsync.ScenarioError) as e:
        attsync.load(REPO / "no-such-scenario.toml")
    assert e.value.file.endswith("no-such-scenario.toml")
    with pytest.raises(TypeError):
        short().set("simulation.duration", object())


def test_a_run_is_the_clis_byte_for_byte(tmp_path):
    ours = attsync.run(short(), out=tmp_path / "py")
    o = cli("run", PAPER, "--engine", "in-process", "--out", tmp_path / "cli", "--set", "simulation.duration=2")
    assert o.returncode == 0, o.stderr
    for f in ["errors.csv", "states.bin", "scenario.toml"]:
        assert (tmp_path / "py" / f).read_bytes() == (tmp_path / "cli" / f).read_bytes(), f
    v = cli("verify", tmp_path / "py")
    assert v.returncode == 0, v.stdout + v.stderr
    assert ours.complete and ours.summary["engine"] == "in-process"


def test_errors_are_errors_csv_as_a_dataframe(tmp_path):
    r = attsync.run(short(), out=tmp_path / "r")
    df = r.errors
    header = (tmp_path / "r" / "errors.csv").read_text().splitlines()[0].split(",")
    assert list(df.columns) == header
    assert len(df) == 201 * 7
    assert df["agent"].nunique() == 7
    pd.testing.assert_frame_equal(df, attsync.open(tmp_path / "r").errors)


def test_states_match_the_clis_csv_export(tmp_path):
    r = attsync.run(short(duration=1), out=tmp_path / "r")
    s = r.states
    assert s.R.shape == (101, 7, 3, 3) and s.omega.shape == (101, 7, 3) and s.R0.shape == (101, 3, 3)
    assert list(s.agent_ids) == [1, 2, 3, 4, 5, 6, 7]
    assert s.has_observer and math.isclose(s.dt, 0.001)
    o = cli("export", tmp_path / "r" / "states.bin", "--csv")
    assert o.returncode == 0, o.stderr
    from io import StringIO

    csv = pd.read_csv(StringIO(o.stdout), float_precision="round_trip")
    agents = csv[csv["node"] != 0]
    rows = agents[agents["t"] == agents["t"].unique()[37]]
    k = 37
    for i, (_, row) in enumerate(rows.iterrows()):
        assert row["node"] == s.agent_ids[i]
        assert np.array_equal(s.R[k, i].ravel(), row[[f"r{a}{b}" for a in (1, 2, 3) for b in (1, 2, 3)]].to_numpy(float))
        assert np.array_equal(s.omega_hat[k, i], row[["w_hat1", "w_hat2", "w_hat3"]].to_numpy(float))
        assert np.array_equal(s.tau[k, i], row[["tau1", "tau2", "tau3"]].to_numpy(float))
    leader = csv[csv["node"] == 0].iloc[k]
    assert np.array_equal(s.R0[k].ravel(), leader[[f"r{a}{b}" for a in (1, 2, 3) for b in (1, 2, 3)]].to_numpy(float))
    # Rotations: every attitude orthogonal.
    RtR = np.einsum("tnji,tnjk->tnik", s.R, s.R)
    assert np.abs(RtR - np.eye(3)).max() < 1e-9


def test_torques_are_nan_only_at_the_last_step(tmp_path):
    r = attsync.run(short(OBSERVERLESS, duration=1), out=tmp_path / "r")
    tq = r.torques
    assert list(tq.columns) == ["t", "agent", "tau1", "tau2", "tau3"]
    last = tq["t"] == tq["t"].max()
    assert tq.loc[last, "tau1"].isna().all()
    assert tq.loc[~last, ["tau1", "tau2", "tau3"]].notna().all().all()


def test_the_process_engine_gives_the_same_bits(tmp_path):
    a = attsync.run(short(OBSERVERLESS, duration=0.5), out=tmp_path / "a")
    b = attsync.run(short(OBSERVERLESS, duration=0.5), engine="processes", out=tmp_path / "b")
    assert b.summary["engine"] == "processes"
    for f in ["errors.csv", "states.bin"]:
        assert (a.dir / f).read_bytes() == (b.dir / f).read_bytes(), f


def test_a_run_without_out_lives_in_a_temporary_directory():
    r = attsync.run(short(duration=0.5))
    d = r.dir
    assert (d / "states.bin").is_file()
    assert len(r.errors) == 51 * 7
    del r
    import gc

    gc.collect()
    assert not d.exists()


def test_bad_engine_bad_directory_and_a_cut_states_file(tmp_path):
    with pytest.raises(ValueError, match="engine"):
        attsync.run(short(duration=0.5), engine="warp")
    with pytest.raises(FileNotFoundError):
        attsync.open(tmp_path)
    r = attsync.run(short(duration=0.5), out=tmp_path / "r")
    data = (r.dir / "states.bin").read_bytes()
    (tmp_path / "cut.bin").write_bytes(data[:-7])
    with pytest.raises(attsync.StatesFormatError, match="whole number"):
        attsync.read_states(tmp_path / "cut.bin")
    (tmp_path / "junk.bin").write_bytes(b"NOTSTATE" + data[8:])
    with pytest.raises(attsync.StatesFormatError, match="magic"):
        attsync.read_states(tmp_path / "junk.bin")


def test_a_diverging_run_returns_what_it_recorded(tmp_path):
    # The envelope's rate limit below the initial rates' peak: the guard stops the run.
    sc = short(OBSERVERLESS, duration=2).set("guard.omega", 7.0)
    r = attsync.run(sc, out=tmp_path / "r")
    assert not r.complete
    assert r.summary["diverged"]["quantity"] == "omega"
    assert r.summary["diverged"]["value"] > 7.0
    assert list(r.errors.columns)[:3] == ["t", "agent", "att_err"]


def _cli_csv(path):
    return pd.read_csv(path, float_precision="round_trip")


def test_sweep_is_the_clis_sweep_csv(tmp_path):
    sc = short(OBSERVERLESS, duration=2)
    df = attsync.sweep(sc, "network.delay", [0, 0.05, 0.1], out=tmp_path / "py")
    assert list(df["value"]) == [0, 0.05, 0.1]
    assert df.attrs["dir"] == str(tmp_path / "py")
    o = cli("sweep", OBSERVERLESS, "--param", "network.delay", "--values", "0,0.05,0.1",
            "--set", "simulation.duration=2", "--out", tmp_path / "cli")
    assert o.returncode == 0, o.stderr
    pd.testing.assert_frame_equal(df, _cli_csv(tmp_path / "cli" / "sweep.csv"))
    grid = attsync.sweep(sc, "network.delay", [0, 0.1], grid=("scheme.control.k_r", [1.0, 2.0]))
    assert len(grid) == 4 and "dir" not in grid.attrs


def test_mc_is_the_clis_trials_csv(tmp_path):
    sc = short(OBSERVERLESS, duration=1)
    df = attsync.mc(sc, 6, seed=11, out=tmp_path / "py")
    assert list(df["trial"]) == list(range(6))
    o = cli("mc", OBSERVERLESS, "--trials", "6", "--seed", "11", "--set", "simulation.duration=1",
            "--out", tmp_path / "cli")
    assert o.returncode == 0, o.stderr
    ours, theirs = df, _cli_csv(tmp_path / "cli" / "trials.csv")
    pd.testing.assert_frame_equal(ours, theirs)


def test_margin_is_the_clis(tmp_path):
    m = attsync.margin(OBSERVERLESS)
    o = cli("margin", OBSERVERLESS, "--json", tmp_path / "m.json")
    assert o.returncode == 0, o.stderr
    import json

    theirs = json.loads((tmp_path / "m.json").read_text())
    assert m["margin"] == theirs["margin"]
    assert m["kind"] == "crossing" and abs(m["margin"] - 0.389) < 1e-3


def test_parquet_reads_back_exactly(tmp_path):
    r = attsync.run(short(duration=1), out=tmp_path / "r")
    d = r.to_parquet(tmp_path / "pq")
    errors = pd.read_parquet(d / "errors.parquet")
    pd.testing.assert_frame_equal(errors, r.errors)
    states = pd.read_parquet(d / "states.parquet")
    s = r.states
    assert len(states) == s.R.shape[0] * s.R.shape[1]
    row = states.iloc[37 * 7 + 2]
    assert row["agent"] == s.agent_ids[2] and row["t"] == s.t[37]
    assert row["r23"] == s.R[37, 2, 1, 2] and row["w_hat3"] == s.omega_hat[37, 2, 2]
    assert row["tau1"] == s.tau[37, 2, 0]
    leader = pd.read_parquet(d / "leader.parquet")
    assert np.array_equal(leader[["r11", "r12", "r13"]].to_numpy(), s.R0[:, 0, :])
    # The agents' columns are export --csv's.
    o = cli("export", r.dir / "states.bin", "--csv")
    header = o.stdout.splitlines()[0].split(",")
    assert list(states.columns) == ["t", "agent"] + header[2:]
    assert sorted(p.name for p in d.iterdir()) == ["errors.parquet", "leader.parquet", "states.parquet"]
