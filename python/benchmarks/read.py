"""Reading a large run's results (issue 36, "Performance"; BENCHMARKS.md
"Reading a 10⁵-agent run"): a generated tree of N agents run briefly
in-process, then, interleaved and repeated, the time to

- write its states as CSV (`attsync export DIR --csv --out FILE`),
- write its tables as Parquet (`attsync export DIR --parquet`),
- read `states.bin` into numpy arrays (`attsync.open(DIR).states`),
- read `states.parquet` back into pandas.

Medians. Run from the repository root with the package importable:

    python3 python/benchmarks/read.py [--agents 100000] [--reps 3]
"""

import argparse
import statistics
import subprocess
import tempfile
import time
from pathlib import Path

import pandas as pd

import attsync


def timed(f):
    t = time.perf_counter()
    f()
    return time.perf_counter() - t


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--agents", type=int, default=100_000)
    p.add_argument("--reps", type=int, default=3)
    p.add_argument("--cli", default="target/release/attsync")
    a = p.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="attsync-read-"))
    scenario = tmp / "tree.toml"
    subprocess.run([a.cli, "gen", "tree", "--agents", str(a.agents), "--scheme", "observerless",
                    "--out", str(scenario)], check=True, capture_output=True)
    run = tmp / "run"
    # 0.05 s sampled every 5 ms: 11 records of every agent.
    subprocess.run([a.cli, "run", str(scenario), "--engine", "in-process", "--out", str(run), "--quiet",
                    "--no-view", "--set", "simulation.duration=0.05", "--set", "output.sample_period=0.005"],
                   check=True, capture_output=True)
    size = (run / "states.bin").stat().st_size
    csv, pq, arrays, frame = [], [], [], []
    for k in range(a.reps):
        csv.append(timed(lambda: subprocess.run([a.cli, "export", str(run), "--csv", "--out", str(tmp / "s.csv")],
                                                check=True, capture_output=True)))
        pq.append(timed(lambda: subprocess.run([a.cli, "export", str(run), "--parquet", "--out", str(tmp / "pq")],
                                               check=True, capture_output=True)))
        arrays.append(timed(lambda: attsync.open(run).states.R.sum()))
        frame.append(timed(lambda: pd.read_parquet(tmp / "pq" / "states.parquet")))
    m = {name: statistics.median(v) for name, v in
         [("csv", csv), ("pq", pq), ("arrays", arrays), ("frame", frame)]}
    rows = attsync.open(run).states.R.shape[0] * a.agents
    print(f"| {a.agents} agents, {rows} agent-samples, states.bin {size / 1e6:.0f} MB | wall s (median of {a.reps}) | vs CSV |")
    print("|---|---:|---:|")
    print(f"| `attsync export --csv` writes ({(tmp / 's.csv').stat().st_size / 1e6:.0f} MB) | {m['csv']:.3f} | 1 |")
    pq_mb = sum(f.stat().st_size for f in (tmp / "pq").iterdir()) / 1e6
    print(f"| `attsync export --parquet` writes ({pq_mb:.0f} MB) | {m['pq']:.3f} | {m['pq'] / m['csv']:.2f}× |")
    print(f"| `attsync.open(DIR).states` reads states.bin into arrays | {m['arrays']:.3f} | {m['arrays'] / m['csv']:.3f}× |")
    print(f"| `pd.read_parquet(states.parquet)` | {m['frame']:.3f} | {m['frame'] / m['csv']:.3f}× |")


if __name__ == "__main__":
    main()
