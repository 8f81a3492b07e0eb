"""friction-node from Python: a physics-based estimate of sliding friction.

The transient mixed-lubrication model of Driesen et al. 2023 (transient
Reynolds equation with cavitation, Greenwood-Williamson asperity contact,
load balance with inertia), the same Rust code as the ``friction-node``
command and node. SI units throughout: m/s, N, s, Pa, degC.

>>> import numpy as np, friction_node as fn
>>> m = fn.Model(**{"solver.cells": 64})
>>> t = np.arange(0, 2.0, m.dt)
>>> run = m.run(t, np.sin(2 * np.pi * t))          # dict of numpy arrays
>>> e = m.step(0.1)                                # one estimate
>>> curve = fn.stribeck(np.logspace(-4, 0, 20))

Configurations: ``Model(config)`` takes a parameter file (path), a dict of
parameters (nested, or dotted keys), or None for the built-in default; any
dotted-key overrides follow, as keyword arguments
(``Model(**{"contact.load_n": 5720})``) or ``overrides={...}``. They are
checked exactly like the command line's ``--set`` (unknown keys and
out-of-range values raise ``ValueError`` naming the key).

Errors: ``ValueError`` for bad configuration and input (non-finite or
mismatched arrays, unknown keys, a file that is not a bag), ``OSError``
(``FileNotFoundError``) for files. Long calls release the GIL.

The fleet functions (many bags on a Dask cluster) are in
``friction_node.fleet`` (``pip install ".[fleet]"``).
"""

from __future__ import annotations

import json
import os
import tempfile
from typing import Any, Dict, Iterable, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _core
from ._core import Estimate, LOOP_METRIC_COLUMNS, SIMULATE_COLUMNS, STRIBECK_COLUMNS, __version__

__all__ = [
    "Model",
    "Estimate",
    "stribeck",
    "replay",
    "fit",
    "ReplayResult",
    "FitResult",
    "SIMULATE_COLUMNS",
    "STRIBECK_COLUMNS",
    "LOOP_METRIC_COLUMNS",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]
Config = Union[None, PathLike, Mapping[str, Any]]


def _value_text(v: Any) -> str:
    """A Python value as the text of a ``--set key=value`` override."""
    if isinstance(v, str):
        return v
    if isinstance(v, (bool, np.bool_)):
        return "true" if v else "false"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        return repr(float(v))
    return json.dumps(v)


def _overrides(overrides: Optional[Mapping[str, Any]], extra: Mapping[str, Any]) -> list:
    merged: Dict[str, Any] = dict(overrides or {})
    merged.update(extra)
    out = []
    for k, v in merged.items():
        if not isinstance(k, str) or not k:
            raise ValueError(f"override key {k!r}: expected a dotted configuration key")
        out.append(f"{k}={_value_text(v)}")
    return out


def _flatten(d: Mapping[str, Any], prefix: str = "") -> Dict[str, Any]:
    out: Dict[str, Any] = {}
    for k, v in d.items():
        key = f"{prefix}{k}"
        if isinstance(v, Mapping):
            out.update(_flatten(v, key + "."))
        else:
            out[key] = v
    return out


def _config_args(config: Config) -> Tuple[Optional[str], Optional[str], list]:
    """(yaml text, path, overrides from a dict) of a configuration argument."""
    if config is None:
        return None, None, []
    if isinstance(config, Mapping):
        # A dict of parameters: the defaults with these keys set, checked
        # like --set overrides (so an unknown key is named).
        return None, None, _overrides(_flatten(config), {})
    if isinstance(config, (str, os.PathLike)):
        path = os.fspath(config)
        if "\n" in path:
            return path, None, []
        return None, path, []
    raise TypeError(
        f"config: expected a file path, a dict of parameters or None, got {type(config).__name__}"
    )


def _path(p: Optional[PathLike]) -> Optional[str]:
    """A path argument as text (None stays None)."""
    return None if p is None else os.fspath(p)


