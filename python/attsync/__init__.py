"""attsync from Python: load a scenario, run it on the in-process engine
(or the process engine), and read the results as pandas DataFrames and
numpy arrays. docs/python.md is the manual.

    import attsync
    sc = attsync.load("scenarios/paper/timevarying.toml").set("simulation.duration", 10)
    run = attsync.run(sc)
    run.errors            # DataFrame: errors.csv
    run.states.R.shape    # (time, agent, 3, 3)
    run.summary["verdict"]

A run is the CLI's own (`attsync run`), called directly: its results
directory is byte-identical to the CLI's.
"""

from __future__ import annotations

import json
import math
import tempfile
from pathlib import Path
from typing import Any, Optional

import pandas as pd

from . import _attsync
from .states import States, StatesFormatError, read_states

__all__ = [
    "Heard",
    "LawContext",
    "LawError",
    "Run",
    "RunError",
    "Scenario",
    "ScenarioError",
    "States",
    "StatesFormatError",
    "load",
    "margin",
    "mc",
    "mc_merge",
    "open",
    "read_states",
    "run",
    "sweep",
]

__version__ = _attsync.__version__

#: A run that could not start or did not complete (``exit_code`` as the CLI's).
RunError = _attsync.RunError

#: A control law given with ``law=`` raised, or returned something other than
#: 3 finite numbers; the message names the agent, the step, the stage and the cause.
LawError = _attsync.LawError

# Pickled by reference as attsync.RunError and attsync.LawError (a trial that
# fails on a Dask worker raises the same exception in the client).
for _e in (RunError, LawError):
    _e.__module__ = "attsync"

import numpy as np  # noqa: E402


class Heard:
    """What an agent holds of one input: its gain ``a`` (3×3) and the value
    received, ``R``, ``omega``, ``sigma`` (the sender's ``(R̂, ω̂, σ̂)`` for the
    observer schemes, ``(R, ω, 0)`` for the observerless one)."""

    __slots__ = ("a", "R", "omega", "sigma")


class LawContext:
    """What a control law receives at one stage of one agent: what the
    built-in law receives (docs/python.md, "Your own law").

    ``agent``, ``step``, ``stage`` (0–3), ``t`` (the stage's time, s), ``dt``;
    the agent's measured ``R`` (3×3), ``omega``, and its observer's ``R_hat``,
    ``omega_hat``, ``sigma_hat``, ``omega_hat_dot``; ``neighbours`` (a list of
    :class:`Heard`, in id order), ``leader`` (a :class:`Heard`, or None when
    the agent does not hear it); the scheme's gains ``k_r``, ``k_omega``; the
    ``inertia`` the law assumes (3×3). The arrays are views of one array
    made for the call: copy what you keep."""

    __slots__ = ("agent", "step", "stage", "t", "dt", "R", "omega", "R_hat", "omega_hat",
                 "sigma_hat", "omega_hat_dot", "neighbours", "leader", "k_r", "k_omega", "inertia")


def _heard(v, o):
    h = Heard()
    h.a, h.R = v[o : o + 9].reshape(3, 3), v[o + 9 : o + 18].reshape(3, 3)
    h.omega, h.sigma = v[o + 18 : o + 21], v[o + 21 : o + 24]
    return h


def _adapter(f):
    """``f(ctx) -> torque`` as the native module calls a law: one flat tuple
    of numbers in (python/src/law.rs says its order), 3 floats out."""

    def call(when, data, n_nbrs, has_leader, k):
        c = LawContext()
        c.agent, c.step, c.stage, c.t, c.dt = when
        v = np.array(data)
        c.R, c.omega = v[0:9].reshape(3, 3), v[9:12]
        c.R_hat, c.omega_hat, c.sigma_hat = v[12:21].reshape(3, 3), v[21:24], v[24:27]
        c.omega_hat_dot, c.inertia = v[27:30], v[30:39].reshape(3, 3)
        heard = [_heard(v, o) for o in range(39, 39 + 24 * (n_nbrs + has_leader), 24)]
        c.leader = heard.pop(0) if has_leader else None
        c.neighbours = heard
        c.k_r, c.k_omega = k
        tau = np.asarray(f(c), dtype=float)
        if tau.shape != (3,):
            raise ValueError(f"the law returned an array of shape {tau.shape}, not (3,)")
        return (float(tau[0]), float(tau[1]), float(tau[2]))

    return call


