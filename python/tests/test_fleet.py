"""Fleet replay and calibration on a two-worker local Dask cluster."""

import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

import friction_node as fn

fleet = pytest.importorskip("friction_node.fleet")
pytest.importorskip("distributed", reason="pip install '.[fleet]'")


def test_fleet_replay_equals_one_by_one_cli_replays_and_a_bad_bag_stops_nothing(cli, bag_dir, cluster_client, tmp_path):
    bags = [bag_dir / "node_a.mcap", bag_dir / "truncated.mcap", bag_dir / "no_velocity.mcap",
            bag_dir / "missing.mcap", bag_dir / "node_b.mcap"]
    out = tmp_path / "out"
    r = fleet.replay([str(b) for b in bags], client=cluster_client, out_dir=str(out), progress=False)
    assert r.workers == 2
    rows = r.bags.set_index("bag")
    assert list(rows["ok"]) == [True, False, False, False, True]
    assert "truncated.mcap" in rows.loc[str(bag_dir / "truncated.mcap"), "error"]
    assert "no usable velocity topic" in rows.loc[str(bag_dir / "no_velocity.mcap"), "error"]
    assert "FileNotFoundError" in rows.loc[str(bag_dir / "missing.mcap"), "error"]
    for name in ("node_a", "node_b"):
        assert rows.loc[str(bag_dir / f"{name}.mcap"), "identical"] is True
        ref = tmp_path / f"{name}-cli.csv"
        cli("replay", bag_dir / f"{name}.mcap", "--out", ref)
        assert (out / f"{name}.csv").read_bytes() == ref.read_bytes()
    # Nothing written for the failed bags, no temporary leftovers.
    assert sorted(os.listdir(out)) == ["node_a.csv", "node_b.csv"]


def test_fleet_replay_of_a_glob_with_options_gives_per_cycle_metrics(bag_dir, cluster_client):
    r = fleet.replay(str(bag_dir / "fore*.mcap"), client=cluster_client, topic="/joint_states",
                     joint="slider", progress=False)
    assert r.bags["ok"].all(), r.bags["error"].tolist()
    assert len(r.cycles) >= 2
    single = fn.replay(bag_dir / "foreign.mcap", topic="/joint_states", joint="slider")
    np.testing.assert_array_equal(
        r.cycles["friction_loop_area_n_m_s"].to_numpy(), single.cycles["friction_loop_area_n_m_s"].to_numpy()
    )


def test_fleet_replay_lists_each_joints_share_of_time_outside_its_calibrated_range(bag_dir, cluster_client):
    rng = {"calibrated_range.speed_forward_min_m_s": 0.0, "calibrated_range.speed_forward_max_m_s": 0.5,
           "calibrated_range.speed_backward_min_m_s": 0.0, "calibrated_range.speed_backward_max_m_s": 0.5,
           "calibrated_range.training_rms_n": 1.0, "calibrated_range.training_samples": 10}
    r = fleet.replay([str(bag_dir / "node_a.mcap")], client=cluster_client, overrides=rng, progress=False)
    one = fn.replay(bag_dir / "node_a.mcap", overrides=rng)
    outside = one.summary["steps_outside_calibrated_range"]
    assert outside == (one.estimates["calibrated_range"] == "outside").sum() > 0
    share = outside / one.summary["steps"]
    # The 1 m/s sine spends 2/3 of its time above 0.5 m/s.
    assert abs(share - 2 / 3) < 0.01
    row = r.bags.iloc[0]
    assert row["outside_share"] == share
    assert row["outside_by_joint"] == f"contact {share:.3f}"
    # Without a range: nothing is watched.
    plain = fleet.replay([str(bag_dir / "node_a.mcap")], client=cluster_client, progress=False)
    assert np.isnan(plain.bags.iloc[0]["outside_share"])


