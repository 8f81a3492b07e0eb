"""The package from Python: numpy in and out, the same numbers as the
command line for the same inputs, Python exceptions for bad input."""

import csv
import inspect
import math
import re
from pathlib import Path

import numpy as np
import pytest

import friction_node as fn


def read_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {k: [r[k] for r in rows] for k in rows[0]}


def floats(col):
    return np.array([float(x) for x in col])


REAL_DRIVE_TERMS = {
    "contact.presliding_stiffness_n_m": 1e8,
    "contact.presliding_damping_n_s_m": 50.0,
    "contact.width_load_exponent": 0.5,
    "drivetrain.quadratic_n_s2_m2": 300.0,
    "drivetrain.coulomb_asymmetry_n": 40.0,
    "contact.boundary_friction_rate": 0.01,
    "contact.boundary_activation_speed_m_s": 1e-3,
}


@pytest.mark.parametrize("terms", [{}, REAL_DRIVE_TERMS], ids=["default", "pre-sliding, soft width, boundary rate, losses"])
def test_run_is_bit_identical_to_the_cli_simulate(cli, tmp_path, terms):
    out = tmp_path / "run.csv"
    sets = [a for k, v in terms.items() for a in ("--set", f"{k}={v}")]
    cli("--set", "solver.cells=64", *sets, "simulate", "--velocity", "sine:0,1,1", "--duration", "2", "--out", out)
    ref = read_csv(out)
    t = np.concatenate([[0.0], floats(ref["t_s"])])
    v = np.concatenate([[0.0], floats(ref["velocity_m_s"])])
    m = fn.Model(**{"solver.cells": 64, **terms})
    got = m.run(t, v)
    assert len(got["friction_n"]) == len(t)
    for col in ("friction_n", "h0_m", "h_min_m", "f_hyd_n", "f_asp_n", "cof", "contact_friction_n"):
        np.testing.assert_array_equal(got[col][1:], floats(ref[col]), err_msg=col)
    assert list(got["status"][1:]) == ref["status"]
    assert list(got["iterations"][1:]) == [int(x) for x in ref["iterations"]]


def test_run_as_a_frame_has_the_simulate_columns():
    m = fn.Model(**{"solver.cells": 32})
    t = np.arange(200) * m.dt
    df = m.run(t, 0.5 * np.sin(2 * np.pi * t), load=np.full(200, 5000.0), as_frame=True)
    assert set(fn.SIMULATE_COLUMNS.split(",")) <= set(df.columns)
    assert len(df) == 200
    assert (df["load_n"] == 5000.0).all()


def test_step_by_step_equals_a_run():
    a, b = fn.Model(**{"solver.cells": 32}), fn.Model(**{"solver.cells": 32})
    t = np.arange(300) * a.dt
    v = np.sin(2 * np.pi * t)
    run = a.run(t, v)
    b.reset(v[0])
    stepped = [b.step(x) for x in v[1:]]
    assert [e.friction_force_n for e in stepped] == list(run["friction_n"][1:])
    assert stepped[-1].status == "converged"


RANGE = {
    "speed_forward_min_m_s": 0.0, "speed_forward_max_m_s": 0.3,
    "speed_backward_min_m_s": 0.0, "speed_backward_max_m_s": 0.3,
    "training_rms_n": 1.0, "training_samples": 10,
}


def test_each_estimate_says_where_its_input_lay_against_the_calibrated_range():
    plain = fn.Model(**{"solver.cells": 32})
    assert plain.step(1.0).calibrated_range == "not_watched"
    warn = fn.Model({"calibrated_range": RANGE}, **{"solver.cells": 32})
    zero = fn.Model({"calibrated_range": RANGE, "node": {"outside_envelope": "zero"}}, **{"solver.cells": 32})
    steps = [(warn.step(v), zero.step(v)) for v in (0.1, 0.2, 1.0, 1.0, 0.2)]
    assert [w.calibrated_range for w, _ in steps] == ["inside", "inside", "outside", "outside", "inside"]
    assert [z.calibrated_range for _, z in steps] == [w.calibrated_range for w, _ in steps]
    # zero: no feed-forward outside, the model's value inside.
    assert [z.friction_force_n == 0.0 for _, z in steps] == [False, False, True, True, False]
    assert steps[0][1].friction_force_n == steps[0][0].friction_force_n


