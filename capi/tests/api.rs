//! The C API's contract, called from Rust as C would call it: errors are
//! codes with a message naming the input, nothing panics across the
//! boundary, bad handles are detected, parameters change the model, and a
//! step does not allocate.

use friction_node_c::*;
use std::cell::Cell;
use std::ffi::{c_char, CStr, CString};
use std::ptr::{null, null_mut};

struct CountingAlloc;
thread_local! {
    static ALLOCATIONS: Cell<u64> = const { Cell::new(0) };
}
unsafe impl std::alloc::GlobalAlloc for CountingAlloc {
    unsafe fn alloc(&self, l: std::alloc::Layout) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        unsafe { std::alloc::System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: std::alloc::Layout) {
        unsafe { std::alloc::System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: std::alloc::Layout, n: usize) -> *mut u8 {
        let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
        unsafe { std::alloc::System.realloc(p, l, n) }
    }
}
#[global_allocator]
static GLOBAL: CountingAlloc = CountingAlloc;

fn last_error() -> String {
    let mut buf = [0 as c_char; 512];
    let n = unsafe { fn_last_error(buf.as_mut_ptr(), buf.len()) };
    let s = unsafe { CStr::from_ptr(buf.as_ptr()) }
        .to_str()
        .unwrap()
        .to_string();
    assert_eq!(n, s.len(), "short messages are copied whole");
    s
}

fn new_model(yaml: &str) -> Result<*mut FnModel, (i32, String)> {
    let y = CString::new(yaml).unwrap();
    let mut m = null_mut();
    match unsafe { fn_model_new_from_yaml(y.as_ptr(), &mut m) } {
        FN_OK => Ok(m),
        code => Err((code, last_error())),
    }
}

fn set(m: *mut FnModel, key: &str, value: &str) -> Result<(), (i32, String)> {
    let (k, v) = (CString::new(key).unwrap(), CString::new(value).unwrap());
    match unsafe { fn_model_set_parameter(m, k.as_ptr(), v.as_ptr()) } {
        FN_OK => Ok(()),
        code => Err((code, last_error())),
    }
}

fn step(m: *mut FnModel, v: f64, load: f64, dt: f64) -> FnEstimate {
    let mut e = FnEstimate::default();
    assert_eq!(unsafe { fn_model_step(m, v, load, dt, &mut e) }, FN_OK);
    e
}

#[test]
fn a_bad_configuration_is_an_error_code_with_the_key_and_value_named() {
    let (code, msg) =
        new_model("/**:\n  ros__parameters:\n    contact:\n      load_n: -3.0\n").unwrap_err();
    assert_eq!(code, FN_ERROR_CONFIG);
    assert!(
        msg.contains("contact.load_n") && msg.contains("-3"),
        "{msg}"
    );
    let (code, msg) =
        new_model("/**:\n  ros__parameters:\n    contact:\n      lod_n: 1\n").unwrap_err();
    assert_eq!(code, FN_ERROR_CONFIG);
    assert!(msg.contains("lod_n"), "{msg}");
    let (code, msg) = new_model(
        "/**:\n  ros__parameters:\n    contacts:\n      left: {gain: 0}\n      right: {}\n",
    )
    .unwrap_err();
    assert_eq!(code, FN_ERROR_CONFIG);
    assert!(msg.contains("contacts.left.gain"), "{msg}");
    let (code, _) = new_model("{{{").unwrap_err();
    assert_eq!(code, FN_ERROR_CONFIG);
    let path = CString::new("/nonexistent/machine.yaml").unwrap();
    let mut m = null_mut();
    assert_eq!(
        unsafe { fn_model_new_from_file(path.as_ptr(), &mut m) },
        FN_ERROR_IO
    );
    assert!(last_error().contains("/nonexistent/machine.yaml"));
    assert!(m.is_null());
    assert_eq!(
        unsafe { fn_model_new_from_yaml(null(), &mut m) },
        FN_ERROR_NULL_ARGUMENT
    );
    let bad_utf8 = [0xffu8 as c_char, 0];
    assert_eq!(
        unsafe { fn_model_new_from_yaml(bad_utf8.as_ptr(), &mut m) },
        FN_ERROR_UTF8
    );
    let y = CString::new("").unwrap();
    assert_eq!(
        unsafe { fn_model_new_from_yaml(y.as_ptr(), null_mut()) },
        FN_ERROR_NULL_ARGUMENT
    );
    // The caller's own YAML is named as such, never as the built-in file.
    let (code, msg) = new_model("not: [valid").unwrap_err();
    assert_eq!(code, FN_ERROR_CONFIG);
    assert!(
        msg.contains("YAML text passed to fn_model_new_from_yaml") && !msg.contains("built-in"),
        "{msg}"
    );
    // A directory given as the file: the reason is kept.
    let dir = CString::new(std::env::temp_dir().to_str().unwrap()).unwrap();
    assert_eq!(
        unsafe { fn_model_new_from_file(dir.as_ptr(), &mut m) },
        FN_ERROR_IO
    );
    let msg = last_error();
    assert!(msg.contains("directory"), "{msg}");
}

#[test]
fn null_freed_and_foreign_handles_are_refused_not_followed() {
    let mut e = FnEstimate::default();
    assert_eq!(
        unsafe { fn_model_step(null_mut(), 0.1, 1e4, 1e-3, &mut e) },
        FN_ERROR_INVALID_HANDLE
    );
    // A pointer to something that is not a model (aligned, readable).
    let mut junk = vec![0u64; 4096];
    let foreign = junk.as_mut_ptr() as *mut FnModel;
    assert_eq!(
        unsafe { fn_model_step(foreign, 0.1, 1e4, 1e-3, &mut e) },
        FN_ERROR_INVALID_HANDLE
    );
    assert!(last_error().contains("not a friction-node model"));
    assert_eq!(unsafe { fn_model_dt(foreign) }, 0.0);
    unsafe { fn_model_free(foreign) }; // ignored, not freed
    unsafe { fn_model_free(null_mut()) };
    let m = new_model("").unwrap();
    assert_eq!(
        unsafe { fn_model_step(m, 0.1, 1e4, 1e-3, null_mut()) },
        FN_ERROR_NULL_ARGUMENT
    );
    unsafe { fn_model_free(m) };
    drop(junk);
}

#[test]
fn a_step_is_a_status_not_an_error_and_does_not_allocate() {
    let m = new_model("").unwrap();
    let dt = unsafe { fn_model_dt(m) };
    assert_eq!(dt, 1e-3);
    let mut e = FnEstimate::default();
    let before = ALLOCATIONS.with(Cell::get);
    for k in 1..=2000 {
        let v = (2.0 * std::f64::consts::PI * k as f64 * dt).sin();
        assert_eq!(unsafe { fn_model_step(m, v, 20762.0, dt, &mut e) }, FN_OK);
        assert_eq!(e.status, FN_STATUS_CONVERGED, "step {k}");
    }
    assert_eq!(
        ALLOCATIONS.with(Cell::get) - before,
        0,
        "allocations in 2000 steps"
    );
    // Out of the envelope: FN_OK, the status says so, the last good values held.
    let good = e;
    let bad = step(m, f64::NAN, 20762.0, dt);
    assert_eq!(bad.status, FN_STATUS_NON_FINITE_INPUT);
    assert_eq!(bad.friction_force_n, good.friction_force_n);
    assert_eq!(step(m, 0.5, -1.0, dt).status, FN_STATUS_INPUT_OUT_OF_RANGE);
    assert_eq!(
        step(m, 0.5, 20762.0, 7200.0).status,
        FN_STATUS_INPUT_OUT_OF_RANGE
    );
    let name = unsafe { CStr::from_ptr(fn_status_name(FN_STATUS_INPUT_OUT_OF_RANGE)) };
    assert_eq!(name.to_str().unwrap(), "input_out_of_range");
    // A late period: one backward-Euler step of 3 ms, then back to dt.
    let late = step(m, 0.5, 20762.0, 3e-3);
    assert_eq!(late.status, FN_STATUS_CONVERGED);
    assert!(
        (late.time_s - good.time_s - 3e-3 - 3.0 * dt).abs() < 1e-12,
        "{}",
        late.time_s
    );
    unsafe { fn_model_free(m) };
}

#[test]
fn a_runtime_parameter_changes_the_model_and_a_refused_one_changes_nothing() {
    // Two identical models; only `m` is offered the refused changes.
    let m = new_model("").unwrap();
    let twin = new_model("").unwrap();
    let dt = unsafe { fn_model_dt(m) };
    for _ in 0..200 {
        step(m, 0.05, 20762.0, dt);
        step(twin, 0.05, 20762.0, dt);
    }
    let (code, msg) = set(m, "contact.boundary_friction", "7").unwrap_err();
    assert_eq!(code, FN_ERROR_PARAMETER);
    assert!(
        msg.contains("contact.boundary_friction") && msg.contains('7'),
        "{msg}"
    );
    let (_, msg) = set(m, "solver.cells", "64").unwrap_err();
    assert!(msg.contains("solver.cells"), "read-only: {msg}");
    let (_, msg) = set(m, "contact.boundary_friction", "high").unwrap_err();
    assert!(
        msg.contains("contact.boundary_friction") && msg.contains("high"),
        "{msg}"
    );
    let (_, msg) = set(m, "contact.nosuch", "1").unwrap_err();
    assert!(msg.contains("contact.nosuch"), "{msg}");
    let before = step(m, 0.05, 20762.0, dt);
    assert_eq!(
        before,
        step(twin, 0.05, 20762.0, dt),
        "refused sets changed nothing"
    );
    // Half the boundary friction: the asperity part of the friction halves.
    set(m, "contact.boundary_friction", "0.15").unwrap();
    let after = step(m, 0.05, 20762.0, dt);
    assert!(after.asperity_force_n > 0.0);
    let asperity_part = |e: &FnEstimate, mu: f64| mu * e.asperity_force_n;
    assert!(
        (after.friction_force_n
            - before.friction_force_n
            - (asperity_part(&after, 0.15) - asperity_part(&before, 0.3)))
        .abs()
            < 0.05 * before.friction_force_n.abs(),
        "{} -> {}",
        before.friction_force_n,
        after.friction_force_n
    );
    assert!(after.friction_force_n < 0.75 * before.friction_force_n);
    let t = CString::new("x").unwrap();
    assert_eq!(
        unsafe { fn_model_set_parameter(m, t.as_ptr(), null()) },
        FN_ERROR_NULL_ARGUMENT
    );
    assert_eq!(
        unsafe { fn_model_set_temperature(m, f64::NAN) },
        FN_ERROR_ARGUMENT
    );
    assert_eq!(unsafe { fn_model_set_temperature(m, 40.0) }, FN_OK);
    assert_eq!(unsafe { fn_model_reset(m, 0.0, -1.0) }, FN_ERROR_ARGUMENT);
    assert_eq!(unsafe { fn_model_reset(m, 0.0, 20762.0) }, FN_OK);
    unsafe { fn_model_free(m) };
    unsafe { fn_model_free(twin) };
}

const THREE: &str = "/**:
  ros__parameters:
    solver: {cells: 48}
    contacts:
      left: {joint: j_left, contact: {load_n: 4000.0}}
      right: {joint: j_right, gain: 0.05}
      wrist: {joint: j_wrist, gain: 0.02, solver: {cells: 24}, lubricant: {viscosity_pa_s: 0.1}}
";

/// The one-contact configuration of contact `name` of THREE.
fn one_of_three(name: &str) -> String {
    let cfg = friction_node::config::Config::from_yaml(
        THREE,
        &friction_node::config::Origin::Embedded,
        &[],
    )
    .unwrap();
    let c = cfg
        .resolved_contacts()
        .into_iter()
        .find(|c| c.name == name)
        .unwrap();
    format!(
        "/**:\n  ros__parameters:\n{}",
        serde_norway::to_string(&c.config)
            .unwrap()
            .lines()
            .filter(|l| !l.starts_with("contacts:"))
            .map(|l| format!("    {l}\n"))
            .collect::<String>()
    )
}

#[test]
fn one_handle_steps_several_contacts_each_equal_to_its_own_handle_at_gain_times_the_joint_velocity_with_gain_times_friction_efforts(
) {
    let m = new_model(THREE).unwrap();
    assert_eq!(unsafe { fn_model_contact_count(m) }, 3);
    let idx = |name: &str| {
        let n = CString::new(name).unwrap();
        let mut i = u32::MAX;
        let code = unsafe { fn_model_contact_index(m, n.as_ptr(), &mut i) };
        (code, i)
    };
    assert_eq!(idx("right"), (FN_OK, 1));
    assert_eq!(idx("j_wrist"), (FN_OK, 2), "by joint name");
    let (code, _) = idx("gripper");
    assert_eq!(code, FN_ERROR_ARGUMENT);
    assert!(last_error().contains("gripper") && last_error().contains("j_left"));
    let singles: Vec<*mut FnModel> = ["left", "right", "wrist"]
        .iter()
        .map(|n| new_model(&one_of_three(n)).unwrap())
        .collect();
    let gains = [1.0, 0.05, 0.02];
    let dt = unsafe { fn_model_dt(m) };
    let mut out = [FnEstimate::default(); 3];
    let mut efforts = [0.0; 3];
    let mut allocated = 0;
    let mut alone = Vec::new();
    for k in 1..=500 {
        let t = k as f64 * dt;
        let v: Vec<f64> = (0..3)
            .map(|i| {
                (1.0 + 0.3 * i as f64) * (2.0 * std::f64::consts::PI * (t + 0.1 * i as f64)).sin()
            })
            .collect();
        let before = ALLOCATIONS.with(Cell::get);
        let code = unsafe {
            fn_model_step_contacts(
                m,
                v.as_ptr(),
                null(),
                3,
                dt,
                out.as_mut_ptr(),
                efforts.as_mut_ptr(),
            )
        };
        allocated += ALLOCATIONS.with(Cell::get) - before;
        assert_eq!(code, FN_OK);
        alone.clear();
        for (i, &s) in singles.iter().enumerate() {
            let load = [4000.0, 20762.0, 20762.0][i];
            // The contact slides at gain × its joint's velocity.
            alone.push(step(s, gains[i] * v[i], load, dt));
        }
        for i in 0..3 {
            assert_eq!(out[i], alone[i], "step {k}, contact {i}");
            assert_eq!(efforts[i], gains[i] * out[i].friction_force_n);
        }
    }
    assert!(out.iter().all(|e| e.status == FN_STATUS_CONVERGED));
    assert_eq!(allocated, 0, "allocations in 500 steps of three contacts");
    // Loads given per contact (right: 0.2 m/s at its 0.05 m lever).
    let v = [0.2, 4.0, 0.2];
    let loads = [3000.0, 3000.0, 3000.0];
    assert_eq!(
        unsafe {
            fn_model_step_contacts(
                m,
                v.as_ptr(),
                loads.as_ptr(),
                3,
                dt,
                out.as_mut_ptr(),
                null_mut(),
            )
        },
        FN_OK
    );
    assert!(out.iter().all(|e| e.load_n == 3000.0));
    // Bad calls: a wrong count, null arrays, the one-contact step.
    let code = unsafe {
        fn_model_step_contacts(m, v.as_ptr(), null(), 2, dt, out.as_mut_ptr(), null_mut())
    };
    assert_eq!(code, FN_ERROR_ARGUMENT);
    assert!(last_error().contains("count is 2") && last_error().contains("3 contacts"));
    let code =
        unsafe { fn_model_step_contacts(m, null(), null(), 3, dt, out.as_mut_ptr(), null_mut()) };
    assert_eq!(code, FN_ERROR_NULL_ARGUMENT);
    let mut e = FnEstimate::default();
    assert_eq!(
        unsafe { fn_model_step(m, 0.1, 1000.0, dt, &mut e) },
        FN_ERROR_ARGUMENT
    );
    assert!(last_error().contains("fn_model_step_contacts"));
    // A per-contact parameter changes that contact alone; reset restarts all.
    let twin = new_model(THREE).unwrap();
    unsafe {
        fn_model_step_contacts(
            twin,
            v.as_ptr(),
            loads.as_ptr(),
            3,
            dt,
            out.as_mut_ptr(),
            null_mut(),
        )
    };
    set(m, "contacts.right.lubricant.viscosity_pa_s", "0.2").unwrap();
    let (code, msg) = set(m, "contacts.right.joint", "x").unwrap_err();
    assert_eq!(code, FN_ERROR_PARAMETER);
    assert!(msg.contains("contacts.right.joint"), "{msg}");
    assert_eq!(unsafe { fn_model_reset(m, 0.0, 0.0) }, FN_OK);
    assert_eq!(unsafe { fn_model_reset(twin, 0.0, 0.0) }, FN_OK);
    let mut a = [FnEstimate::default(); 3];
    let mut b = [FnEstimate::default(); 3];
    for _ in 0..50 {
        unsafe {
            fn_model_step_contacts(m, v.as_ptr(), null(), 3, dt, a.as_mut_ptr(), null_mut());
            fn_model_step_contacts(twin, v.as_ptr(), null(), 3, dt, b.as_mut_ptr(), null_mut());
        }
    }
    // (The reset's steady solve is warm-started from each run's own state:
    // equal to the solver tolerance, not bit for bit.)
    let rel = |x: f64, y: f64| (x - y).abs() / y.abs();
    assert!(rel(a[0].friction_force_n, b[0].friction_force_n) < 1e-8);
    assert!(rel(a[2].friction_force_n, b[2].friction_force_n) < 1e-8);
    assert!(
        rel(a[1].friction_force_n, b[1].friction_force_n) > 1e-3,
        "{} vs {}",
        a[1].friction_force_n,
        b[1].friction_force_n
    );
    for h in singles.into_iter().chain([m, twin]) {
        unsafe { fn_model_free(h) };
    }
    assert_eq!(unsafe { fn_model_contact_count(null()) }, 0);
}

/// One case every entry point refuses: (quantity, value, overrides,
/// expected message part).
type EnvelopeCase = (String, f64, Vec<(String, String)>, String);

/// `tests/fixtures/envelope_cases.csv`.
fn envelope_cases() -> Vec<EnvelopeCase> {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/fixtures/envelope_cases.csv"
    );
    let text = std::fs::read_to_string(path).expect("the cases file");
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .skip(1)
        .map(|l| {
            let mut f = l.splitn(4, ',');
            let (q, v, o, e) = (
                f.next().unwrap(),
                f.next().unwrap(),
                f.next().unwrap(),
                f.next().unwrap(),
            );
            let overrides = o
                .split(';')
                .filter(|s| !s.is_empty())
                .map(|kv| {
                    let (k, v) = kv.split_once('=').unwrap();
                    (k.to_string(), v.to_string())
                })
                .collect();
            (
                q.into(),
                v.parse().unwrap(),
                overrides,
                e.trim_matches('"').into(),
            )
        })
        .collect()
}