def test_fleet_replay_as_a_dask_dataframe_computes_to_the_same_table(bag_dir, cluster_client):
    pytest.importorskip("dask.dataframe")
    bags = [str(bag_dir / "node_a.mcap"), str(bag_dir / "truncated.mcap")]
    lazy = fleet.replay(bags, client=cluster_client, as_dask=True, progress=False)
    eager = fleet.replay(bags, client=cluster_client, progress=False)
    got = lazy.bags.compute().reset_index(drop=True)
    assert list(got["bag"]) == list(eager.bags["bag"])
    assert list(got["ok"]) == [True, False]
    assert list(got["steps"].fillna(-1)) == list(eager.bags["steps"].fillna(-1))


def test_a_glob_that_matches_nothing_is_an_error_naming_it(tmp_path):
    with pytest.raises(FileNotFoundError, match="nothing-here"):
        fleet.replay(str(tmp_path / "nothing-here/*.mcap"), progress=False)


def test_a_glob_keeps_rosbag2_directories_as_one_bag_each(repo, tmp_path):
    # The shipped fixture bags, copied by name (whatever else lies in bags/,
    # a demo recording say, is not the test's): two MCAP files, a rosbag2
    # directory of MCAP files and one of SQLite files.
    shipped = tmp_path / "shipped"
    shipped.mkdir()
    for name in ("foreign_joint_states.mcap", "node_lockstep.mcap"):
        shutil.copy(repo / "bags" / name, shipped / name)
    for name in ("rosbags_mcap", "rosbags_sqlite3"):
        shutil.copytree(repo / "bags" / name, shipped / name)
    got = fleet.expand(str(shipped / "**" / "*.mcap"))
    assert got == sorted(
        [str(shipped / "foreign_joint_states.mcap"), str(shipped / "node_lockstep.mcap"),
         str(shipped / "rosbags_mcap")]
    )
    # A tree holding only split recordings: each directory once, however
    # many files it holds; a directory without metadata.yaml is no bag.
    for d, files in (("day1", 3), ("day2", 2)):
        (tmp_path / "fleet" / d).mkdir(parents=True)
        (tmp_path / "fleet" / d / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
        for k in range(files):
            (tmp_path / "fleet" / d / f"{d}_{k}.mcap").write_bytes(b"")
    (tmp_path / "fleet" / "notes").mkdir()
    want = [str(tmp_path / "fleet" / "day1"), str(tmp_path / "fleet" / "day2")]
    assert fleet.expand(str(tmp_path / "fleet" / "**" / "*.mcap")) == want
    assert fleet.expand(str(tmp_path / "fleet" / "*")) == want


def test_an_unreachable_scheduler_is_a_clear_error(bag_dir):
    with pytest.raises(ConnectionError, match="tcp://127.0.0.1:9"):
        fleet.replay([str(bag_dir / "node_a.mcap")], client="tcp://127.0.0.1:9", progress=False)


def test_an_unknown_replay_option_is_refused(bag_dir):
    with pytest.raises(TypeError, match="topci"):
        fleet.replay([str(bag_dir / "node_a.mcap")], topci="/x", progress=False)


def synthetic(path, viscosity, boundary, seed):
    m = fn.Model(**{"solver.cells": 32, "lubricant.viscosity_pa_s": viscosity,
                    "contact.boundary_friction": boundary})
    t = np.arange(2001) * m.dt
    v = np.sin(2 * np.pi * t)
    f = m.run(t, v)["friction_n"]
    f = f + np.random.default_rng(seed).normal(0.0, 5.0, f.shape)
    np.savetxt(path, np.column_stack([t, v, f]), delimiter=",", header="t_s,velocity_m_s,friction_n", comments="")


def test_fleet_fit_recovers_the_shared_boundary_friction_and_each_machines_viscosity(tmp_path, cluster_client):
    truth = {"m1": 0.04, "m2": 0.07, "m3": 0.10}
    for k, (name, mu) in enumerate(truth.items()):
        synthetic(tmp_path / f"{name}.csv", mu, 0.22, k)
    r = fleet.fit(
        sorted(str(p) for p in tmp_path.glob("m*.csv")),
        shared=["contact.boundary_friction"],
        per_bag=["lubricant.viscosity_pa_s"],
        client=cluster_client,
        overrides={"solver.cells": 32},
        bounds={"lubricant.viscosity_pa_s": (0.01, 0.3), "contact.boundary_friction": (0.05, 0.6)},
        starts=1,
        global_points=0,
        progress=False,
    )
    shared = r.shared.set_index("name")
    assert shared.loc["contact.boundary_friction", "value"] == pytest.approx(0.22, rel=0.005)
    assert shared.loc["contact.boundary_friction", "bags_used"] == 3
    assert r.bags["ok"].all(), r.bags["error"].tolist()
    got = dict(zip(r.bags["bag"].map(lambda b: os.path.basename(b)[:-4]), r.bags["lubricant.viscosity_pa_s"]))
    for name, mu in truth.items():
        assert got[name] == pytest.approx(mu, rel=0.01), name
    assert len(r.history) == 1
    assert r.bags["contact.boundary_friction:bag_estimate"].between(0.21, 0.23).all()


def test_a_fleet_fit_in_which_every_bag_fails_raises_naming_the_errors(bag_dir, cluster_client):
    with pytest.raises(RuntimeError, match="every bag failed to fit") as e:
        fleet.fit([str(bag_dir / "node_a.mcap")], shared=["contact.boundary_friction"],
                  client=cluster_client, velocity_topic="/nope", friction_topic="/nope", progress=False)
    assert "node_a.mcap" in str(e.value)


def test_a_script_that_starts_a_local_cluster_outside_a_main_guard_is_told_why(tmp_path):
    script = tmp_path / "unguarded.py"
    script.write_text(
        "from friction_node import fleet\n"
        f"fleet.replay({str(tmp_path / 'none.mcap')!r}, workers=1, progress=False)\n"
    )
    r = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, cwd=tmp_path)
    assert r.returncode != 0
    assert "__main__" in r.stderr, r.stderr[-2000:]