def test_configuration_from_a_dict_dotted_keys_or_overrides_is_the_same(repo):
    by_dict = fn.Model({"contact": {"load_n": 5720.0}})
    by_key = fn.Model(**{"contact.load_n": 5720})
    by_overrides = fn.Model(overrides={"contact.load_n": 5720})
    by_file = fn.Model(repo / "launch-config/default.yaml", **{"contact.load_n": 5720})
    assert by_dict.load_n == by_key.load_n == by_overrides.load_n == by_file.load_n == 5720.0
    assert by_dict.config_yaml() == by_key.config_yaml() == by_file.config_yaml()


def test_stribeck_equals_the_cli(cli, tmp_path):
    out = tmp_path / "s.csv"
    cli("--set", "solver.cells=64", "stribeck", "--v-min", "1e-4", "--v-max", "1", "--points", "9", "--log", "--out", out)
    ref = read_csv(out)
    got = fn.stribeck(floats(ref["velocity_m_s"]), **{"solver.cells": 64})
    for col in ("cof", "h0_m", "friction_n"):
        np.testing.assert_array_equal(got[col], floats(ref[col]), err_msg=col)


def test_replay_of_the_node_bag_is_bit_identical_and_equals_the_cli(cli, repo, tmp_path):
    bag = repo / "bags/node_lockstep.mcap"
    out = tmp_path / "cli.csv"
    cli("replay", bag, "--out", out)
    r = fn.replay(bag, out=tmp_path / "py.csv")
    assert r.identical is True
    assert r.summary["steps"] == len(r.estimates) == 2000
    ref = read_csv(out)
    np.testing.assert_array_equal(r.estimates["friction_n"].to_numpy(), floats(ref["friction_n"]))
    assert (tmp_path / "py.csv").read_bytes() == out.read_bytes()


def test_fit_recovers_boundary_friction_and_equals_the_cli(cli, tmp_path):
    truth = fn.Model(**{"solver.cells": 32, "contact.boundary_friction": 0.22})
    t = np.arange(2001) * truth.dt
    v = np.sin(2 * np.pi * t)
    run = truth.run(t, v)
    data = tmp_path / "data.csv"
    np.savetxt(data, np.column_stack([t, v, run["friction_n"]]), delimiter=",",
               header="t_s,velocity_m_s,friction_n", comments="")
    r = fn.fit(data, ["contact.boundary_friction"], overrides={"solver.cells": 32}, starts=1, global_points=0)
    assert r.converged
    assert r.value("contact.boundary_friction") == pytest.approx(0.22, rel=1e-3)
    assert r.train_rms_n < 1.0
    # Where it was calibrated: the sine's speeds each way, 2001 samples.
    assert r.calibrated_range["speed_forward_max_m_s"] == pytest.approx(1.0, rel=1e-3)
    assert r.calibrated_range["speed_backward_max_m_s"] == pytest.approx(1.0, rel=1e-3)
    assert r.calibrated_range["training_samples"] == 2001
    assert "calibrated_range:" in r.fitted_yaml
    out = tmp_path / "cli.yaml"
    cli("--set", "solver.cells=32", "fit", data, "--fit", "contact.boundary_friction",
        "--starts", "1", "--global-points", "0", "--out", out)
    assert r.fitted_yaml == out.read_text()