#[test]
fn the_c_api_refuses_every_envelope_case_with_the_rule_of_every_entry_point() {
    let cases = envelope_cases();
    assert!(cases.len() >= 10);
    for (quantity, value, overrides, expect) in cases {
        let m = new_model("").unwrap();
        for (k, v) in &overrides {
            set(m, k, v).unwrap();
        }
        let before = step(m, 0.1, 20762.0, 1e-3);
        match quantity.as_str() {
            "temperature" => {
                assert_eq!(
                    unsafe { fn_model_set_temperature(m, value) },
                    FN_ERROR_ARGUMENT,
                    "{value}"
                );
                let msg = last_error();
                assert!(msg.contains(&expect), "{value}: {msg}");
                // Nothing changed: the next step is the one a model that
                // never saw the temperature takes.
                let twin = new_model("").unwrap();
                for (k, v) in &overrides {
                    set(twin, k, v).unwrap();
                }
                step(twin, 0.1, 20762.0, 1e-3);
                let (a, b) = (step(m, 0.2, 20762.0, 1e-3), step(twin, 0.2, 20762.0, 1e-3));
                assert_eq!(a.friction_force_n, b.friction_force_n, "{value}");
                unsafe { fn_model_free(twin) };
            }
            "velocity" | "load" => {
                let (v, f) = if quantity == "velocity" {
                    (value, 20762.0)
                } else {
                    (0.1, value)
                };
                let e = step(m, v, f, 1e-3);
                assert_eq!(e.status, FN_STATUS_INPUT_OUT_OF_RANGE, "{quantity} {value}");
                assert_eq!(
                    e.friction_force_n, before.friction_force_n,
                    "the last good estimate"
                );
            }
            q => panic!("unknown quantity {q}"),
        }
        unsafe { fn_model_free(m) };
    }
}

