"""A fleet of bags on Dask: replay and calibration, one task per bag.

``pip install ".[fleet]"`` (dask, distributed, fsspec). Without a client the
work runs on this machine (a local cluster on 127.0.0.1, one single-threaded
worker process per core); with ``client=distributed.Client("tcp://host:8786")``
or ``client="tcp://host:8786"`` the same call runs unchanged on an existing
cluster, whose workers need this package installed.

>>> from friction_node import fleet
>>> r = fleet.replay("bags/**/*.mcap", out_dir="replayed/")
>>> r.bags        # one row per bag: steps, rate, verdict, error
>>> r.cycles      # one row per cycle of every bag: loop metrics

A bag that fails (missing, corrupt, no velocity topic) does not stop the
others: its row has ``ok = False`` and the error text, and nothing is written
for it (outputs are written to a temporary file and moved into place only
when complete). Bags may be local paths, globs (``**`` recurses) or any URL
fsspec opens (``s3://``, ``gs://``...; fetched to the worker's temporary
directory first).

Command line: ``friction-node-fleet replay 'bags/**/*.mcap' --scheduler ADDR``
(or ``python -m friction_node.fleet``).
"""

from __future__ import annotations

import argparse
import contextlib
import glob as _glob
import math
import os
import shutil
import sys
import tempfile
import time
from typing import Any, Dict, Iterable, List, Mapping, Optional, Sequence, Tuple, Union

import friction_node as _fn

__all__ = ["replay", "fit", "expand", "FleetReplay", "FleetFit", "main"]

#: Seconds to wait for a scheduler before giving up.
CONNECT_TIMEOUT_S = 5.0


def _is_url(s: str) -> bool:
    return "://" in s and not s.startswith(("file://", "local://"))


def _plain(s: str) -> str:
    """A ``file://`` or ``local://`` URL as a plain path."""
    for prefix in ("file://", "local://"):
        if s.startswith(prefix) and "::" not in s:
            return s[len(prefix):]
    return s


def expand(bags: Union[str, os.PathLike, Iterable[Union[str, os.PathLike]]]) -> List[str]:
    """Bags as a list: a path, a glob (``**`` recurses), a URL or URL glob
    (fsspec), or a list of those. A pattern that matches nothing is an
    error; an explicit path that does not exist is kept (its row will carry
    the error)."""
    if isinstance(bags, (str, os.PathLike)):
        bags = [bags]
    out: List[str] = []
    for b in bags:
        b = _plain(os.fspath(b))
        has_glob = any(c in b for c in "*?[")
        if not has_glob:
            out.append(b)
            continue
        if _is_url(b):
            import fsspec

            fs, _, paths = fsspec.get_fs_token_paths(b)
            head, chain = (b.split("::", 1) + [""])[:2]
            proto = head.split("://", 1)[0]
            suffix = f"::{chain}" if chain else ""
            # A rosbag2 directory's split files are one bag: the directory.
            paths = _rosbag2_dirs_for_their_files(paths, lambda p: fs.isfile(p), lambda p: fs.isdir(p))
            hits = sorted(f"{proto}://{p.lstrip('/') if chain else p}{suffix}" for p in paths)
        else:
            hits = _rosbag2_dirs_for_their_files(_glob.glob(b, recursive=True), os.path.isfile, os.path.isdir)
        if not hits:
            raise FileNotFoundError(f"no bags match {b!r}")
        out.extend(hits)
    # Each bag once, in order.
    seen = set()
    return [b for b in out if not (b in seen or seen.add(b))]


def _rosbag2_dirs_for_their_files(hits: Iterable[str], isfile, isdir) -> List[str]:
    """Glob hits with every file of a rosbag2 directory (a directory holding
    ``metadata.yaml``: the node's split recordings, rosbag2's own bags)
    replaced by the directory itself, once: a rosbag2 directory is one bag.
    A hit that is such a directory stays one bag too. Sorted."""
    out = set()
    for h in hits:
        h = h.rstrip("/")
        parent = h.rsplit("/", 1)[0] if "/" in h else "."
        if isfile(h) and isfile(f"{parent}/metadata.yaml"):
            out.add(parent)
        elif isfile(h) or (isdir(h) and isfile(f"{h}/metadata.yaml")):
            out.add(h)
    return sorted(out)