def test_fit_takes_tables_in_memory_and_equals_the_fit_of_the_same_csv(tmp_path):
    truth = fn.Model(**{"solver.cells": 32, "contact.boundary_friction": 0.22})
    t = np.arange(2001) * truth.dt
    run = truth.run(t, np.sin(2 * np.pi * t))
    train = {"t_s": t[:1500], "velocity_m_s": run["velocity_m_s"][:1500], "friction_n": run["friction_n"][:1500]}
    held = {k: v for k, v in run.items() if k in ("t_s", "velocity_m_s", "friction_n")}
    data, validate = tmp_path / "train.csv", tmp_path / "validate.csv"
    for path, table in ((data, train), (validate, held)):
        np.savetxt(path, np.column_stack([table["t_s"], table["velocity_m_s"], table["friction_n"]]),
                   delimiter=",", header="t_s,velocity_m_s,friction_n", comments="", fmt="%.17g")
    args = dict(fit=["contact.boundary_friction"], overrides={"solver.cells": 32}, starts=1, global_points=0)
    from_files = fn.fit(data, validate=[validate], **args)
    # A dict of arrays (and Model.run's own dict, its extra columns unread).
    from_tables = fn.fit(train, validate=run, **args)
    assert from_tables.value("contact.boundary_friction") == from_files.value("contact.boundary_friction")
    assert from_tables.train_rms_n == from_files.train_rms_n
    assert from_tables.held_out_rms_n == from_files.held_out_rms_n
    assert from_tables.value("contact.boundary_friction") == pytest.approx(0.22, rel=1e-3)


@pytest.mark.parametrize("table, words", [
    ({"velocity_m_s": [0.1, 0.2], "friction_n": [1.0]}, "'friction_n' has 1 rows"),
    ({"velocity_m_s": np.zeros((2, 2)), "friction_n": [1.0, 2.0]}, "shape (2, 2)"),
    ({"velocity, m/s": [0.1], "friction_n": [1.0]}, "column name 'velocity, m/s'"),
    ({}, "a table without columns"),
    ({"velocity_m_s": [0.1, 0.2, 0.3], "friction_n": [1.0, 2.0, np.nan]}, "'friction_n' is nan at row 2 (counting from 0)"),
])
def test_a_table_in_memory_that_cannot_be_a_csv_is_a_value_error_naming_it(table, words):
    with pytest.raises(ValueError) as e:
        fn.fit(table, ["contact.boundary_friction"])
    assert words in str(e.value) and "data 1" in str(e.value)


def test_the_search_rules_are_the_clis_and_a_bad_rule_is_named(cli, tmp_path):
    truth = fn.Model(**{"solver.cells": 32, "contact.boundary_friction": 0.22})
    t = np.arange(1001) * truth.dt
    run = truth.run(t, np.sin(2 * np.pi * t))
    data = tmp_path / "data.csv"
    np.savetxt(data, np.column_stack([t, np.sin(2 * np.pi * t), run["friction_n"]]), delimiter=",",
               header="t_s,velocity_m_s,friction_n", comments="")
    keys = ["contact.boundary_friction", "drivetrain.viscous_n_s_m"]
    rules = {"jacobian": "differences", "later_runs": "valley", "linear_keys": "searched",
             "cheap_keys": "profiled"}
    r = fn.fit(data, keys, overrides={"solver.cells": 32}, starts=2, global_points=4, **rules)
    out = tmp_path / "cli.yaml"
    cli("--set", "solver.cells=32", "fit", data, "--fit", ",".join(keys), "--starts", "2",
        "--global-points", "4", "--jacobian", "differences", "--later-runs", "valley",
        "--linear-keys", "searched", "--cheap-keys", "profiled", "--out", out)
    assert r.fitted_yaml == out.read_text()
    # The defaults solve the viscous loss instead of searching it: another path
    # to the same optimum, so the same value to the fit's tolerance.
    d = fn.fit(data, keys, overrides={"solver.cells": 32}, starts=2, global_points=4)
    assert d.value("contact.boundary_friction") == pytest.approx(0.22, rel=1e-3)
    assert r.value("contact.boundary_friction") == pytest.approx(0.22, rel=1e-3)
    for name, value, allowed in [("jacobian", "exact", "secant or differences"),
                                 ("later_runs", "some", "valley or full"),
                                 ("linear_keys", "fixed", "solved or searched"),
                                 ("cheap_keys", "held", "profiled or searched")]:
        with pytest.raises(ValueError) as e:
            fn.fit(data, keys, **{name: value})
        assert f"{name}: `{value}`" in str(e.value) and allowed in str(e.value)