#[test]
fn the_real_drive_terms_are_in_the_c_api_bit_for_bit() {
    // Pre-sliding, a soft width, a rate-sensitive boundary film, a quadratic
    // loss and an asymmetry: the C API's steps equal the solver's own.
    let yaml = "/**:\n  ros__parameters:\n    solver: {cells: 32}\n    contact: {presliding_stiffness_n_m: 1.0e+8, width_load_exponent: 0.5, boundary_friction_rate: 0.01, boundary_activation_speed_m_s: 1.0e-3}\n    drivetrain: {quadratic_n_s2_m2: 300.0, coulomb_asymmetry_n: 40.0}\n";
    let m = new_model(yaml).unwrap();
    let c = friction_node::config::Config::from_yaml(
        yaml,
        &friction_node::config::Origin::Embedded,
        &[],
    )
    .unwrap();
    let mut s = friction_node::physics::Solver::new(&c.model(), &c.solver_settings()).unwrap();
    s.initialize_steady(0.0, c.contact.load_n);
    for k in 1..=500 {
        let v = 0.3 * (k as f64 * 1e-3 * std::f64::consts::TAU).sin();
        let e = step(m, v, 15_000.0, 1e-3);
        assert_eq!(
            e.friction_force_n,
            s.step(v, 15_000.0).friction_force,
            "step {k}"
        );
    }
    unsafe { fn_model_free(m) };
}