class ScenarioError(ValueError):
    """A scenario that cannot be read or is not valid.

    ``file`` is the scenario file; ``issues`` every problem as ``(field,
    reason)`` (the field in the file's TOML path, ``--set SPEC`` for an
    override that does not apply); ``field`` and ``reason`` are the first's.
    """

    def __init__(self, message: str, file: str, issues: list):
        super().__init__(message)
        self.file = file
        self.issues = [tuple(i) for i in issues]
        self.field, self.reason = self.issues[0] if self.issues else ("", message)

    def __reduce__(self):
        return (ScenarioError, (str(self), self.file, self.issues))


def _native(f, *args, **kwargs):
    """Calls the native ``f``, its scenario errors as :class:`ScenarioError`."""
    try:
        return f(*args, **kwargs)
    except _attsync.ScenarioError as e:
        message, file, issues = e.args
        raise ScenarioError(message, file, issues) from None


def _toml_value(v: Any) -> str:
    """``v`` as a TOML value (what ``--set FIELD=VALUE`` reads)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{json.dumps(str(k))} = {_toml_value(x)}" for k, x in v.items()) + " }"
    if hasattr(v, "tolist"):  # numpy arrays and scalars
        return _toml_value(v.tolist())
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot set a value of type {type(v).__name__} (numbers, booleans, strings, lists, dicts)")


class Scenario:
    """A scenario file with overrides, validated at every change.

    ``set`` takes the same field paths as ``attsync run --set`` and is
    checked the same way: an error raises :class:`ScenarioError` naming the
    file, the field and the reason, and leaves the scenario as it was.
    """

    def __init__(self, path, sets: Optional[list] = None):
        self.path = Path(path)
        self.sets = list(sets or [])
        self.name, self.warnings = _native(_attsync.check, str(self.path), self.sets)

    def set(self, field: str, value: Any) -> "Scenario":
        """Sets ``field`` (a path such as ``simulation.duration`` or
        ``agent[2].omega``) to ``value``; returns the scenario (chainable)."""
        spec = f"{field}={_toml_value(value)}"
        name, warnings = _native(_attsync.check, str(self.path), self.sets + [spec])
        self.sets.append(spec)
        self.name, self.warnings = name, warnings
        return self

    def to_toml(self) -> str:
        """The effective scenario (the file with every override), as TOML."""
        return _native(_attsync.effective_toml, str(self.path), self.sets)

    def __repr__(self) -> str:
        sets = "".join(f" --set {s}" for s in self.sets)
        return f"<attsync.Scenario {self.name}: {self.path}{sets}>"


def load(path) -> Scenario:
    """Loads and validates the scenario file at ``path``."""
    return Scenario(path)


class Run:
    """A run's results directory, read lazily: ``errors``, ``states``,
    ``torques``, ``summary``."""

    def __init__(self, directory, _keep=None):
        self.dir = Path(directory)
        if not (self.dir / "summary.json").is_file():
            raise FileNotFoundError(f"{self.dir}: not a results directory (no summary.json)")
        self._keep = _keep  # a temporary directory that lives as long as this run
        self._errors = None
        self._states = None
        self._summary = None

    @property
    def summary(self) -> dict:
        """``summary.json``."""
        if self._summary is None:
            self._summary = json.loads((self.dir / "summary.json").read_text())
        return self._summary

    @property
    def errors(self) -> pd.DataFrame:
        """``errors.csv``: one row per sample, its columns."""
        if self._errors is None:
            self._errors = pd.read_csv(self.dir / "errors.csv", float_precision="round_trip")
        return self._errors

    @property
    def states(self) -> States:
        """``states.bin`` as numpy arrays (:class:`States`)."""
        if self._states is None:
            self._states = read_states(self.dir / "states.bin")
        return self._states

    @property
    def torques(self) -> pd.DataFrame:
        """The torque each agent applied at each sample (``t``, ``agent``,
        ``tau1``–``tau3``, N·m, body frame); NaN where none was applied (after
        the last step, while an agent is down) or a plug-in did not report it."""
        s = self.states
        T, n = s.tau.shape[:2]
        return pd.DataFrame(
            {
                "t": s.t.repeat(n),
                "agent": list(s.agent_ids) * T,
                "tau1": s.tau[:, :, 0].ravel(),
                "tau2": s.tau[:, :, 1].ravel(),
                "tau3": s.tau[:, :, 2].ravel(),
            }
        )

    def states_table(self) -> pd.DataFrame:
        """The agents' states in long form, one row per agent per sample:
        ``t``, ``agent``, ``r11``…``r33``, ``w1``…``w3``, ``r_hat11``…,
        ``w_hat1``…, ``s_hat1``…, ``tau1``…``tau3`` (the columns of
        ``attsync export --csv`` for agents)."""
        s = self.states
        T, n = s.R.shape[:2]
        cols = {"t": s.t.repeat(n), "agent": np.tile(s.agent_ids.astype(np.int64), T)}
        parts = [("r", s.R), ("w", s.omega), ("r_hat", s.R_hat), ("w_hat", s.omega_hat),
                 ("s_hat", s.sigma_hat), ("tau", s.tau)]
        for name, x in parts:
            if x.ndim == 4:
                for i in range(3):
                    for j in range(3):
                        cols[f"{name}{i + 1}{j + 1}"] = x[:, :, i, j].ravel()
            else:
                for i in range(3):
                    cols[f"{name}{i + 1}"] = x[:, :, i].ravel()
        return pd.DataFrame(cols)

    def leader_table(self) -> pd.DataFrame:
        """The leader's state per sample: ``t``, ``r11``…``r33`` (R₀),
        ``w1``…``w3`` (ω₀), ``s1``…``s3`` (σ₀)."""
        s = self.states
        cols = {"t": s.t}
        for i in range(3):
            for j in range(3):
                cols[f"r{i + 1}{j + 1}"] = s.R0[:, i, j]
        for name, v in [("w", s.omega0), ("s", s.sigma0)]:
            for i in range(3):
                cols[f"{name}{i + 1}"] = v[:, i]
        return pd.DataFrame(cols)

    def to_parquet(self, directory) -> Path:
        """Writes ``errors.parquet``, ``states.parquet`` (:meth:`states_table`,
        torques included) and ``leader.parquet`` (:meth:`leader_table`) into
        ``directory`` (created): tables pandas, polars and DuckDB read as they
        are, exact, and under half the CSVs' size (9.5 MB against 22 MB for
        the paper's 40 s run). Returns the directory."""
        d = Path(directory)
        d.mkdir(parents=True, exist_ok=True)
        for name, df in [("errors", self.errors), ("states", self.states_table()), ("leader", self.leader_table())]:
            tmp = d / f".{name}.parquet.partial"
            df.to_parquet(tmp, engine="pyarrow", index=False)
            tmp.replace(d / f"{name}.parquet")
        return d

    def plot(self, path=None, observer: Optional[bool] = None, title: Optional[str] = None):
        """The paper's figure of this run (matplotlib, optional): the errors
        against time on log axes in the paper's symbols (|R̃ᵢ|_I, ‖ωᵢ − ω₀‖),
        the observer's where the scheme has one, each agent in the look
        ``errors.svg`` and the 3D view give it (colour-blind-safe colour and
        dash), the ``--set`` changes in the title. With ``path`` it is also
        written there (``.pdf``, ``.svg``, ``.png``). Returns the
        ``matplotlib.figure.Figure``."""
        from . import plot as _plot

        fig = _plot.figure(self.errors, self.summary, observer=observer, title=title)
        if path is not None:
            _plot.save(fig, path)
        return fig

    @property
    def complete(self) -> bool:
        """Whether the run reached its horizon (``summary["complete"]``)."""
        return bool(self.summary.get("complete"))

    def __repr__(self) -> str:
        s = self.summary
        return f"<attsync.Run {s.get('scenario')} ({s.get('engine')}, t = {s.get('t_end')} s): {self.dir}>"


