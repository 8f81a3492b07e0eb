"""A fit's standard errors: a time series' from contiguous batches of its
residuals (its consecutive samples are not independent news), a steady
curve's from its points as independent."""

import numpy as np

import friction_node as fn


def _series(path, drift_share, rng):
    """A joint sliding one way at 500 Hz, its friction a level of 3 N·m
    plus noise of RMS 0.05 N·m: the share `drift_share` of the noise's
    power a slow wandering no model has (two periods over the record), the
    rest white."""
    t = np.arange(0, 8, 0.002)
    w = 0.2 + 0.1 * np.sin(2 * np.pi * 0.5 * t)
    white = rng.normal(0, 1, t.shape)
    slow = np.sin(2 * np.pi * 0.25 * t + 0.3)
    noise = np.sqrt(1 - drift_share) * white / white.std() + np.sqrt(drift_share) * slow / slow.std()
    np.savetxt(path, np.column_stack([t, w, 3.0 + 0.05 * noise]), delimiter=",",
               header="t_s,velocity_rad_s,friction_nm", comments="")


def _fit(path):
    return fn.fit(str(path), ["contact.boundary_friction"], rotary=True,
                  global_points=0, starts=1)


def _se(r):
    return float(r.parameters.set_index("name").loc["contact.boundary_friction", "std_error"])


def test_a_time_series_errors_come_from_32_batches_and_a_slow_drift_widens_them(tmp_path):
    rng = np.random.default_rng(5)
    white, drift = tmp_path / "white.csv", tmp_path / "drift.csv"
    _series(white, 0.0, rng)
    _series(drift, 0.5, rng)
    rw, rd = _fit(white), _fit(drift)
    assert rw.error_batches == 32 and rd.error_batches == 32
    # The same residual RMS, but half its power alike over hundreds of
    # samples: the level is known far less well than 4000 independent
    # samples would tell.
    assert rw.train_rms_n < 0.06, rw.train_rms_n
    assert abs(rd.train_rms_n / rw.train_rms_n - 1) < 0.1, (rd.train_rms_n, rw.train_rms_n)
    assert _se(rd) > 5 * _se(rw), (_se(rd), _se(rw))


def test_a_steady_curve_counts_its_points_as_independent(tmp_path):
    w = np.logspace(-1, 1, 20)
    p = tmp_path / "steady.csv"
    f = 3.0 + 0.02 * np.random.default_rng(6).normal(size=w.shape)
    np.savetxt(p, np.column_stack([w, f]), delimiter=",",
               header="velocity_rad_s,friction_nm", comments="")
    r = _fit(p)
    assert r.error_batches == 0
    assert r.train_rms_n < 0.05, r.train_rms_n
    assert _se(r) > 0