def _output_names(bags: Sequence[str]) -> List[str]:
    """A distinct file stem per bag (its name; its index when names repeat)."""
    stems = []
    for b in bags:
        base = os.path.basename(b.split("::", 1)[0].rstrip("/")) or "bag"
        stem = base.rsplit(".", 1)[0] if "." in base else base
        stems.append(stem)
    counts: Dict[str, int] = {}
    for s in stems:
        counts[s] = counts.get(s, 0) + 1
    return [s if counts[s] == 1 else f"{s}-{k:05d}" for k, s in enumerate(stems)]


@contextlib.contextmanager
def _local(bag: str):
    """A local path for ``bag`` (a URL is fetched to a temporary directory)."""
    if not _is_url(bag):
        yield bag
        return
    import fsspec

    tmp = tempfile.mkdtemp(prefix="friction-node-bag-")
    try:
        fs, _, (path,) = fsspec.get_fs_token_paths(bag)
        target = os.path.join(tmp, os.path.basename(path.rstrip("/")) or "bag")
        fs.get(path, target, recursive=fs.isdir(path))
        yield target
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _deliver(local_file: str, target: str) -> None:
    """Copy a finished local file to an fsspec URL (the object appears whole
    when the upload closes)."""
    import fsspec

    with open(local_file, "rb") as src, fsspec.open(target, "wb") as dst:
        shutil.copyfileobj(src, dst, 1 << 20)


def _replay_one(bag: str, stem: str, options: Mapping[str, Any], out_dir: Optional[str], out_format: str):
    """One task: replay one bag; never raises (the row carries the error)."""
    started = time.perf_counter()
    row: Dict[str, Any] = {"bag": bag, "ok": False, "error": None}
    cycles = None
    try:
        with _local(bag) as path:
            out = None
            remote_out = None
            tmpdir = None
            if out_dir is not None:
                name = f"{stem}.{out_format}"
                if _is_url(out_dir):
                    tmpdir = tempfile.mkdtemp(prefix="friction-node-out-")
                    out = os.path.join(tmpdir, name)
                    remote_out = out_dir.rstrip("/") + "/" + name
                else:
                    out = os.path.join(out_dir, name)
            try:
                r = _fn.replay(path, out=out, **options)
                if remote_out is not None:
                    _deliver(out, remote_out)
                    out = remote_out
            finally:
                if tmpdir is not None:
                    shutil.rmtree(tmpdir, ignore_errors=True)
        s = r.summary
        f = r.estimates["friction_n"].to_numpy()
        row.update(
            ok=True,
            steps=s["steps"],
            span_s=s["span_s"],
            wall_s=s["wall_s"],
            model_wall_s=s["model_wall_s"],
            real_time_factor=s["span_s"] / s["wall_s"] if s["wall_s"] > 0 else math.nan,
            commands_rejected=s["commands_rejected"],
            outside_share=max((x for x in s["outside_share"].values() if x == x), default=math.nan),
            outside_by_joint=", ".join(f"{k} {v:.3f}" for k, v in s["outside_share"].items()),
            identical=s["identical"],
            input=s["input"],
            cycles=len(r.cycles),
            friction_mean_abs_n=float(abs(f).mean()) if len(f) else math.nan,
            friction_max_abs_n=float(abs(f).max()) if len(f) else math.nan,
            mean_friction_loop_area_n_m_s=float(r.cycles["friction_loop_area_n_m_s"].mean())
            if len(r.cycles)
            else math.nan,
            out=out,
        )
        cycles = r.cycles.assign(bag=bag)
    except Exception as e:  # noqa: BLE001 - a bag's failure is its row's content
        row["error"] = f"{type(e).__name__}: {e}"
    row["task_s"] = time.perf_counter() - started
    return row, cycles


#: Columns of FleetReplay.bags, in order.
BAG_COLUMNS = [
    "bag", "ok", "error", "steps", "span_s", "wall_s", "model_wall_s", "real_time_factor",
    "commands_rejected", "outside_share", "outside_by_joint", "identical", "input", "cycles",
    "friction_mean_abs_n",
    "friction_max_abs_n", "mean_friction_loop_area_n_m_s", "out", "task_s",
]
#: Columns of FleetReplay.cycles, in order.
CYCLE_COLUMNS = ["bag"] + _fn.LOOP_METRIC_COLUMNS.split(",")