def run(scenario, engine: str = "in-process", threads: Optional[int] = None, out=None, law=None) -> Run:
    """Runs ``scenario`` (a :class:`Scenario` or a path) as ``attsync run``
    does, on ``engine`` (``"in-process"`` or ``"processes"``).

    ``out``: the results directory to write (as ``--out``; then ``attsync
    verify`` accepts it); without it the results go to a temporary directory
    removed with the returned :class:`Run`. A run that stops early (it
    diverged, a node failed, Ctrl-C) still returns its results so far:
    ``Run.complete`` is false and ``Run.summary["incomplete_reason"]`` says
    why (Ctrl-C then raises ``KeyboardInterrupt``); a run that cannot start
    raises :class:`RunError`.

    ``law``: a function ``f(ctx) -> torque`` (3 numbers, N·m, body frame)
    called for each agent at each stage with a :class:`LawContext`, in place
    of the scheme's law (the observers stay the model's; the actuator's
    limits still apply). In-process, on one thread, deterministic. A law
    that raises or returns anything but 3 finite numbers stops the run at
    that step and raises :class:`LawError` naming the agent, the step and the
    cause (the results so far are kept, as a diverged run's).
    """
    if not isinstance(scenario, Scenario):
        scenario = load(scenario)
    keep = None
    if out is None:
        keep = tempfile.TemporaryDirectory(prefix="attsync-")
        out = Path(keep.name) / "results"
    adapter = None if law is None else _adapter(law)
    _native(_attsync.run, str(scenario.path), scenario.sets, Path(out), engine, threads, adapter)
    return Run(out, _keep=keep)