def test_fit_takes_every_default_of_the_command_line(cli):
    """Each option `friction-node fit --help` gives a default is a parameter
    of `fit` (dashes as underscores) with that default."""
    params = inspect.signature(fn.fit).parameters
    blocks = re.split(r"\n\s+(?:-\w, )?--", cli("fit", "--help").stdout)
    checked = {}
    for block in blocks[1:]:
        flag = re.match(r"[a-z0-9-]+", block).group(0)
        default = re.search(r"\[default: ([^\]]+)\]", block)
        if default is None:
            continue
        name, text = flag.replace("-", "_"), default.group(1)
        assert name in params, f"--{flag} [default: {text}] is not a parameter of fit"
        ours = params[name].default
        assert ours == type(ours)(text), f"{name}: fit's default {ours!r}, the command line's {text}"
        checked[name] = ours
    assert {"holdout", "starts", "global_points", "seed", "max_evaluations", "jacobian",
            "later_runs", "linear_keys", "cheap_keys", "skip", "delimiter", "velocity",
            "friction", "smooth"} <= set(checked), checked


def test_a_fit_from_python_writes_the_report_the_cli_writes_section_for_section(cli, tmp_path):
    # One flow (fit/request.rs) for both: the same sections, --fit auto's
    # "Terms chosen by the data" and the models table included.
    truth = fn.Model(**{"solver.cells": 16, "contact.boundary_friction": 0.22,
                        "drivetrain.viscous_n_s_m": 400.0})
    t = np.arange(1001) * truth.dt
    v = 0.5 * np.sin(2 * np.pi * t)
    run = truth.run(t, v)
    data = tmp_path / "data.csv"
    np.savetxt(data, np.column_stack([t, v, run["friction_n"]]), delimiter=",",
               header="t_s,velocity_m_s,friction_n", comments="")
    fn.fit(data, ["auto"], overrides={"solver.cells": 16}, baselines=True, starts=1,
           global_points=0, max_evaluations=40, report=tmp_path / "py")
    cli("--set", "solver.cells=16", "fit", data, "--fit", "auto", "--baselines", "--starts", "1",
        "--global-points", "0", "--max-evaluations", "40", "--report", tmp_path / "cli",
        "--out", tmp_path / "cli.yaml")

    def sections(d):
        return [l for l in (d / "summary.md").read_text().splitlines() if l.startswith("#")]

    assert sections(tmp_path / "py") == sections(tmp_path / "cli")
    assert any("Terms chosen" in s for s in sections(tmp_path / "py")), sections(tmp_path / "py")
    assert any("Models" in s for s in sections(tmp_path / "py")), sections(tmp_path / "py")


def test_a_rotary_fit_takes_rad_s_and_newton_metres_and_equals_the_cli(cli, tmp_path):
    truth = fn.Model(**{"solver.cells": 32})
    t = np.arange(2001) * truth.dt
    v = 0.05 * np.sin(2 * np.pi * t)
    run = truth.run(t, v)
    lever = 0.02
    data = tmp_path / "joint.csv"
    np.savetxt(data, np.column_stack([t, v / lever, run["friction_n"] * lever]), delimiter=",",
               header="t_s,w,tau", comments="")
    r = fn.fit(data, ["contact.boundary_friction"], overrides={"solver.cells": 32}, starts=1,
               global_points=0, velocity="w", friction="tau", rotary=True)
    assert "training RMS" in r.summary and " N·m" in r.summary
    assert "gain:" in r.fitted_yaml
    out = tmp_path / "cli.yaml"
    cli("--set", "solver.cells=32", "fit", data, "--fit", "contact.boundary_friction", "--rotary",
        "--velocity", "w", "--friction", "tau", "--starts", "1", "--global-points", "0", "--out", out)
    assert r.fitted_yaml == out.read_text()