def _bag_frame(result):
    import pandas as pd

    row = result[0]
    return pd.DataFrame([{k: row.get(k) for k in BAG_COLUMNS}], columns=BAG_COLUMNS)


def _cycle_frame(result):
    import pandas as pd

    cy = result[1]
    if cy is None or not len(cy):
        return pd.DataFrame({k: pd.Series(dtype="object" if k == "bag" else "float64") for k in CYCLE_COLUMNS})
    return cy[CYCLE_COLUMNS]


class FleetReplay:
    """``bags``: one row per bag (``ok``, ``error``, steps, span, rates, the
    determinism verdict, summary metrics, ``out``); ``cycles``: one row per
    cycle of every bag (the loop metrics, with the ``bag`` column); ``wall_s``
    and ``workers``: the run's wall time and the cluster's worker count."""

    def __init__(self, bags, cycles, wall_s: float, workers: int):
        self.bags = bags
        self.cycles = cycles
        self.wall_s = wall_s
        self.workers = workers

    @property
    def failed(self):
        """The rows of the bags that failed."""
        return self.bags[~self.bags["ok"]]

    def __repr__(self) -> str:
        n = len(self.bags)
        bad = int((~self.bags["ok"]).sum()) if n else 0
        return f"FleetReplay({n} bags, {bad} failed, {self.wall_s:.1f} s on {self.workers} workers)"


@contextlib.contextmanager
def _client(client: Any, workers: Optional[int]):
    """The client to use: the given one, a scheduler address, or a local
    cluster on loopback (closed afterwards)."""
    import distributed

    if isinstance(client, distributed.Client):
        yield client
        return
    if isinstance(client, str):
        try:
            c = distributed.Client(client, timeout=CONNECT_TIMEOUT_S)
        except (OSError, TimeoutError) as e:
            raise ConnectionError(
                f"cannot reach the Dask scheduler at {client!r} within {CONNECT_TIMEOUT_S:g} s: {e}"
            ) from None
        try:
            yield c
        finally:
            c.close()
        return
    if client is not None:
        raise TypeError(f"client: expected a distributed.Client, a scheduler address or None, got {client!r}")
    n = workers or os.cpu_count() or 1
    try:
        cluster = distributed.LocalCluster(
            n_workers=n,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            silence_logs=40,
        )
    except RuntimeError as e:
        main = sys.modules.get("__main__")
        if getattr(main, "__file__", None):
            raise RuntimeError(
                f"the local Dask cluster could not start its workers ({e}). Dask starts each worker "
                "as a new Python process that imports your script again: call fleet functions in a "
                "script under `if __name__ == \"__main__\":` (see the README's fleet example), or "
                "pass client= an existing distributed.Client"
            ) from e
        raise
    c = distributed.Client(cluster)
    try:
        yield c
    finally:
        c.close()
        cluster.close()


def _show_progress(futures, progress: Optional[bool]) -> None:
    """Dask's own progress bar (terminal or notebook) when wanted."""
    if progress is None:
        progress = sys.stderr.isatty() or "ipykernel" in sys.modules
    if progress:
        import distributed

        distributed.progress(futures)


def _workers(c) -> int:
    try:
        return len(c.scheduler_info()["workers"])
    except Exception:  # noqa: BLE001
        return 0


