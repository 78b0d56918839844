"""``Run.plot()`` (issue 36, part 5): the paper's figure from a run, with
the paper's symbols, axis labels with units, log axes, every agent in the
palette's look (the same as errors.svg and the 3D view), the ``--set``
changes in the title; written as PDF and SVG.

Run by tests/tests/python_package.rs (ATTSYNC_REPO)."""

import os
from pathlib import Path

import matplotlib.colors as mcolors

import attsync
from attsync import plot as aplot

REPO = Path(os.environ["ATTSYNC_REPO"])
PAPER = REPO / "scenarios/paper/timevarying.toml"
OBSERVERLESS = REPO / "scenarios/paper/constant-observerless.toml"


def test_the_paper_figure_has_its_symbols_labels_palette_and_sets(tmp_path):
    run = attsync.run(attsync.load(PAPER).set("simulation.duration", 2).set("network.delay", 0.05))
    fig = run.plot(tmp_path / "paper.pdf")
    assert (tmp_path / "paper.pdf").read_bytes()[:5] == b"%PDF-"
    axes = fig.axes
    # The time-varying scheme has an observer: four panels.
    assert len(axes) == 4
    labels = [ax.get_ylabel() for ax in axes]
    assert labels[0] == r"$|\tilde R_i|_I$" and "rad/s" in labels[1] and r"\hat" in labels[2]
    assert axes[-1].get_xlabel() == "$t$ (s)"
    assert all(ax.get_yscale() == "log" for ax in axes)
    # The title says what was changed: a delayed run is not titled as the undelayed one.
    assert "network.delay=0.05" in fig._suptitle.get_text()
    assert "simulation.duration=2" in fig._suptitle.get_text()
    # Seven agents, seven colours of the palette, in id order.
    lines = axes[0].get_lines()
    assert len(lines) == 7
    for k, line in enumerate(lines):
        assert mcolors.to_hex(line.get_color()).upper() == aplot.COLOURS[k]
    assert len({mcolors.to_hex(l.get_color()) for l in lines}) == 7
    assert [t.get_text() for t in axes[0].get_legend().get_texts()] == [f"agent {i}" for i in range(1, 8)]


def test_an_observerless_run_has_two_panels_and_svg_is_written(tmp_path):
    run = attsync.run(attsync.load(OBSERVERLESS).set("simulation.duration", 1))
    fig = run.plot(tmp_path / "f.svg")
    assert len(fig.axes) == 2
    assert (tmp_path / "f.svg").read_text().lstrip().startswith("<?xml")
    assert not list(tmp_path.glob(".*partial"))


def test_agents_past_the_colours_are_told_apart_by_their_dashes():
    looks = {(aplot.look(k)["color"], str(aplot.look(k)["linestyle"])) for k in range(28)}
    assert len(looks) == 28
    assert aplot.look(0)["linestyle"] == "-" and aplot.look(7)["linestyle"] != "-"
    assert aplot.look(7)["color"] == aplot.look(0)["color"]