@pytest.mark.parametrize(
    "call, error, words",
    [
        (lambda: fn.Model(**{"contact.nope": 1}), ValueError, "contact.nope"),
        (lambda: fn.Model(**{"contact.load_n": -1}), ValueError, "contact.load_n"),
        (lambda: fn.Model("/no/such/config.yaml"), FileNotFoundError, "/no/such/config.yaml"),
        (lambda: fn.Model("not: [valid\n"), ValueError, "YAML text given to friction_node"),
        (lambda: fn.Model("/tmp"), OSError, "directory"),
        (lambda: fn.Model().step(50.0), ValueError, "node.max_abs_velocity_m_s"),
        (lambda: fn.fit("/no/such/data.csv", ["contact.boundary_friction"], holdout=2.0), ValueError,
         "holdout: 2 is out of range"),
        (lambda: fn.Model().run([0, 0.001, 0.002], [0, math.nan, 1]), ValueError, "velocity[1]"),
        (lambda: fn.Model().run([0, 0.001], [0, 1, 2]), ValueError, "same length"),
        (lambda: fn.Model().run([0, 0.002, 0.001], [0, 0, 0]), ValueError, "t[2]"),
        (lambda: fn.Model().run([0, 0.001], [0, 1e6]), ValueError, "max_abs_velocity"),
        (lambda: fn.Model().run([0, 0.001], [0, 1], load=[1.0, -5.0]), ValueError, "load[1]"),
        (lambda: fn.Model().run([0, 0.001], [[0, 1]]), ValueError, "1-D"),
        (lambda: fn.stribeck([0.1, math.inf]), ValueError, "velocities[1]"),
        (lambda: fn.replay("/no/such/bag.mcap"), FileNotFoundError, "/no/such/bag.mcap"),
        (lambda: fn.replay(__file__), ValueError, "not a bag"),
        (lambda: fn.fit("/no/such/data.csv", ["contact.boundary_friction"]), FileNotFoundError, "data.csv"),
    ],
)
def test_bad_input_is_a_python_exception_naming_it(call, error, words):
    with pytest.raises(error) as e:
        call()
    assert words in str(e.value)


def test_fit_names_an_unknown_key_and_a_bound_outside_the_fit(tmp_path):
    data = tmp_path / "d.csv"
    data.write_text("t_s,velocity_m_s,friction_n\n0,0,0\n0.001,0.1,100\n0.002,0.2,120\n")
    with pytest.raises(ValueError, match="contact.nope"):
        fn.fit(data, ["contact.nope"])
    with pytest.raises(ValueError, match="roughness.sigma_m"):
        fn.fit(data, ["contact.boundary_friction"], bounds={"roughness.sigma_m": (1e-6, 1e-5)})


THREE = """\
friction_node:
  ros__parameters:
    node: {transport: iceoryx2}
    solver: {cells: 32}
    contacts:
      left:  {joint: x_left,  contact: {load_n: 5000.0}}
      right: {joint: x_right, contact: {load_n: 4000.0}}
      wrist: {joint: wrist, gain: 0.03, contact: {load_n: 800.0}}
"""


