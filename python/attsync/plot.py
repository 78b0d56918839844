"""``Run.plot()``: a run's errors as the paper draws them (its Figures 2–4),
ready for a paper: the paper's symbols, axis labels with units, log scales,
every agent in the look ``errors.svg`` and the 3D view give it (a
colour-blind-safe colour and a dash pattern, orchestrator/src/results/
palette.rs, exported by the native module), the run's ``--set`` changes in
the title. matplotlib is an optional dependency (``pip install
attsync[plot]``); nothing here imports pyplot, so no GUI is needed."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import numpy as np
import pandas as pd

from . import _attsync

#: The palette's colours (agent k, 0-based: ``COLOURS[k % 7]``).
COLOURS = list(_attsync.PALETTE_COLOURS)
#: Its dash patterns, (drawn, gap) px at a 2 px line, (0, 0) solid
#: (agent k: ``DASHES[(k // 7) % 4]``).
DASHES = [tuple(d) for d in _attsync.PALETTE_DASHES]

#: The panels: errors.csv column, y label (mathtext), caption.
PANELS = [
    ("att_err", r"$|\tilde R_i|_I$", r"attitude error to the leader, $\tilde R_i = R_i R_0^\top$"),
    ("angvel_err", r"$\|\omega_i - \omega_0\|$ (rad/s)", "angular-velocity error to the leader"),
    ("obs_att_err", r"$|\hat R_i R_0^\top|_I$", "attitude error of the observer"),
    ("obs_angvel_err", r"$\|\hat\omega_i - \omega_0\|$ (rad/s)", "angular-velocity error of the observer"),
]


#: Past this many agents the legend is left out (it would cover the curves).
LEGEND_UP_TO = 16


def look(k: int) -> dict:
    """matplotlib line properties of agent ``k`` (0-based, in id order)."""
    on, off = DASHES[(k // len(COLOURS)) % len(DASHES)]
    # The palette's dashes are px at a 2 px line; matplotlib scales a dash
    # pattern by the line width, so they are given per unit of width.
    style = "-" if on == 0 else (0, (on / 2, off / 2))
    return {"color": COLOURS[k % len(COLOURS)], "linestyle": style, "linewidth": 1.5}


def title_of(summary: dict) -> str:
    """The scenario, the engine and every ``--set`` of the run."""
    t = f"{summary.get('scenario', '?')} ({summary.get('engine', '?')})"
    sets = summary.get("overrides") or []
    return t + (" · " + ", ".join(sets) if sets else "")


def figure(errors: pd.DataFrame, summary: dict, observer: Optional[bool] = None,
           title: Optional[str] = None, floor: float = 1e-16):
    """The figure of ``errors`` (errors.csv's rows) titled from ``summary``:
    the attitude and angular-velocity errors against time, then the
    observer's where the scheme has one (``observer``: force either way).
    Exact zeros are drawn at ``floor`` (a log axis has no 0)."""
    from matplotlib.figure import Figure

    has_observer = errors["obs_att_err"].notna().any()
    panels = PANELS if (has_observer if observer is None else observer) else PANELS[:2]
    fig = Figure(figsize=(7.0, 2.4 * len(panels) + 0.6), layout="constrained")
    axes = fig.subplots(len(panels), 1, sharex=True, squeeze=False)[:, 0]
    agents = sorted(errors["agent"].unique())
    for ax, (column, ylabel, caption) in zip(axes, panels):
        for k, agent in enumerate(agents):
            rows = errors[errors["agent"] == agent]
            y = np.maximum(rows[column].to_numpy(dtype=float), floor)
            ax.plot(rows["t"].to_numpy(), y, label=f"agent {agent}", **look(k))
        ax.set_yscale("log")
        ax.set_ylabel(ylabel)
        ax.set_title(caption, fontsize="medium")
        ax.grid(True, which="major", alpha=0.3)
    axes[-1].set_xlabel("$t$ (s)")
    if len(agents) <= LEGEND_UP_TO:
        axes[0].legend(ncol=min(len(agents), 4), fontsize="small", loc="upper right")
    fig.suptitle(title if title is not None else title_of(summary))
    return fig


def save(fig, path) -> Path:
    """Writes ``fig`` to ``path`` (PDF, SVG, PNG: by its extension), atomically."""
    path = Path(path)
    tmp = path.with_name(f".{path.name}.partial")
    fig.savefig(tmp, format=path.suffix.lstrip(".") or None)
    tmp.replace(path)
    return path