def open(results_dir) -> Run:  # noqa: A001 (the API's name)
    """Reads a results directory written by ``attsync run`` or :func:`run`."""
    return Run(results_dir)



def _scenario(scenario) -> Scenario:
    return scenario if isinstance(scenario, Scenario) else load(scenario)


def _rows(out, csv_name: str, write) -> pd.DataFrame:
    """Calls ``write(directory)`` with ``out`` (a temporary directory if
    None) and reads its ``csv_name``; the directory is in
    ``DataFrame.attrs["dir"]`` when kept."""
    keep = None
    if out is None:
        keep = tempfile.TemporaryDirectory(prefix="attsync-")
        out = Path(keep.name) / "results"
    try:
        write(Path(out))
        df = pd.read_csv(Path(out) / csv_name, float_precision="round_trip")
    finally:
        if keep is not None:
            keep.cleanup()
    if keep is None:
        df.attrs["dir"] = str(out)
    return df


def _table(native, scenario, out, csv_name, *args, **kwargs) -> pd.DataFrame:
    """Runs ``native`` into ``out`` and reads its ``csv_name`` (:func:`_rows`)."""
    sc = _scenario(scenario)
    return _rows(out, csv_name, lambda o: _native(native, str(sc.path), sc.sets, *args, o, **kwargs))


def sweep(scenario, param: str, values, engine: str = "in-process", out=None, grid=None,
          jobs: Optional[int] = None, find_margin: bool = False) -> pd.DataFrame:
    """``attsync sweep``: one run per value of ``param`` (and, with ``grid =
    (param2, values2)``, per pair: the stability chart); the rows of
    ``sweep.csv`` (verdict, decay rate, settle time per value).
    ``find_margin`` bisects for the first value that does not converge (each
    run then goes on until its verdict is final)."""
    second = None if grid is None else (grid[0], [_toml_value(v) for v in grid[1]])
    return _table(_attsync.sweep, scenario, out, "sweep.csv", param, [_toml_value(v) for v in values],
                  grid=second, engine=engine, jobs=jobs, find_margin=find_margin)