def _array(x: Any, name: str, n: Optional[int] = None) -> np.ndarray:
    try:
        a = np.ascontiguousarray(x, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: not an array of numbers ({e})") from None
    if a.ndim == 0:
        if n is None:
            a = a.reshape(1)
        else:
            a = np.full(n, float(a))
    if a.ndim != 1:
        raise ValueError(f"{name}: expected a 1-D array, got shape {a.shape}")
    if n is not None and a.shape[0] != n:
        raise ValueError(
            f"{name} has {a.shape[0]} samples, t has {n}: the arrays must have the same length"
        )
    bad = ~np.isfinite(a)
    if bad.any():
        k = int(np.argmax(bad))
        raise ValueError(f"{name}[{k}] = {a[k]}: not a finite number")
    return a


class Model:
    """One lubricated contact's model, stepped in fixed or given steps.

    ``Model(config=None, overrides=None, **dotted_keys)``: ``config`` is a
    parameter file path (or its text), a dict of parameters, or None for
    the built-in default (``launch-config/default.yaml``). The model starts
    in the steady state at rest under ``contact.load_n``.
    """

    def __init__(self, config: Config = None, overrides: Optional[Mapping[str, Any]] = None, **keys: Any):
        yaml, path, from_dict = _config_args(config)
        self._core = _core.Model(yaml=yaml, path=path, overrides=from_dict + _overrides(overrides, keys))

    @property
    def dt(self) -> float:
        """The configured step ``solver.dt_s``, s."""
        return self._core.dt

    @property
    def load_n(self) -> float:
        """The configured load ``contact.load_n``, N."""
        return self._core.load_n

    def config_yaml(self) -> str:
        """The complete configuration as a parameter file."""
        return self._core.config_yaml()

    def step(self, velocity: float, load: Optional[float] = None, dt: Optional[float] = None) -> Estimate:
        """Advance one step (``dt``: default ``solver.dt_s``, BDF2; another
        length is one backward-Euler step) at ``velocity`` m/s under ``load``
        N (default ``contact.load_n``). A velocity or load outside the
        configuration's envelope (``node.max_abs_velocity_m_s``,
        ``node.min_load_n``..``node.max_load_n``: the rule ``run``, the command
        line and the node apply) raises ``ValueError``. A numerical outcome is
        not an error: the estimate's ``status`` says what the solver did."""
        return self._core.step(float(velocity), None if load is None else float(load), None if dt is None else float(dt))

    def reset(self, velocity: float = 0.0, load: Optional[float] = None) -> Estimate:
        """Restart from the steady state (the squeeze-film history is forgotten)."""
        return self._core.reset(float(velocity), None if load is None else float(load))

    def set_parameter(self, key: str, value: Any) -> None:
        """Change a live parameter between steps, as the node's ROS 2
        parameters and the C API's ``fn_model_set_parameter`` do: ``key`` a
        dotted configuration key (``contact.boundary_friction``), ``value`` a
        number, a bool or YAML text. The squeeze-film history and the
        pre-sliding displacement are kept. An unknown or read-only key, a
        wrong type, a value out of range or a change of grid
        (``solver.cells``) raises ``ValueError`` naming the key and value.
        It rebuilds the model's tables: call it between steps, not inside a
        real-time loop."""
        self._core.set_parameter(str(key), value)

    def set_temperature(self, temperature_c: float) -> None:
        """The lubricant temperature, degC (with ``lubricant.viscosity_model:
        vogel`` the viscosity follows it). A temperature outside [-60, 300]
        degC, at or below Vogel's C, or giving a viscosity outside the
        model's (1e-5, 100] Pa s raises ``ValueError`` (the rule of every
        entry point)."""
        self._core.set_temperature(float(temperature_c))

    def run(self, t: Any, velocity: Any, load: Any = None, temperature: Any = None, as_frame: bool = False):
        """A whole run, as ``simulate`` does it: the steady state at the first
        sample, then one step to each next time (``t`` strictly increasing, s;
        steps of ``solver.dt_s`` continue BDF2). ``velocity`` m/s, ``load`` N
        and ``temperature`` degC are arrays of ``len(t)`` (or scalars).

        Returns a dict of numpy arrays, one per ``simulate`` column (row 0 is
        the initial steady state), or a pandas DataFrame with
        ``as_frame=True``. The GIL is released while the model runs; Ctrl-C
        (``KeyboardInterrupt``) stops it within about 10 000 steps."""
        t = _array(t, "t")
        n = t.shape[0]
        v = _array(velocity, "velocity", n)
        f = None if load is None else _array(load, "load", n)
        tc = None if temperature is None else _array(temperature, "temperature", n)
        cols = _columns(self._core.run(t, v, f, tc))
        return _frame(cols) if as_frame else cols

    def __repr__(self) -> str:
        return repr(self._core)


def _columns(d: dict) -> dict:
    for k in ("status", "regime", "command_status", "calibrated_range", "contact"):
        if k in d:
            d[k] = np.asarray(d[k], dtype=object)
    return d


def _frame(cols: Mapping[str, np.ndarray]):
    import pandas as pd

    return pd.DataFrame(cols)


def stribeck(
    velocities: Any,
    load: Optional[float] = None,
    config: Config = None,
    overrides: Optional[Mapping[str, Any]] = None,
    as_frame: bool = False,
    **keys: Any,
):
    """Steady states (the Stribeck curve) at ``velocities`` m/s under
    ``load`` N (default ``contact.load_n``): the ``stribeck`` columns as a
    dict of numpy arrays, in the input order (or a DataFrame)."""
    yaml, path, from_dict = _config_args(config)
    v = _array(velocities, "velocities")
    cols = _columns(
        _core.stribeck(v, None if load is None else float(load), yaml=yaml, path=path,
                       overrides=from_dict + _overrides(overrides, keys))
    )
    return _frame(cols) if as_frame else cols


class ReplayResult:
    """What ``replay`` returns.

    Attributes: ``estimates`` (DataFrame: the ``simulate`` columns,
    ``stamp_ns``, ``command_status`` and ``calibrated_range``, one row per
    step), ``cycles`` (DataFrame of loop metrics per cycle), ``summary``
    (dict: steps, span_s, wall_s, commands_rejected,
    steps_outside_calibrated_range, outside_share by contact, ...), ``identical`` (True/False when the bag
    holds recorded estimates to compare with, else None) and
    ``deviations`` (field, largest difference, step) when not identical.
    A recording of several contacts replays every contact: ``estimates``
    then has a ``contact`` column, ``summary["contacts"]`` lists (name,
    identical, steps compared) per contact, and ``cycles`` are the first
    contact's.
    """

    def __init__(self, raw: dict):
        import pandas as pd

        self.estimates = pd.DataFrame(_columns(raw["estimates"]))
        self.cycles = pd.DataFrame(raw["cycles"])
        self.summary = raw["summary"]
        self.identical = self.summary["identical"]
        self.deviations = self.summary["deviations"]

    def __repr__(self) -> str:
        s = self.summary
        verdict = {None: "no recorded estimates", True: "bit-identical", False: "DIFFERS"}[self.identical]
        return (
            f"ReplayResult({s['bag']}: {s['steps']} steps over {s['span_s']:.3f} s, "
            f"{len(self.cycles)} cycles, {verdict})"
        )


def replay(
    bag: PathLike,
    config: Optional[PathLike] = None,
    overrides: Optional[Mapping[str, Any]] = None,
    topic: Optional[str] = None,
    joint: Optional[str] = None,
    load_topic: Optional[str] = None,
    temperature_topic: Optional[str] = None,
    velocity_map: Optional[str] = None,
    load_map: Optional[str] = None,
    out: Optional[PathLike] = None,
    report: Optional[PathLike] = None,
) -> ReplayResult:
    """Re-run the model over the velocity recorded in a bag (MCAP, rosbag2
    ``.db3`` or a rosbag2 directory), as ``friction-node replay`` does: the
    configuration recorded in the bag unless ``config`` (a file) is given,
    ``overrides`` on top. ``out`` (``.csv`` or ``.mcap``) and ``report`` (a
    directory) write the command's files, atomically."""
    raw = _core.replay(
        os.fspath(bag),
        config_path=_path(config),
        overrides=_overrides(overrides, {}),
        topic=topic,
        joint=joint,
        load_topic=load_topic,
        temperature_topic=temperature_topic,
        velocity_map=velocity_map,
        load_map=load_map,
        out=_path(out),
        report_dir=_path(report),
    )
    return ReplayResult(raw)


class FitResult:
    """What ``fit`` returns.

    ``parameters`` (DataFrame: name, value, std_error, ci95_low, ci95_high,
    start, bounds, at_bound; on a time series the errors come from
    ``error_batches`` contiguous batches of the residuals, 0 where every
    sample counted as independent), ``converged``, ``train_rms_n``,
    ``held_out_rms_n``, ``models`` (DataFrame, one row per model: ours and,
    with ``baselines=True``, Coulomb + viscous, Stribeck, LuGre on the same
    data with the same optimiser), ``direction_table`` (with baselines: every
    model's level and offset error per held-out source, markdown; the level
    error is the friction too large or small in magnitude, the offset error
    the part that is the same in both directions of motion), ``fitted_yaml``
    (the complete fitted parameter file), ``calibrated_range`` (dict: where
    the calibration holds, as the fitted file's ``calibrated_range``: the
    speeds by direction, loads and temperatures where they were inputs, a
    time series' largest acceleration, in the contact's units, and the
    training error with its sample count; None when the data give no
    range), ``summary`` (the command's summary text), ``raw``.
    """

    def __init__(self, raw: dict):
        import pandas as pd

        self.raw = raw
        self.parameters = pd.DataFrame(raw["parameters"])
        self.error_batches = raw["error_batches"]
        self.converged = raw["converged"]
        self.train_rms_n = raw["train_rms_n"]
        self.held_out_rms_n = raw["held_out_rms_n"]
        self.fitted_yaml = raw["fitted_yaml"]
        self.calibrated_range = raw.get("calibrated_range")
        self.summary = raw["summary"]
        self.notes = raw["notes"]
        rows = []
        for m in raw["models"]:
            row = {
                "model": m["label"],
                "converged": m["converged"],
                "termination": m["termination"],
                "cost_n2": m["cost_n2"],
                "train_rms_n": m["train_rms_n"],
                "held_out_rms_n": m["held_out_rms_n"],
            }
            row.update({p["name"]: p["value"] for p in m["parameters"]})
            rows.append(row)
        self.models = pd.DataFrame(rows)
        self.models_table = raw.get("models_table")
        self.direction_table = raw.get("direction_table")

    def value(self, name: str) -> float:
        """The fitted value of parameter ``name``."""
        hit = self.parameters[self.parameters["name"] == name]
        if hit.empty:
            raise KeyError(f"{name!r} was not fitted (fitted: {', '.join(self.parameters['name'])})")
        return float(hit["value"].iloc[0])

    def __repr__(self) -> str:
        vals = ", ".join(f"{r.name}={r.value:.4g}±{r.std_error:.2g}" for r in self.parameters.itertuples())
        return f"FitResult({vals}; train RMS {self.train_rms_n:.4g} N, converged={self.converged})"


Table = Mapping[str, Any]
"""Columns in memory: a dict of equal-length 1-D arrays (as ``Model.run``
returns) or a pandas DataFrame, named as a CSV file's header would be."""


def _is_table(x: Any) -> bool:
    return isinstance(x, Mapping) or (hasattr(x, "columns") and hasattr(x, "items"))


def _write_table(table: Table, path: str, what: str) -> None:
    """``table``'s columns as CSV at ``path``: numbers in the shortest form
    that reads back to the same double, text columns as they are."""
    cols = [(str(k), np.asarray(v)) for k, v in table.items()]
    if not cols:
        raise ValueError(f"{what}: a table without columns")
    n = None
    for name, c in cols:
        if not name or any(ch in name for ch in ",\n\r\""):
            raise ValueError(f"{what}: column name {name!r} must be non-empty, without commas, quotes or line breaks")
        if c.ndim != 1:
            raise ValueError(f"{what}: column {name!r} has shape {c.shape}; a column is one-dimensional")
        if n is not None and len(c) != n:
            raise ValueError(f"{what}: column {name!r} has {len(c)} rows, column {cols[0][0]!r} has {n}")
        n = len(c)
    text = []
    for name, c in cols:
        if c.dtype.kind in "biuf":
            bad = np.flatnonzero(~np.isfinite(c.astype(float)))
            if bad.size:
                raise ValueError(f"{what}: column {name!r} is {c[bad[0]]} at row {bad[0]} (counting from 0): every sample must be finite")
            text.append([repr(float(x)) for x in c])
        else:
            cells = [str(x) for x in c]
            bad = next((x for x in cells if any(ch in x for ch in ",\n\r\"")), None)
            if bad is not None:
                raise ValueError(f"{what}: column {name!r} holds {bad!r}: a cell without commas, quotes or line breaks")
            text.append(cells)
    with open(path, "w", encoding="utf-8") as f:
        f.write(",".join(name for name, _ in cols) + "\n")
        for row in zip(*text):
            f.write(",".join(row) + "\n")


def _as_files(items: Sequence[Any], tmp: str, stem: str) -> list:
    """Paths as they are; each table in memory written to ``tmp`` as
    ``STEM-K.csv`` (the name the report gives it)."""
    out = []
    for k, d in enumerate(items, start=1):
        if _is_table(d):
            path = os.path.join(tmp, f"{stem}-{k}.csv")
            _write_table(d, path, f"{stem} {k}")
            out.append(path)
        else:
            out.append(os.fspath(d))
    return out


def fit(
    data: Union[PathLike, Table, Sequence[Union[PathLike, Table]]],
    fit: Union[str, Sequence[str]],
    config: Optional[PathLike] = None,
    overrides: Optional[Mapping[str, Any]] = None,
    bounds: Optional[Mapping[str, Tuple[float, float]]] = None,
    start: Optional[Mapping[str, float]] = None,
    holdout: float = 0.0,
    validate: Iterable[Union[PathLike, Table]] = (),
    baselines: bool = False,
    starts: int = 3,
    global_points: int = 16,
    seed: int = 1,
    max_evaluations: int = 200,
    columns: Optional[Sequence[str]] = None,
    skip: int = 0,
    delimiter: str = "auto",
    time: Optional[str] = None,
    velocity: str = "velocity_m_s",
    friction: str = "friction_n",
    load: Optional[str] = None,
    temperature: Optional[str] = None,
    smooth: float = 0.05,
    map: Optional[Mapping[str, float]] = None,
    velocity_topic: Optional[str] = None,
    friction_topic: Optional[str] = None,
    joint: Optional[str] = None,
    load_topic: Optional[str] = None,
    temperature_topic: Optional[str] = None,
    out: Optional[PathLike] = None,
    report: Optional[PathLike] = None,
    progress: bool = False,
    rotary: bool = False,
    jacobian: str = "secant",
    later_runs: str = "full",
    linear_keys: str = "solved",
    cheap_keys: str = "profiled",
) -> FitResult:
    """Calibrate configuration keys (and input-map coefficients) to
    recorded friction, as ``friction-node fit`` does (same arguments, same
    defaults, same messages): ``data`` CSV files or bags, or tables in
    memory (a dict of equal-length arrays, as ``Model.run`` returns, or a
    pandas DataFrame, named as a CSV header: ``t_s``, ``velocity_m_s``,
    ``friction_n``...; the report calls them ``data-1.csv``...; so does
    ``validate``, ``validate-1.csv``...), ``fit`` the keys
    (e.g. ``["roughness.sigma_m", "contact.boundary_friction"]``), ``bounds``
    ``{key: (lo, hi)}``, ``start`` ``{key: value}``. ``out`` writes the
    fitted parameter file, ``report`` the summary, tables and plots.
    ``fit=["auto", ...]`` lets the data choose the physical terms (the
    names after ``auto`` are fitted as well); ``rotary=True`` takes a
    joint's velocity in rad/s and friction in N·m (the lever arm and the
    contact's load are chosen from the data); with ``velocity`` and
    ``friction`` left at their defaults it reads a joint's columns by name
    (``velocity_rad_s``, or ``velocity_deg_s`` / ``velocity_rpm`` converted
    to rad/s; ``friction_nm``, ``torque_nm``..., or ``torque_nmm`` in
    N·mm converted to N·m); without it, a table with no ``velocity_m_s``
    but ``velocity_mm_s``, ``velocity_m_min`` or ``velocity_mm_min`` is
    read in m/s, and one with no ``friction_n`` but ``force_n``,
    ``friction_mn`` or ``friction_kn`` is read in N. ``jacobian`` (``"secant"`` or
    ``"differences"``), ``later_runs`` (``"full"`` or ``"valley"``),
    ``linear_keys`` (``"solved"`` or ``"searched"``) and ``cheap_keys``
    (``"profiled"`` or ``"searched"``) choose how the search runs, as
    ``--jacobian``, ``--later-runs``, ``--linear-keys`` and ``--cheap-keys``
    do."""
    if isinstance(data, (str, os.PathLike)) or _is_table(data):
        data = [data]
    if isinstance(validate, (str, os.PathLike)) or _is_table(validate):
        validate = [validate]
    if isinstance(fit, str):
        fit = [k for k in fit.split(",") if k.strip()]
    # Tables in memory are written for the fit and removed after it.
    with tempfile.TemporaryDirectory(prefix="friction-node-fit-") as tmp:
        raw = _core.fit(
            _as_files(list(data), tmp, "data"),
            list(fit),
            config_path=_path(config),
            overrides=_overrides(overrides, {}),
            bounds=[(k, float(lo), float(hi)) for k, (lo, hi) in (bounds or {}).items()],
            starts_at=[(k, float(v)) for k, v in (start or {}).items()],
            holdout=float(holdout),
            validate=_as_files(list(validate), tmp, "validate"),
            baselines=bool(baselines),
            starts=int(starts),
            global_points=int(global_points),
            seed=int(seed),
            max_evaluations=int(max_evaluations),
            columns=None if columns is None else list(columns),
            skip=int(skip),
            delimiter=delimiter,
            time=time,
            velocity=velocity,
            friction=friction,
            load=load,
            temperature=temperature,
            smooth=float(smooth),
            map=[(k, float(v)) for k, v in (map or {}).items()],
            velocity_topic=velocity_topic,
            friction_topic=friction_topic,
            joint=joint,
            load_topic=load_topic,
            temperature_topic=temperature_topic,
            out=_path(out),
            report_dir=_path(report),
            progress=bool(progress),
            rotary=bool(rotary),
            jacobian=jacobian,
            later_runs=later_runs,
            linear_keys=linear_keys,
            cheap_keys=cheap_keys,
        )
    return FitResult(raw)