def test_the_fleet_command_line_replays_and_exits_1_when_a_bag_failed(bag_dir, tmp_path):
    table = tmp_path / "bags.csv"
    r = subprocess.run(
        [sys.executable, "-m", "friction_node.fleet", "replay", str(bag_dir / "node_a.mcap"),
         str(bag_dir / "truncated.mcap"), "--workers", "2", "--table", str(table), "--no-progress"],
        capture_output=True, text=True,
    )
    assert r.returncode == 1, r.stderr
    assert "2 bags, 1 failed" in r.stdout
    assert table.read_text().count("\n") == 3
    bad = subprocess.run(
        [sys.executable, "-m", "friction_node.fleet", "replay", str(bag_dir / "node_a.mcap"),
         "--scheduler", "tcp://127.0.0.1:9", "--no-progress"],
        capture_output=True, text=True,
    )
    assert bad.returncode == 2
    assert "cannot reach the Dask scheduler at 'tcp://127.0.0.1:9'" in bad.stderr


def test_fsspec_urls_are_fetched_to_the_worker_and_outputs_delivered_whole(bag_dir, cluster_client, tmp_path):
    import zipfile

    import fsspec

    # A zip archive read through fsspec stands for s3:// or gs:// here: the
    # worker fetches each bag, replays it and writes its output.
    archive = tmp_path / "bags.zip"
    with zipfile.ZipFile(archive, "w") as z:
        z.write(bag_dir / "node_a.mcap", "node_a.mcap")
        z.write(bag_dir / "node_b.mcap", "node_b.mcap")
    r = fleet.replay(f"zip://node_*.mcap::{archive}", client=cluster_client,
                     out_dir=f"file://{tmp_path}/out", progress=False)
    assert r.bags["ok"].all(), r.bags["error"].tolist()
    assert r.bags["identical"].tolist() == [True, True]
    assert sorted(os.listdir(tmp_path / "out")) == ["node_a.csv", "node_b.csv"]
    # Delivery to an object store: the file arrives whole, in one piece.
    fleet._deliver(str(tmp_path / "out/node_a.csv"), "memory://fleet/node_a.csv")
    with fsspec.open("memory://fleet/node_a.csv", "rb") as f:
        assert f.read() == (tmp_path / "out/node_a.csv").read_bytes()