def replay(
    bags: Union[str, Iterable[str]],
    client: Any = None,
    out_dir: Optional[str] = None,
    out_format: str = "csv",
    as_dask: bool = False,
    progress: Optional[bool] = None,
    workers: Optional[int] = None,
    **replay_options: Any,
) -> FleetReplay:
    """Replay every bag as one Dask task (see ``friction_node.replay`` for
    ``replay_options``: config, overrides, topic, joint, load_topic, ...).

    ``out_dir`` (a directory or an fsspec URL) receives ``STEM.csv`` (or
    ``.mcap``) per bag; ``as_dask=True`` returns Dask DataFrames that stay on
    the cluster instead of pandas ones; ``workers`` sizes the local cluster
    (default: one per core); ``progress`` shows Dask's progress bar (default:
    on a terminal or in a notebook)."""
    import pandas as pd

    if out_format not in ("csv", "mcap"):
        raise ValueError(f"out_format = {out_format!r}: csv or mcap")
    unknown = set(replay_options) - {
        "config", "overrides", "topic", "joint", "load_topic", "temperature_topic",
        "velocity_map", "load_map",
    }
    if unknown:
        raise TypeError(f"unknown replay option(s): {', '.join(sorted(unknown))}")
    paths = expand(bags)
    if out_dir is not None:
        out_dir = _plain(os.fspath(out_dir))
    if out_dir is not None and not _is_url(out_dir):
        os.makedirs(out_dir, exist_ok=True)
    stems = _output_names(paths)
    started = time.perf_counter()
    with _client(client, workers) as c:
        futures = [
            c.submit(_replay_one, b, s, dict(replay_options), out_dir, out_format, key=f"replay-{k}-{s}", pure=False)
            for k, (b, s) in enumerate(zip(paths, stems))
        ]
        _show_progress(futures, progress)
        n_workers = _workers(c)
        if as_dask:
            import dask.dataframe as dd

            import distributed

            bag_parts = [c.submit(_bag_frame, f, pure=False) for f in futures]
            cyc_parts = [c.submit(_cycle_frame, f, pure=False) for f in futures]
            distributed.wait(bag_parts + cyc_parts)
            return FleetReplay(
                dd.from_delayed(bag_parts, meta=_bag_frame(({}, None)).iloc[:0], verify_meta=False),
                dd.from_delayed(cyc_parts, meta=_cycle_frame(({}, None)), verify_meta=False),
                time.perf_counter() - started,
                n_workers,
            )
        results = c.gather(futures)
    wall = time.perf_counter() - started
    bags_df = pd.concat([_bag_frame(r) for r in results], ignore_index=True)
    cycles = [cy for _, cy in results if cy is not None and len(cy)]
    cycles_df = pd.concat([cy[CYCLE_COLUMNS] for cy in cycles], ignore_index=True) if cycles else _cycle_frame(({}, None))
    return FleetReplay(bags_df, cycles_df, wall, n_workers)


# ----------------------------------------------------------------- calibration


def _fit_one(bag: str, keys: Sequence[str], fixed: Mapping[str, float], options: Mapping[str, Any]):
    """One task: fit ``keys`` on one bag with ``fixed`` keys set; never raises."""
    row: Dict[str, Any] = {"bag": bag, "ok": False, "error": None}
    try:
        opts = dict(options)
        overrides = dict(opts.pop("overrides", None) or {})
        overrides.update(fixed)
        # Bounds and starts of the parameters this wave does not fit stay out.
        for k in ("bounds", "start"):
            if opts.get(k):
                opts[k] = {n: v for n, v in opts[k].items() if n in keys}
        with _local(bag) as path:
            r = _fn.fit(path, list(keys), overrides=overrides, **opts)
        row.update(ok=True, converged=r.converged, train_rms_n=r.train_rms_n, held_out_rms_n=r.held_out_rms_n)
        for p in r.raw["parameters"]:
            row[p["name"]] = p["value"]
            row[p["name"] + ":std_error"] = p["std_error"]
    except Exception as e:  # noqa: BLE001
        row["error"] = f"{type(e).__name__}: {e}"
    return row


def _raise_if_every_bag_failed(rows: Sequence[Mapping[str, Any]]) -> None:
    """A fleet fit in which no bag could be fitted has no result: raise,
    naming each bag's error (at most five)."""
    if rows and not any(r.get("ok") for r in rows):
        errors = "; ".join(f"{r['bag']}: {r.get('error')}" for r in rows[:5])
        more = f" (and {len(rows) - 5} more)" if len(rows) > 5 else ""
        raise RuntimeError(f"every bag failed to fit ({len(rows)} bags): {errors}{more}")


def _consensus(rows: Sequence[Mapping[str, Any]], key: str) -> Tuple[float, float, int]:
    """The precision-weighted mean of the bags' estimates of a shared
    parameter, its standard error and the number of bags used."""
    vals, ses = [], []
    for r in rows:
        if r.get("ok") and key in r and math.isfinite(r[key]):
            vals.append(r[key])
            ses.append(r.get(key + ":std_error", math.nan))
    if not vals:
        return math.nan, math.nan, 0
    if all(math.isfinite(s) and s > 0 for s in ses):
        w = [1.0 / (s * s) for s in ses]
        mean = sum(wi * v for wi, v in zip(w, vals)) / sum(w)
        return mean, 1.0 / math.sqrt(sum(w)), len(vals)
    mean = sum(vals) / len(vals)
    return mean, math.nan, len(vals)


