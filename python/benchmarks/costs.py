"""What the Python package costs (issue 36; BENCHMARKS.md "attsync from
Python"): a run from Python against the CLI's in-process run of the same
scenario, and a Python control law's cost per call. Medians of interleaved
repetitions. Run from the repository root with the package importable:

    python3 python/benchmarks/costs.py [--reps 5]
"""

import argparse
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

import attsync

PAPER = Path("scenarios/paper/timevarying.toml")
OBSERVERLESS = Path("scenarios/paper/constant-observerless.toml")


def timed(f):
    t = time.perf_counter()
    f()
    return time.perf_counter() - t


def cli_run(cli, path, out, sets=()):
    args = [cli, "run", str(path), "--engine", "in-process", "--threads", "1", "--out", out, "--quiet"]
    for s in sets:
        args += ["--set", s]
    subprocess.run(args, check=True, capture_output=True)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--cli", default="target/release/attsync")
    a = p.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="attsync-bench-"))
    sc = attsync.load(PAPER)
    py, cl = [], []
    for k in range(a.reps):
        cl.append(timed(lambda: cli_run(a.cli, PAPER, tmp / f"cli{k}")))
        py.append(timed(lambda: attsync.run(sc, threads=1, out=tmp / f"py{k}")))
    m_cli, m_py = statistics.median(cl), statistics.median(py)
    print("| paper time-varying, 40 s, in-process, 1 thread | wall s (median) |")
    print("|---|---:|")
    print(f"| `attsync run` (CLI, a process) | {m_cli:.3f} |")
    print(f"| `attsync.run` (Python) | {m_py:.3f} ({m_py / m_cli:.2f}×) |")

    def zero(c):
        return (0.0, 0.0, 0.0)

    def numpy_law(c):
        tau = -c.k_omega * c.omega
        for h in ([c.leader] if c.leader is not None else []) + c.neighbours:
            m = h.a @ h.R.T @ c.R
            tau = tau - c.k_r * 0.5 * np.array([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]])
        return tau

    short = attsync.load(OBSERVERLESS).set("simulation.duration", 5)
    calls = 5000 * 4 * 7
    rows = []
    for name, law in [("none (built-in)", None), ("returns zeros", zero), ("numpy districontrol", numpy_law)]:
        ts = [timed(lambda: attsync.run(short, threads=1, law=law)) for _ in range(a.reps)]
        rows.append((name, statistics.median(ts)))
    base = rows[0][1]
    print()
    print(f"| law (paper observerless, 5 s: {calls} calls) | wall s (median) | per call, µs |")
    print("|---|---:|---:|")
    for name, t in rows:
        per = "" if t is base else f"{(t - base) / calls * 1e6:.1f}"
        print(f"| {name} | {t:.3f} | {per} |")


if __name__ == "__main__":
    main()
