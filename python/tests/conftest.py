"""Shared fixtures: the friction-node binary (for same-input comparisons),
the repository, a two-worker local Dask cluster, and bags."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def cli():
    """Run the friction-node command (FRICTION_NODE_BIN, set by
    tests/python_package.rs; else target/release or target/debug)."""
    exe = os.environ.get("FRICTION_NODE_BIN")
    if not exe:
        for p in (REPO / "target/release/friction-node", REPO / "target/debug/friction-node"):
            if p.exists():
                exe = str(p)
                break
    assert exe and Path(exe).exists(), "the friction-node binary: set FRICTION_NODE_BIN or run cargo build"

    def run(*args, check=True):
        r = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
        if check:
            assert r.returncode == 0, f"friction-node {' '.join(map(str, args))}: {r.stderr}"
        return r

    return run


@pytest.fixture(scope="session")
def repo():
    return REPO


@pytest.fixture(scope="session")
def cluster_client():
    """A two-worker local cluster on loopback (one thread per worker)."""
    distributed = pytest.importorskip("distributed", reason="pip install '.[fleet]'")
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1",
        dashboard_address=None, silence_logs=40,
    )
    client = distributed.Client(cluster)
    yield client
    client.close()
    cluster.close()


@pytest.fixture(scope="session")
def bag_dir(tmp_path_factory):
    """Bags: two copies of the node's lockstep recording (recorded estimates:
    an exact oracle), a 4 s foreign JointState bag, a truncated bag, and a
    bag without any velocity topic."""
    d = tmp_path_factory.mktemp("bags")
    src = REPO / "bags/node_lockstep.mcap"
    shutil.copy(src, d / "node_a.mcap")
    shutil.copy(src, d / "node_b.mcap")
    (d / "truncated.mcap").write_bytes(src.read_bytes()[:5000])
    subprocess.run(
        [sys.executable, str(REPO / "bags/make_foreign_bag.py"), str(d / "foreign.mcap"), "--seconds", "4"],
        check=True,
    )
    from mcap_ros2.writer import Writer

    with open(d / "no_velocity.mcap", "wb") as f:
        w = Writer(f)
        schema = w.register_msgdef("std_msgs/msg/String", "string data\n")
        for k in range(10):
            w.write_message("/notes", schema, {"data": f"note {k}"}, log_time=k * 10**8, publish_time=k * 10**8)
        w.finish()
    return d