class FleetFit:
    """``shared``: the fleet's shared parameters (value, std_error, bags
    used); ``bags``: one row per bag (its own parameters with standard
    errors, train and held-out RMS, converged, error); ``history``: the
    shared values after each round; ``wall_s``, ``workers``."""

    def __init__(self, shared, bags, history, wall_s: float, workers: int):
        self.shared = shared
        self.bags = bags
        self.history = history
        self.wall_s = wall_s
        self.workers = workers

    def __repr__(self) -> str:
        vals = ", ".join(f"{r.name}={r.value:.4g}" for r in self.shared.itertuples())
        return f"FleetFit({vals}; {len(self.bags)} bags, {self.wall_s:.1f} s)"


def fit(
    bags: Union[str, Iterable[str]],
    shared: Sequence[str],
    per_bag: Sequence[str] = (),
    client: Any = None,
    rounds: int = 1,
    start: Optional[Mapping[str, float]] = None,
    progress: Optional[bool] = None,
    workers: Optional[int] = None,
    **fit_options: Any,
) -> FleetFit:
    """Fit parameters shared by the whole fleet (e.g. roughness, boundary
    friction) and per bag (e.g. viscosity, drivetrain terms), every per-bag
    fit a Dask task. ``fit_options`` are ``friction_node.fit``'s (bounds,
    overrides, velocity_topic, friction_topic, ...).

    Method (two waves of tasks): (1) each bag fits the shared and its own
    parameters together; the fleet's value of a shared parameter is the
    precision-weighted mean of the bags' estimates, weighted by 1/SE^2 with
    the *marginal* standard errors of those joint fits. When each bag's
    cost is quadratic near its optimum this is exactly the joint
    least-squares optimum of the whole fleet (profiling out a bag's own
    parameters leaves a quadratic in the shared ones whose curvature is the
    inverse marginal variance); correlations between several shared
    parameters are not used (diagonal weights). (2) Each bag refits its own
    parameters with the shared ones fixed at the fleet's values: the
    report. ``rounds`` > 1 repeats (1) started at the fleet's values (for
    strongly nonlinear cases). With no ``per_bag`` parameters, (1) is the
    whole fit."""
    import pandas as pd

    shared, per_bag = list(shared), list(per_bag)
    if not shared:
        raise ValueError("shared: name at least one parameter shared by the fleet")
    both = set(shared) & set(per_bag)
    if both:
        raise ValueError(f"{', '.join(sorted(both))}: both shared and per bag")
    if rounds < 1:
        raise ValueError(f"rounds = {rounds}: at least 1")
    paths = expand(bags)
    if "data" in fit_options or "fit" in fit_options:
        raise TypeError("data and fit are given by bags, shared and per_bag")
    # The shared values start at `start` (else the configured values).
    current: Dict[str, float] = {k: float(v) for k, v in (start or {}).items() if k in shared}
    own_start = {k: float(v) for k, v in (start or {}).items() if k in per_bag}
    history = []
    started = time.perf_counter()

    def wave(c, keys, fixed_of) -> List[Dict[str, Any]]:
        opts = dict(fit_options)
        futures = []
        for k, b in enumerate(paths):
            fixed, st = fixed_of(k)
            o = dict(opts)
            if st:
                o["start"] = {**(o.get("start") or {}), **st}
            futures.append(c.submit(_fit_one, b, list(keys), fixed, o, pure=False))
        _show_progress(futures, progress)
        return c.gather(futures)

    with _client(client, workers) as c:
        for _ in range(rounds):
            # (1) Each bag alone, shared and own parameters together: its
            # estimate of the shared ones with their marginal standard errors
            # (the correlation with its own parameters accounted for).
            rows = wave(c, shared + per_bag, lambda k: ({}, {**own_start, **current}))
            _raise_if_every_bag_failed(rows)
            combined = {key: _consensus(rows, key) for key in shared}
            current = {key: v for key, (v, _, n) in combined.items() if n > 0}
            history.append(dict(current))
        # (2) Each bag's own parameters at the fleet's shared values.
        final = wave(c, per_bag, lambda k: (dict(current), own_start)) if per_bag else rows
        _raise_if_every_bag_failed(final)
        n_workers = _workers(c)
    shared_rows = [
        {"name": key, "value": v, "std_error": se, "bags_used": n} for key, (v, se, n) in combined.items()
    ]
    bag_rows = []
    for r, joint in zip(final, rows):
        row = {k: v for k, v in r.items() if k.split(":")[0] not in shared}
        # Each bag's own estimate of the shared parameters (from its joint
        # fit): the machine-to-machine scatter around the fleet's value.
        row.update({f"{k}:bag_estimate": joint.get(k, math.nan) for k in shared})
        bag_rows.append(row)
    return FleetFit(
        pd.DataFrame(shared_rows),
        pd.DataFrame(bag_rows),
        pd.DataFrame(history),
        time.perf_counter() - started,
        n_workers,
    )