def test_replay_of_a_recording_of_several_contacts_checks_each_contact(cli, tmp_path):
    import os

    cfg = tmp_path / "three.yaml"
    cfg.write_text(THREE)
    svc = f"fn_py_three_{os.getpid()}"
    services = []
    for key in ("cmd_velocity", "normal_load", "temperature", "friction", "loop_statistics",
                "cmd_event", "joint_state", "efforts", "contact_friction"):
        services += ["--set", f"iceoryx2.{key}_service={svc}/{key}"]
    bag = tmp_path / "three.mcap"
    cli("--config", cfg, *services, "run", "--demo", "1", "--record", bag, "--quiet")
    r = fn.replay(bag, out=tmp_path / "py.csv")
    assert [(name, same) for name, same, _ in r.summary["contacts"]] == [
        ("left", True), ("right", True), ("wrist", True)]
    assert r.identical is True
    counts = r.estimates["contact"].value_counts()
    assert set(counts.index) == {"left", "right", "wrist"}
    assert counts.nunique() == 1 and counts.iloc[0] > 500
    cli("replay", bag, "--out", tmp_path / "cli.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()


def _envelope_cases():
    """tests/fixtures/envelope_cases.csv: the inputs every entry point refuses."""
    path = Path(__file__).resolve().parents[2] / "tests" / "fixtures" / "envelope_cases.csv"
    rows = [l for l in path.read_text().splitlines() if l.strip() and not l.startswith("#")]
    out = []
    for row in csv.DictReader(rows):
        overrides = dict(kv.split("=", 1) for kv in row["overrides"].split(";") if kv)
        out.append((row["quantity"], float(row["value"]), overrides, row["expect"]))
    return out


@pytest.mark.parametrize("quantity, value, overrides, expect", _envelope_cases())
def test_step_run_and_set_temperature_refuse_every_envelope_case_with_one_rule(quantity, value, overrides, expect):
    m = fn.Model(overrides=overrides)
    before = m.step(0.1)
    t = [0.0, m.dt]
    with pytest.raises(ValueError) as e:
        if quantity == "temperature":
            m.set_temperature(value)
        elif quantity == "velocity":
            m.step(value)
        else:
            m.step(0.1, load=value)
    assert expect in str(e.value)
    with pytest.raises(ValueError) as e:
        if quantity == "temperature":
            fn.Model(overrides=overrides).run(t, [0.1, 0.1], temperature=[40.0, value])
        elif quantity == "velocity":
            fn.Model(overrides=overrides).run(t, [0.1, value])
        else:
            fn.Model(overrides=overrides).run(t, [0.1, 0.1], load=[20762.0, value])
    # A non-finite sample is refused by the array check before the envelope.
    assert f"{quantity}[1]" in str(e.value)
    assert (expect if math.isfinite(value) else "not a finite number") in str(e.value)
    # The refused call changed nothing.
    twin = fn.Model(overrides=overrides)
    twin.step(0.1)
    assert m.step(0.2).friction_force_n == twin.step(0.2).friction_force_n
    assert before.status == "converged"


def test_ctrl_c_stops_a_long_model_run_with_keyboard_interrupt(tmp_path):
    """Model.run checks Python's signals between chunks: SIGINT during a
    run of millions of steps raises KeyboardInterrupt instead of finishing."""
    import signal
    import subprocess
    import sys

    script = tmp_path / "long_run.py"
    script.write_text(
        "import sys, numpy as np, friction_node as fn\n"
        "m = fn.Model(**{'solver.cells': 256})\n"
        "t = np.arange(0, 600, m.dt)\n"
        "try:\n"
        "    print('running', flush=True)\n"
        "    m.run(t, 0.2 * np.sin(t))\n"
        "except KeyboardInterrupt:\n"
        "    print('interrupted', flush=True)\n"
        "    sys.exit(7)\n"
        "print('finished', flush=True)\n"
    )
    p = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, text=True)
    assert p.stdout.readline().strip() == "running"
    p.send_signal(signal.SIGINT)
    out, _ = p.communicate()
    assert p.returncode == 7 and "interrupted" in out, out


def test_set_parameter_changes_a_live_key_and_refuses_what_the_c_api_refuses():
    m = fn.Model(**{"solver.cells": 32})
    before = m.step(0.5)
    m.set_parameter("contact.boundary_friction", 0.15)
    after = m.step(0.5)
    # The boundary part of the friction halves; the film is the same state.
    assert after.friction_force_n < before.friction_force_n
    assert "boundary_friction: 0.15" in m.config_yaml()
    m.set_parameter("contact.boundary_friction", "0.3")
    assert "boundary_friction: 0.3" in m.config_yaml()
    for key, value, words in [
        ("contact.nope", 1.0, "contact.nope"),
        ("contact.boundary_friction", -1.0, "contact.boundary_friction"),
        ("contact.boundary_friction", float("nan"), "contact.boundary_friction"),
        ("solver.cells", 64, "solver.cells"),
    ]:
        with pytest.raises(ValueError) as e:
            m.set_parameter(key, value)
        assert words in str(e.value), str(e.value)
    # A refused change leaves the model as it was.
    assert "boundary_friction: 0.3" in m.config_yaml()


def test_a_configuration_error_in_replay_is_not_blamed_on_the_bag(repo):
    bag = repo / "bags/node_lockstep.mcap"
    with pytest.raises(ValueError) as e:
        fn.replay(bag, overrides={"contact.load_n": -1})
    assert "contact.load_n" in str(e.value)
    assert not str(e.value).startswith("bag "), str(e.value)
