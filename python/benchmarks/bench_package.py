"""Benchmarks of the Python package (issue 17's targets), side by side in
one run on this machine:

1. ``Model.run`` over 60 s at 1 kHz (the shipped default: N = 64, muscl_van_leer; N = 256 upwind before 2026-11-26) against
   the same run through the Rust API (``examples/bench_run.rs``), medians of
   alternating repetitions;
2. 64 bags of 60 s replayed by ``fleet.replay`` on a local cluster of one
   and of two workers, every result checked byte-identical to a
   one-by-one ``friction-node replay`` of the same bag;
3. the per-bag cost, for the on-paper fleet estimate.

Run from the repository root, with the package installed
(``pip install ".[fleet]" mcap-ros2-support``) and ``cargo build --release
--bin friction-node --example bench_run`` done:

    python python/benchmarks/bench_package.py [--bags 64] [--seconds 60] [--repeats 7]
"""

import argparse
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import friction_node as fn
from friction_node import fleet

REPO = Path(__file__).resolve().parents[2]
BIN = REPO / "target/release/friction-node"
RUST_RUN = REPO / "target/release/examples/bench_run"


def model_run(seconds: float, repeats: int) -> None:
    py_s, rust_s = [], []
    for _ in range(repeats):
        out = subprocess.run([str(RUST_RUN), str(seconds), "1"], check=True, capture_output=True, text=True)
        rust_s.append(float(out.stdout.split()[1]))
        started = time.perf_counter()
        m = fn.Model()
        t = np.arange(int(round(seconds / m.dt)) + 1) * m.dt
        m.run(t, np.sin(2 * np.pi * t))
        py_s.append(time.perf_counter() - started)
    p, r = statistics.median(py_s), statistics.median(rust_s)
    print(f"Model.run, {seconds:g} s at 1 kHz, the default grid and flux, {repeats} alternating repetitions:")
    print(f"  Python Model.run median {p:.3f} s (min {min(py_s):.3f}), Rust API median {r:.3f} s (min {min(rust_s):.3f})")
    print(f"  ratio Python/Rust: median {p / r:.3f}, best-of {min(py_s) / min(rust_s):.3f} (target <= 1.10)")


def fleet_replay(n_bags: int, seconds: float) -> None:
    work = Path(tempfile.mkdtemp(prefix="fn-fleet-bench-"))
    try:
        one = work / "src.mcap"
        subprocess.run([sys.executable, str(REPO / "bags/make_foreign_bag.py"), str(one), "--seconds", str(seconds)],
                       check=True)
        bags = []
        for k in range(n_bags):
            b = work / "bags" / f"machine{k:03d}.mcap"
            b.parent.mkdir(exist_ok=True)
            shutil.copy(one, b)
            bags.append(str(b))
        size = one.stat().st_size
        opts = dict(topic="/joint_states", joint="slider")
        # Tables only (what a fleet analysis needs), then also writing every
        # bag's CSV (replay's writer thread then competes for the cores).
        tables = {}
        for writing in (False, True):
            results = {}
            for workers in (1, 2):
                out = str(work / f"out{workers}") if writing else None
                r = fleet.replay(bags, workers=workers, out_dir=out, progress=False, **opts)
                assert r.bags["ok"].all(), r.bags["error"].tolist()
                results[workers] = r
                print(f"fleet.replay{' writing CSVs' if writing else ''}: {n_bags} bags of {seconds:g} s on "
                      f"{workers} worker(s): {r.wall_s:.2f} s wall (median task {r.bags['task_s'].median():.3f} s, "
                      f"replay {r.bags['real_time_factor'].median():.0f}x real time)")
            speedup = results[1].wall_s / results[2].wall_s
            print(f"  speed-up 2 workers / 1 worker: {speedup:.2f}x (target >= 1.7)")
            tables[writing] = results
        # The tables do not depend on the worker count or on writing.
        cols = ["bag", "steps", "span_s", "commands_rejected", "cycles", "friction_mean_abs_n",
                "friction_max_abs_n", "mean_friction_loop_area_n_m_s"]
        ref_bags, ref_cycles = tables[False][1].bags[cols], tables[False][1].cycles
        for w in (False, True):
            for n in (1, 2):
                assert tables[w][n].bags[cols].equals(ref_bags)
                assert tables[w][n].cycles.equals(ref_cycles)
        print("  per-bag and per-cycle tables identical across 1/2 workers, with and without writing")
        # Identical to one-by-one CLI replays, for every bag and both runs.
        started = time.perf_counter()
        for b in bags:
            ref = work / "cli.csv"
            subprocess.run([str(BIN), "replay", b, "--topic", "/joint_states", "--joint", "slider", "--out", str(ref)],
                           check=True, capture_output=True)
            stem = Path(b).stem
            for workers in (1, 2):
                got = (work / f"out{workers}" / f"{stem}.csv").read_bytes()
                assert got == ref.read_bytes(), f"{stem}: fleet output differs from the CLI's"
        cli_s = time.perf_counter() - started
        print(f"  all {n_bags} outputs byte-identical to one-by-one CLI replays (those took {cli_s:.1f} s in a row)")
        task = results[1].bags["task_s"].median()
        rt = seconds / task
        print(f"Per-bag cost: {task:.3f} s of one worker per {seconds:g} s bag ({rt:.0f}x real time), "
              f"bag {size / 1e6:.2f} MB ({size / seconds / 1e3:.1f} kB per recorded second); "
              f"result row + {len(results[1].cycles) // n_bags} cycle rows per bag")
        core_s = 800 * 3600 / rt
        for w in (10, 100, 1000):
            print(f"  800 h of bags a day on {w:4d} workers: {core_s / w / 3600:.2f} h "
                  f"({core_s / w:.0f} s) of replay, {800 * 3600 / seconds:.0f} tasks")
    finally:
        shutil.rmtree(work, ignore_errors=True)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--bags", type=int, default=64)
    ap.add_argument("--seconds", type=float, default=60.0)
    ap.add_argument("--repeats", type=int, default=7)
    a = ap.parse_args()
    for p in (BIN, RUST_RUN):
        if not p.exists():
            sys.exit(f"{p} is missing: cargo build --release --bin friction-node --example bench_run")
    model_run(a.seconds, a.repeats)
    fleet_replay(a.bags, a.seconds)


if __name__ == "__main__":
    main()