# ---------------------------------------------------------------- command line


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``friction-node-fleet replay|fit BAGS... [--scheduler ADDR]``."""
    ap = argparse.ArgumentParser(
        prog="friction-node-fleet",
        description="Replay or calibrate a fleet of bags on Dask (a local cluster, or --scheduler).",
    )
    sub = ap.add_subparsers(dest="command", required=True)
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("bags", nargs="+", help="bags: paths, globs ('bags/**/*.mcap'), fsspec URLs")
    common.add_argument("--scheduler", metavar="ADDR", help="a Dask scheduler (tcp://host:8786); default: a local cluster")
    common.add_argument("--workers", type=int, help="local cluster workers (default: one per core)")
    common.add_argument("--config", help="a parameter file (default: the one recorded in each bag)")
    common.add_argument("--set", action="append", default=[], metavar="KEY=VALUE", help="configuration override (repeatable)")
    common.add_argument("--table", metavar="FILE.csv", help="write the per-bag table here")
    common.add_argument("--no-progress", action="store_true")
    r = sub.add_parser("replay", parents=[common], help="replay every bag")
    r.add_argument("--topic")
    r.add_argument("--joint")
    r.add_argument("--load-topic")
    r.add_argument("--temperature-topic")
    r.add_argument("--out-dir", help="per-bag outputs (directory or fsspec URL)")
    r.add_argument("--format", choices=["csv", "mcap"], default="csv")
    r.add_argument("--cycles", metavar="FILE.csv", help="write the per-cycle table here")
    f = sub.add_parser("fit", parents=[common], help="fit shared and per-bag parameters")
    f.add_argument("--shared", required=True, help="comma-separated keys shared by the fleet")
    f.add_argument("--per-bag", default="", help="comma-separated keys fitted per bag")
    f.add_argument("--velocity-topic")
    f.add_argument("--friction-topic")
    f.add_argument("--joint")
    f.add_argument("--rounds", type=int, default=1)
    a = ap.parse_args(argv)
    overrides = {}
    for kv in a.set:
        if "=" not in kv:
            ap.error(f"--set {kv}: expected KEY=VALUE")
        k, v = kv.split("=", 1)
        overrides[k.strip()] = v.strip()
    client = a.scheduler
    progress = False if a.no_progress else None
    try:
        if a.command == "replay":
            res = replay(
                a.bags, client=client, out_dir=a.out_dir, out_format=a.format, progress=progress,
                workers=a.workers, config=a.config, overrides=overrides, topic=a.topic, joint=a.joint,
                load_topic=a.load_topic, temperature_topic=a.temperature_topic,
            )
            table = res.bags
            if a.cycles:
                res.cycles.to_csv(a.cycles, index=False)
            cols = [c for c in ("bag", "ok", "steps", "span_s", "real_time_factor", "identical", "cycles", "error") if c in table]
        else:
            opts = {k: v for k, v in dict(velocity_topic=a.velocity_topic, friction_topic=a.friction_topic, joint=a.joint).items() if v}
            res = fit(
                a.bags, [k for k in a.shared.split(",") if k], [k for k in a.per_bag.split(",") if k],
                client=client, rounds=a.rounds, progress=progress, workers=a.workers,
                config=a.config, overrides=overrides, **opts,
            )
            print(res.shared.to_string(index=False))
            table = res.bags
            cols = list(table.columns)
    except (OSError, ValueError, TypeError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if a.table:
        table.to_csv(a.table, index=False)
    import pandas as pd

    with pd.option_context("display.max_colwidth", 60, "display.width", 200):
        print(table[cols].to_string(index=False))
    print(f"{len(table)} bags, {int((~table['ok']).sum())} failed, {res.wall_s:.1f} s on {res.workers} workers")
    return 0 if table["ok"].all() else 1


if __name__ == "__main__":
    sys.exit(main())
