"""Parquet (issue 36, part 4): ``attsync export DIR --parquet`` and
``Run.to_parquet`` write the same tables, which pandas reads back exactly
(the numbers of ``Run.errors`` and ``Run.states``), NaN as null.

Run by tests/tests/python_package.rs (ATTSYNC_REPO, ATTSYNC_BIN_DIR)."""

import os
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq

import attsync

REPO = Path(os.environ["ATTSYNC_REPO"])
CLI = Path(os.environ["ATTSYNC_BIN_DIR"]) / "attsync"
PAPER = REPO / "scenarios/paper/timevarying.toml"
OBSERVERLESS = REPO / "scenarios/paper/constant-observerless.toml"
TABLES = ("errors", "states", "leader")


def test_the_cli_and_python_write_the_same_tables(tmp_path):
    for path in (PAPER, OBSERVERLESS):
        run = attsync.run(attsync.load(path).set("simulation.duration", 0.5), out=tmp_path / path.stem)
        cli = subprocess.run([str(CLI), "export", str(run.dir), "--parquet", "--out", str(tmp_path / f"{path.stem}-cli")],
                             capture_output=True, text=True)
        assert cli.returncode == 0, cli.stderr
        py = run.to_parquet(tmp_path / f"{path.stem}-py")
        for name in TABLES:
            a = pd.read_parquet(tmp_path / f"{path.stem}-cli" / f"{name}.parquet")
            b = pd.read_parquet(py / f"{name}.parquet")
            pd.testing.assert_frame_equal(a, b, check_exact=True)
        # The numbers are the run's, bit for bit.
        states = pd.read_parquet(tmp_path / f"{path.stem}-cli" / "states.parquet")
        s = run.states
        assert np.array_equal(states["r12"].to_numpy(), s.R[:, :, 0, 1].ravel())
        assert np.array_equal(states["t"].to_numpy(), s.t.repeat(len(s.agent_ids)))
        pd.testing.assert_frame_equal(pd.read_parquet(tmp_path / f"{path.stem}-cli" / "errors.parquet"), run.errors,
                                      check_exact=True)
        # The last sample has no torque: null in the file, NaN in pandas.
        table = pq.read_table(tmp_path / f"{path.stem}-cli" / "states.parquet")
        assert table.column("tau1").null_count == len(s.agent_ids)
        assert str(table.schema.field("agent").type) == "int64"
