"""A Monte Carlo on a Dask cluster (issue 36, part 6): ``attsync.mc(...,
client=...)`` on a ``LocalCluster`` of two worker processes (loopback
only) gives the rows and the files of a local run, bit for bit, with a
Python law too; a law that raises on a worker raises ``LawError`` here;
shards run by the CLI and merged from Python agree as well.

Run by tests/tests/python_package.rs (ATTSYNC_REPO, ATTSYNC_BIN_DIR)."""

import os
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from dask.distributed import Client, LocalCluster

import attsync

REPO = Path(os.environ["ATTSYNC_REPO"])
CLI = Path(os.environ["ATTSYNC_BIN_DIR"]) / "attsync"
OBSERVERLESS = REPO / "scenarios/paper/constant-observerless.toml"
FILES = ("trials.csv", "initial.csv", "mc.json", "mc.svg")


@pytest.fixture(scope="module")
def client():
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
                      dashboard_address=None) as cluster, Client(cluster) as c:
        yield c


def scenario(duration=3):
    return attsync.load(OBSERVERLESS).set("simulation.duration", duration)


def same_files(a: Path, b: Path):
    for f in FILES:
        assert (a / f).read_bytes() == (b / f).read_bytes(), f"{f} differs: {a} {b}"


def test_a_monte_carlo_on_two_workers_is_the_local_one_bit_for_bit(client, tmp_path):
    sc = scenario()
    local = attsync.mc(sc, trials=7, seed=5, out=tmp_path / "local", jobs=1)
    spread = attsync.mc(sc, trials=7, seed=5, out=tmp_path / "dask", client=client, shards=3)
    pd.testing.assert_frame_equal(local, spread)
    same_files(tmp_path / "local", tmp_path / "dask")
    # Both workers took part (each ran a shard in a process of its own).
    assert len(client.scheduler_info()["workers"]) == 2
    # The default slicing (four per worker, at most one per trial) agrees too.
    again = attsync.mc(sc, trials=7, seed=5, client=client)
    pd.testing.assert_frame_equal(local, again)


def test_a_python_law_runs_on_the_workers_and_a_failing_one_raises_here(client, tmp_path):
    def damped(ctx):
        # A law of one's own: PD on the measured rate only (no attitude term).
        return -2.0 * np.asarray(ctx.omega)

    sc = scenario(duration=0.5)
    local = attsync.mc(sc, trials=4, seed=1, law=damped, jobs=1)
    spread = attsync.mc(sc, trials=4, seed=1, law=damped, client=client, shards=2)
    pd.testing.assert_frame_equal(local, spread)

    def broken(ctx):
        if ctx.step == 3:
            raise ZeroDivisionError("the law's own bug")
        return np.zeros(3)

    with pytest.raises(attsync.LawError, match="the law's own bug"):
        attsync.mc(sc, trials=4, seed=1, law=broken, client=client, shards=2)


def test_shards_of_the_cli_merged_from_python_equal_one_run(tmp_path):
    common = [str(OBSERVERLESS), "--trials", "5", "--seed", "2", "--set", "simulation.duration=3", "--quiet"]
    one = subprocess.run([str(CLI), "mc", *common, "--out", str(tmp_path / "one")], capture_output=True)
    assert one.returncode == 0, one.stderr
    for k in (1, 2, 3):
        s = subprocess.run([str(CLI), "mc", *common, "--shard", f"{k}/3", "--out", str(tmp_path / f"s{k}")],
                           capture_output=True)
        assert s.returncode == 0, s.stderr
    attsync.mc_merge([tmp_path / "s2", tmp_path / "s1", tmp_path / "s3"], tmp_path / "merged")
    same_files(tmp_path / "one", tmp_path / "merged")
    with pytest.raises(attsync.RunError, match="shards 3 of 3 missing"):
        attsync.mc_merge([tmp_path / "s1", tmp_path / "s2"], tmp_path / "partial")
    assert not (tmp_path / "partial").exists()