#[test]
fn each_estimate_says_where_its_input_lay_against_the_calibrated_range_and_zero_publishes_none() {
    let yaml = |policy: &str| {
        format!(
            "/**:\n  ros__parameters:\n    solver: {{cells: 32}}\n    node: {{outside_envelope: {policy}}}\n    \
             calibrated_range: {{speed_forward_min_m_s: 0.0, speed_forward_max_m_s: 0.3, \
             speed_backward_min_m_s: 0.0, speed_backward_max_m_s: 0.3, training_rms_n: 1.0, \
             training_samples: 10}}\n"
        )
    };
    let plain = new_model("/**:\n  ros__parameters:\n    solver: {cells: 32}\n").unwrap();
    assert_eq!(
        step(plain, 1.0, 20_762.0, 1e-3).calibrated_range,
        FN_RANGE_NOT_WATCHED
    );
    let warn = new_model(&yaml("warn")).unwrap();
    let zero = new_model(&yaml("zero")).unwrap();
    let hold = new_model(&yaml("hold")).unwrap();
    let edge = new_model("/**:\n  ros__parameters:\n    solver: {cells: 32}\n").unwrap();
    for (k, v) in [0.1, 0.2, 1.0, 1.0, 0.2].into_iter().enumerate() {
        let (w, z, h) = (
            step(warn, v, 20_762.0, 1e-3),
            step(zero, v, 20_762.0, 1e-3),
            step(hold, v, 20_762.0, 1e-3),
        );
        let e = step(edge, v.min(0.3), 20_762.0, 1e-3);
        let want = if v > 0.3 {
            FN_RANGE_OUTSIDE
        } else {
            FN_RANGE_INSIDE
        };
        for x in [w, z, h] {
            assert_eq!(x.calibrated_range, want, "step {k}");
        }
        assert_eq!(
            h.friction_force_n, e.friction_force_n,
            "hold: the edge's, step {k}"
        );
        if v > 0.3 {
            assert_eq!(z.friction_force_n, 0.0, "step {k}");
            assert!(w.friction_force_n > 0.0);
        } else {
            assert_eq!(z.friction_force_n, w.friction_force_n, "step {k}");
        }
    }
    // The policy is a parameter like the other node.* keys.
    set(warn, "node.outside_envelope", "zero").unwrap();
    assert_eq!(step(warn, 1.0, 20_762.0, 1e-3).friction_force_n, 0.0);
    for m in [plain, warn, zero, hold, edge] {
        unsafe { fn_model_free(m) };
    }
}