def mc(scenario, trials: int, seed: int = 0, engine: str = "in-process", out=None,
       jobs: Optional[int] = None, law=None, client=None, shards: Optional[int] = None) -> pd.DataFrame:
    """``attsync mc``: ``trials`` runs with initial conditions (and the
    scenario's ``[[monte_carlo.param]]`` fields) drawn from ``seed``; the
    rows of ``trials.csv`` (one per trial: its draws, verdict, settle time).
    ``law`` as for :func:`run`.

    ``client``: a ``dask.distributed.Client``: the trials run on its
    cluster, in ``shards`` slices (default: four per worker, at most one
    per trial), each slice a task running ``attsync mc --shard K/N`` on a
    worker (``jobs`` trials at once there; default: the worker's cores), then
    merged here as ``attsync mc merge`` does. Every trial draws from its own
    seed, so the results (and the files in ``out``) are those of a local
    run, bit for bit. The workers need the ``attsync`` package, not the
    scenario file (its text is sent)."""
    if client is not None:
        return _mc_on(client, _scenario(scenario), int(trials), int(seed), engine, out, jobs, law, shards)
    adapter = None if law is None else _adapter(law)
    return _table(_attsync.mc, scenario, out, "trials.csv", int(trials), int(seed), engine=engine, jobs=jobs,
                  law=adapter)


#: The files of a shard that ``attsync mc merge`` reads.
_SHARD_FILES = ("trials.csv", "initial.csv", "mc.json")


def _mc_shard(name: str, text: str, sets: list, trials: int, seed: int, engine: str, jobs, law,
              shard: tuple) -> dict:
    """One slice of a Monte Carlo, run where this is called (a Dask task):
    the scenario's text written under its own file name (its name is the
    file's stem), the shard run, its files returned as text."""
    with tempfile.TemporaryDirectory(prefix="attsync-shard-") as tmp:
        path = Path(tmp) / name
        path.write_text(text)
        out = Path(tmp) / "out"
        adapter = None if law is None else _adapter(law)
        _native(_attsync.mc, str(path), list(sets), trials, seed, out, engine=engine, jobs=jobs, law=adapter,
                shard=shard)
        return {f: (out / f).read_text() for f in _SHARD_FILES}


def _mc_on(client, sc: Scenario, trials: int, seed: int, engine: str, out, jobs, law, shards) -> pd.DataFrame:
    """:func:`mc` on a Dask cluster: one task per shard, merged here."""
    if shards is None:
        workers = len(client.scheduler_info().get("workers", {})) or 1
        shards = min(trials, 4 * workers)
    shards = int(shards)
    if not 1 <= shards <= trials:
        raise ValueError(f"shards = {shards}: between 1 and the number of trials ({trials})")
    text = sc.path.read_text()
    tasks = [
        client.submit(_mc_shard, sc.path.name, text, sc.sets, trials, seed, engine, jobs, law, (k, shards),
                      pure=False)
        for k in range(1, shards + 1)
    ]
    parts = client.gather(tasks)
    return _rows(out, "trials.csv", lambda o: _merge_parts(parts, o))


def _merge_parts(parts: list, out: Path) -> None:
    """Writes each shard's files (as :func:`_mc_shard` returned them) into
    a directory of its own, then merges them into ``out``."""
    with tempfile.TemporaryDirectory(prefix="attsync-shards-") as tmp:
        dirs = []
        for k, files in enumerate(parts, start=1):
            d = Path(tmp) / f"shard-{k}"
            d.mkdir()
            for f, content in files.items():
                (d / f).write_text(content)
            dirs.append(str(d))
        _attsync.mc_merge(dirs, out)


def mc_merge(dirs, out) -> pd.DataFrame:
    """``attsync mc merge DIRS… --out OUT``: joins the directories of one
    Monte Carlo's shards (``attsync mc --shard K/N``, every K of one N) into
    ``out``, the files one run of every trial writes, byte for byte;
    returns the rows of its ``trials.csv``. Shards that do not make one
    whole Monte Carlo raise :class:`RunError` naming the directory and what
    is wrong (nothing is written)."""
    _attsync.mc_merge([str(d) for d in dirs], Path(out))
    df = pd.read_csv(Path(out) / "trials.csv", float_precision="round_trip")
    df.attrs["dir"] = str(out)
    return df


def margin(scenario) -> dict:
    """``attsync margin --json``: the exact delay margin of the scenario's
    linearisation (docs/verdicts.md)."""
    sc = _scenario(scenario)
    return json.loads(_native(_attsync.margin, str(sc.path), sc.sets))
