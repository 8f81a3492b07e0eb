//! In-process C API of the friction-node model, for code that runs the
//! model inside its own control loop (a ros2_control controller's
//! `update()`, a hardware plugin's `write()`): no process, no topics, no
//! copies. The header `include/friction_node.h` is generated from this file
//! by cbindgen and checked to be current by `tests/header.rs`.
//!
//! ```c
//! char err[512];
//! FnModel *m = NULL;
//! if (fn_model_new_from_file("machine.yaml", &m) != FN_OK) {
//!     fn_last_error(err, sizeof err); fprintf(stderr, "%s\n", err); return 1;
//! }
//! FnEstimate e;
//! fn_model_step(m, velocity_m_s, load_n, 0.001, &e);  /* every period */
//! effort += e.friction_force_n;                      /* feed-forward */
//! fn_model_free(m);
//! ```
//!
//! **Several contacts in one handle.** A configuration with `contacts` makes
//! one handle for all of them, in the order they are listed (the joint
//! order of the node's `Float64MultiArray`): `fn_model_step_contacts` steps
//! them all in one call, taking arrays of velocities (and optionally loads)
//! and writing each contact's estimate and its feed-forward effort
//! (`gain` × friction, the input of `forward_command_controller`);
//! `fn_model_contact_count` and `fn_model_contact_index` (by contact or joint
//! name) say which is where. `fn_model_step` steps a one-contact handle only.
//!
//! ```c
//! double v[8], effort[8]; FnEstimate e[8];
//! /* v[i] = the velocity of joint i, in the configuration's contact order */
//! fn_model_step_contacts(m, v, NULL, 8, 0.001, e, effort);
//! ```
//!
//! | function | allocates | may be called from the control loop |
//! |---|---|---|
//! | `fn_model_new_from_yaml`, `fn_model_new_from_file` | yes (the solver's buffers) | no: at configure time |
//! | `fn_model_step`, `fn_model_step_contacts`, `fn_model_set_temperature`, `fn_model_dt`, `fn_model_contact_count`, `fn_model_contact_index` | **no** | yes |
//! | `fn_model_reset` | no | yes (it solves a steady state: slower than a step) |
//! | `fn_model_set_parameter` | yes (rebuilds the model's tables) | no: from a non-real-time thread, between steps |
//! | `fn_model_free`, `fn_last_error`, `fn_status_name` | frees / no / no | — |
//!
//! **Units**: SI, as in the configuration: m/s, N, s, °C. **Time step**: a
//! step of the configured `solver.dt_s` continues the second-order (BDF2)
//! history; any other length in (0, 3600] s is one backward-Euler step after
//! which the history restarts (first order: use it for an occasional late
//! period, not as the normal step). **Threads**: a model is used by one
//! thread at a time (no internal locking); different models are independent
//! and may run on different threads at once. Every function is reentrant.
//! **Errors**: functions return an `FN_*` code; the message of the last
//! error on the calling thread is kept for `fn_last_error`. A numerical
//! outcome is not an error: `fn_model_step` returns `FN_OK` and the
//! estimate's `status` says what the solver did. No function panics across
//! the boundary: a panic inside is caught and returned as `FN_ERROR_PANIC`.
//! A null handle, and a handle that is not a live model where that can be
//! seen (a wrong pointer, a model already freed while its memory still holds
//! the freed marker), return `FN_ERROR_INVALID_HANDLE`.

use friction_node::config::parameters::{declare, set_from_text, Declared};
use friction_node::config::{Config, Origin, ResolvedContact, ViscosityLaw};
use friction_node::msgs::{regime_code, status_code};
use friction_node::physics::{Estimate, Solver};
use std::cell::RefCell;
use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Success.
pub const FN_OK: i32 = 0;
/// A required pointer argument was null.
pub const FN_ERROR_NULL_ARGUMENT: i32 = 1;
/// The handle is null or not a live model.
pub const FN_ERROR_INVALID_HANDLE: i32 = 2;
/// The configuration was refused (syntax, unknown key, type, range); the
/// message names the key and value.
pub const FN_ERROR_CONFIG: i32 = 3;
/// A file could not be read.
pub const FN_ERROR_IO: i32 = 4;
/// The solver could not be built from a valid configuration.
pub const FN_ERROR_SETUP: i32 = 5;
/// A parameter set was refused (unknown, read-only, wrong type, out of
/// range); the model is unchanged.
pub const FN_ERROR_PARAMETER: i32 = 6;
/// An argument was out of its range (a step length, a temperature).
pub const FN_ERROR_ARGUMENT: i32 = 7;
/// A string argument was not UTF-8.
pub const FN_ERROR_UTF8: i32 = 8;
/// A panic inside the library was caught; the model should be freed.
pub const FN_ERROR_PANIC: i32 = 9;

/// `FnEstimate.status`: the solver converged.
pub const FN_STATUS_CONVERGED: u8 = 0;
/// The iteration bound was hit; the last finite iterate was kept.
pub const FN_STATUS_MAX_ITERATIONS: u8 = 1;
/// A non-finite value appeared; the previous state was kept.
pub const FN_STATUS_NON_FINITE: u8 = 2;
/// A non-finite velocity or load was given; the last good estimate is
/// reported, the state kept.
pub const FN_STATUS_NON_FINITE_INPUT: u8 = 3;
/// |v| > 100 m/s, a load not in (0, 1e9] N, or a step length not in
/// (0, 3600] s;
/// handled as `FN_STATUS_NON_FINITE_INPUT`.
pub const FN_STATUS_INPUT_OUT_OF_RANGE: u8 = 6;

/// `FnEstimate.regime`: asperities carry at least 95 % of the load.
pub const FN_REGIME_BOUNDARY: u8 = 0;
/// Between the two.
pub const FN_REGIME_MIXED: u8 = 1;
/// Asperities carry at most 5 % of the load.
pub const FN_REGIME_HYDRODYNAMIC: u8 = 2;

/// One step's estimate (the fields of `friction_msgs/FrictionEstimate`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct FnEstimate {
    /// Model time at the end of the step, s.
    pub time_s: f64,
    /// Sliding velocity of the step, m/s.
    pub velocity_m_s: f64,
    /// Normal load of the step, N.
    pub load_n: f64,
    /// Total friction (contact and drivetrain), signed like the velocity:
    /// add it to the command, N.
    pub friction_force_n: f64,
    /// The lubricated contact alone, N.
    pub contact_friction_force_n: f64,
    /// (|F_visc| + mu_bl F_asp) / F_ext.
    pub cof: f64,
    /// Minimum nominal separation, m.
    pub h0_m: f64,
    /// Minimum film thickness, m.
    pub h_min_m: f64,
    /// Fluid load, N.
    pub hydrodynamic_force_n: f64,
    /// Greenwood–Williamson contact force, N.
    pub asperity_force_n: f64,
    /// asperity_force_n / load_n.
    pub asperity_load_share: f64,
    /// Newton's last residual (scaled).
    pub residual: f64,
    /// Newton iterations of the step.
    pub iterations: u32,
    /// Backward-Euler sub-steps taken as a fallback (0 normally).
    pub substeps: u32,
    /// `FN_STATUS_*`.
    pub status: u8,
    /// `FN_REGIME_*`.
    pub regime: u8,
}

impl From<&Estimate> for FnEstimate {
    fn from(e: &Estimate) -> Self {
        Self {
            time_s: e.time,
            velocity_m_s: e.velocity,
            load_n: e.load,
            friction_force_n: e.friction_force,
            contact_friction_force_n: e.contact_friction_force,
            cof: e.cof,
            h0_m: e.h0,
            h_min_m: e.h_min,
            hydrodynamic_force_n: e.hydrodynamic_force,
            asperity_force_n: e.asperity_force,
            asperity_load_share: e.asperity_load_share,
            residual: e.diagnostics.residual,
            iterations: e.diagnostics.iterations,
            substeps: e.diagnostics.substeps,
            status: status_code(e.status),
            regime: regime_code(e.regime),
        }
    }
}

const LIVE: u64 = 0x6672_6963_7469_6f6e; // "friction"
const FREED: u64 = 0x6672_6565_6420_2020; // "freed   "

/// A model: one solver per contact and the configuration they were built
/// from. Opaque to C.
pub struct FnModel {
    magic: u64,
    /// One per contact, in the configuration's order.
    solvers: Vec<Solver>,
    /// Each contact's name, joint, gain and own configuration.
    contacts: Vec<ResolvedContact>,
    config: Config,
    declared: Vec<Declared>,
    /// The last temperature set, °C (re-applied after a parameter change).
    temperature_c: Option<f64>,
}

impl FnModel {
    /// Each contact's liquid viscosity at `t` °C (where it follows it), or,
    /// changing nothing, why a contact's law refuses `t` (the envelope every
    /// entry point checks: [`friction_node::config::ViscosityLaw`]).
    fn apply_temperature(&mut self, t: f64) -> Result<(), String> {
        let laws = self.contacts.iter().map(|c| ViscosityLaw::of(&c.config));
        let several = self.contacts.len() > 1;
        let mut viscosities = [0.0; friction_node::config::MAX_CONTACTS];
        for (k, (law, c)) in laws.zip(&self.contacts).enumerate() {
            viscosities[k] = law.viscosity_at(t).map_err(|e| {
                if several {
                    format!("contact `{}`: {e}", c.name)
                } else {
                    e.to_string()
                }
            })?;
        }
        for ((s, c), mu) in self.solvers.iter_mut().zip(&self.contacts).zip(viscosities) {
            if ViscosityLaw::of(&c.config).follows_temperature() {
                s.set_liquid_viscosity(mu);
            }
        }
        Ok(())
    }
}

thread_local! {
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

fn fail(code: i32, message: impl Into<String>) -> i32 {
    let m = message.into();
    LAST_ERROR.with(|e| *e.borrow_mut() = m);
    code
}

/// Run `f`, turning a panic into `FN_ERROR_PANIC`.
fn guarded(f: impl FnOnce() -> i32) -> i32 {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|p| {
        let what = p
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown".into());
        fail(FN_ERROR_PANIC, format!("internal error (panic): {what}"))
    })
}

/// The model behind `h`, when it is one.
///
/// # Safety
/// `h` is null or a pointer this library returned (detected otherwise only
/// when the memory it points to does not hold a live model's marker).
unsafe fn model<'a>(h: *mut FnModel) -> Result<&'a mut FnModel, i32> {
    if h.is_null() || !(h as usize).is_multiple_of(std::mem::align_of::<FnModel>()) {
        return Err(fail(
            FN_ERROR_INVALID_HANDLE,
            "the model handle is null or misaligned",
        ));
    }
    // SAFETY: non-null and aligned; the caller promises it came from us.
    let m = unsafe { &mut *h };
    if m.magic != LIVE {
        return Err(fail(
            FN_ERROR_INVALID_HANDLE,
            if m.magic == FREED {
                "the model handle was already freed"
            } else {
                "the handle is not a friction-node model"
            },
        ));
    }
    Ok(m)
}

/// A `&str` from a C string argument.
///
/// # Safety
/// `s` is null or a NUL-terminated string.
unsafe fn text<'a>(s: *const c_char, what: &str) -> Result<&'a str, i32> {
    if s.is_null() {
        return Err(fail(FN_ERROR_NULL_ARGUMENT, format!("{what} is null")));
    }
    // SAFETY: the caller passes a NUL-terminated string.
    unsafe { CStr::from_ptr(s) }
        .to_str()
        .map_err(|e| fail(FN_ERROR_UTF8, format!("{what} is not UTF-8: {e}")))
}

fn build(config: Config, out: *mut *mut FnModel) -> i32 {
    let contacts = config.resolved_contacts();
    let mut solvers = Vec::with_capacity(contacts.len());
    for c in &contacts {
        match Solver::new(&c.config.model(), &c.config.solver_settings()) {
            Ok(mut s) => {
                s.initialize_steady(0.0, c.config.contact.load_n);
                solvers.push(s);
            }
            Err(e) => return fail(FN_ERROR_SETUP, format!("contact `{}`: {e}", c.name)),
        }
    }
    let m = Box::new(FnModel {
        magic: LIVE,
        solvers,
        contacts,
        declared: declare(&config),
        config,
        temperature_c: None,
    });
    // SAFETY: checked non-null by the callers.
    unsafe { *out = Box::into_raw(m) };
    FN_OK
}

fn config_error(e: friction_node::config::ConfigError) -> i32 {
    let code = match e {
        friction_node::config::ConfigError::Io { .. } => FN_ERROR_IO,
        _ => FN_ERROR_CONFIG,
    };
    fail(code, e.to_string())
}

/// Create a model from parameter-file text (the shapes `friction-node`
/// reads: `friction_node: ros__parameters: ...`, `/**: ...`, or an empty
/// string for the built-in defaults). The model starts in the steady state
/// at rest under `contact.load_n`. On success `*out` is the new model.
///
/// # Safety
/// `yaml` is a NUL-terminated string; `out` points to writable storage.
#[no_mangle]
pub unsafe extern "C" fn fn_model_new_from_yaml(
    yaml: *const c_char,
    out: *mut *mut FnModel,
) -> i32 {
    guarded(|| {
        if out.is_null() {
            return fail(FN_ERROR_NULL_ARGUMENT, "out is null");
        }
        // SAFETY: forwarded from the caller.
        let text = match unsafe { text(yaml, "yaml") } {
            Ok(t) => t,
            Err(c) => return c,
        };
        let config = if text.trim().is_empty() {
            Config::load(None, &[])
        } else {
            Config::from_yaml(text, &Origin::Text("passed to fn_model_new_from_yaml"), &[])
        };
        match config {
            Ok(c) => build(c, out),
            Err(e) => config_error(e),
        }
    })
}

/// Create a model from a parameter file (see `fn_model_new_from_yaml`).
///
/// # Safety
/// `path` is a NUL-terminated string; `out` points to writable storage.
#[no_mangle]
pub unsafe extern "C" fn fn_model_new_from_file(
    path: *const c_char,
    out: *mut *mut FnModel,
) -> i32 {
    guarded(|| {
        if out.is_null() {
            return fail(FN_ERROR_NULL_ARGUMENT, "out is null");
        }
        // SAFETY: forwarded from the caller.
        let path = match unsafe { text(path, "path") } {
            Ok(t) => t,
            Err(c) => return c,
        };
        match Config::load(Some(std::path::Path::new(path)), &[]) {
            Ok(c) => build(c, out),
            Err(e) => config_error(e),
        }
    })
}

/// Advance the model by `dt_s` with velocity `velocity_m_s` and normal load
/// `load_n`; write the estimate to `*out`. Does not allocate. `dt_s` equal
/// to the configured step (see `fn_model_dt`) continues BDF2; another
/// length in (0, 3600] s takes one backward-Euler step. Inputs outside the
/// configuration's envelope (`node.max_abs_velocity_m_s`,
/// `node.min_load_n`…`node.max_load_n`: the commands the node rejects) are
/// not errors: the estimate's status is `input_out_of_range` and it holds
/// the last good values.
///
/// # Safety
/// `model` is a handle from this library; `out` points to writable storage.
#[no_mangle]
pub unsafe extern "C" fn fn_model_step(
    model: *mut FnModel,
    velocity_m_s: f64,
    load_n: f64,
    dt_s: f64,
    out: *mut FnEstimate,
) -> i32 {
    guarded(|| {
        // SAFETY: forwarded from the caller.
        let m = match unsafe { self::model(model) } {
            Ok(m) => m,
            Err(c) => return c,
        };
        if out.is_null() {
            return fail(FN_ERROR_NULL_ARGUMENT, "out is null");
        }
        let [solver] = m.solvers.as_mut_slice() else {
            return fail(
                FN_ERROR_ARGUMENT,
                format!(
                    "the model has {} contacts: step them together with fn_model_step_contacts",
                    m.solvers.len()
                ),
            );
        };
        let e = step_one(solver, &m.contacts[0].config, velocity_m_s, load_n, dt_s);
        // SAFETY: checked non-null; the caller provides the storage.
        unsafe { *out = FnEstimate::from(&e) };
        FN_OK
    })
}

/// One contact's step of `dt_s` (BDF2 at the configured step, else
/// backward Euler); inputs outside the configuration's envelope
/// (`node.max_abs_velocity_m_s`, `node.min_load_n`…`node.max_load_n`, the
/// rule every entry point checks) are refused with the status
/// `input_out_of_range`, as the node rejects such commands.
fn step_one(s: &mut Solver, config: &Config, v: f64, load: f64, dt_s: f64) -> Estimate {
    let limits = friction_node::config::InputLimits::of(config);
    // Non-finite inputs go on to the solver, whose status names them.
    let finite = v.is_finite() && load.is_finite();
    if finite && (limits.check_velocity(v).is_err() || limits.check_load(load).is_err()) {
        return s.refuse_step();
    }
    s.step_by(v, load, dt_s)
}

/// Advance every contact by `dt_s`: contact i driven by its joint's
/// velocity `velocities[i]` (m/s for a linear joint, rad/s for a rotary
/// one: the contact slides at its `gain` × it) under `loads[i]` (N; `loads` null: each contact's
/// configured `contact.load_n`), in the configuration's contact order, which
/// is the order of its joints. Writes `count` estimates to `out` and, when
/// `efforts` is not null, each contact's feed-forward effort (its `gain` ×
/// `friction_force_n`: N for a linear joint, N·m for a rotary one) to
/// `efforts[i]`. `count` must equal `fn_model_contact_count`. Does not
/// allocate; the contacts are stepped one after the other on the calling
/// thread. Statuses are per estimate, as for `fn_model_step`.
///
/// # Safety
/// `model` is a handle from this library; `velocities` and `out` (and
/// `loads`, `efforts` when not null) point to `count` values.
#[no_mangle]
pub unsafe extern "C" fn fn_model_step_contacts(
    model: *mut FnModel,
    velocities: *const f64,
    loads: *const f64,
    count: u32,
    dt_s: f64,
    out: *mut FnEstimate,
    efforts: *mut f64,
) -> i32 {
    guarded(|| {
        // SAFETY: forwarded from the caller.
        let m = match unsafe { self::model(model) } {
            Ok(m) => m,
            Err(c) => return c,
        };
        if velocities.is_null() || out.is_null() {
            return fail(FN_ERROR_NULL_ARGUMENT, "velocities or out is null");
        }
        let n = m.solvers.len();
        if count as usize != n {
            return fail(
                FN_ERROR_ARGUMENT,
                format!("count is {count} but the model has {n} contacts"),
            );
        }
        // SAFETY: non-null; the caller provides `count` values each.
        let (v, out) = unsafe {
            (
                std::slice::from_raw_parts(velocities, n),
                std::slice::from_raw_parts_mut(out, n),
            )
        };
        let loads = (!loads.is_null()).then(|| {
            // SAFETY: non-null; `count` values.
            unsafe { std::slice::from_raw_parts(loads, n) }
        });
        for (i, (s, c)) in m.solvers.iter_mut().zip(&m.contacts).enumerate() {
            let load = loads.map_or(c.config.contact.load_n, |l| l[i]);
            let e = FnEstimate::from(&step_one(s, &c.config, c.gain * v[i], load, dt_s));
            out[i] = e;
            if !efforts.is_null() {
                // SAFETY: non-null; `count` values.
                unsafe { *efforts.add(i) = c.gain * e.friction_force_n };
            }
        }
        FN_OK
    })
}

/// The number of contacts of the model (1 for a configuration without
/// `contacts`; 0 for an invalid handle).
///
/// # Safety
/// `model` is a handle from this library.
#[no_mangle]
pub unsafe extern "C" fn fn_model_contact_count(model: *const FnModel) -> u32 {
    let r = catch_unwind(|| {
        // SAFETY: forwarded from the caller; only read.
        unsafe { self::model(model as *mut FnModel) }.map(|m| m.solvers.len() as u32)
    });
    match r {
        Ok(Ok(n)) => n,
        _ => 0,
    }
}

/// The index (in `fn_model_step_contacts`'s arrays) of the contact named
/// `name`, or of the contact on the joint named `name`, into `*out`.
///
/// # Safety
/// `model` is a handle from this library; `name` is a NUL-terminated
/// string; `out` points to writable storage.
#[no_mangle]
pub unsafe extern "C" fn fn_model_contact_index(
    model: *const FnModel,
    name: *const c_char,
    out: *mut u32,
) -> i32 {
    guarded(|| {
        // SAFETY: forwarded from the caller; only read.
        let m = match unsafe { self::model(model as *mut FnModel) } {
            Ok(m) => m,
            Err(c) => return c,
        };
        // SAFETY: forwarded from the caller.
        let name = match unsafe { text(name, "name") } {
            Ok(t) => t,
            Err(c) => return c,
        };
        if out.is_null() {
            return fail(FN_ERROR_NULL_ARGUMENT, "out is null");
        }
        match m
            .contacts
            .iter()
            .position(|c| c.name == name || (!c.joint.is_empty() && c.joint == name))
        {
            Some(i) => {
                // SAFETY: checked non-null.
                unsafe { *out = i as u32 };
                FN_OK
            }
            None => {
                let known: Vec<String> = m
                    .contacts
                    .iter()
                    .map(|c| format!("{} (joint `{}`)", c.name, c.joint))
                    .collect();
                fail(
                    FN_ERROR_ARGUMENT,
                    format!(
                        "no contact or joint named `{name}`; the contacts are {}",
                        known.join(", ")
                    ),
                )
            }
        }
    })
}

/// The configured step `solver.dt_s`, s (0 for an invalid handle).
///
/// # Safety
/// `model` is a handle from this library.
#[no_mangle]
pub unsafe extern "C" fn fn_model_dt(model: *const FnModel) -> f64 {
    let r = catch_unwind(|| {
        // SAFETY: forwarded from the caller; only read.
        unsafe { self::model(model as *mut FnModel) }.map(|m| m.solvers[0].settings().dt)
    });
    match r {
        Ok(Ok(dt)) => dt,
        _ => 0.0,
    }
}

/// Restart from the steady state at velocity `velocity_m_s` under `load_n`
/// (a new run: the squeeze-film history is forgotten). `load_n` = 0 takes
/// each contact's configured `contact.load_n`; with several contacts every
/// contact restarts.
///
/// # Safety
/// `model` is a handle from this library.
#[no_mangle]
pub unsafe extern "C" fn fn_model_reset(
    model: *mut FnModel,
    velocity_m_s: f64,
    load_n: f64,
) -> i32 {
    guarded(|| {
        // SAFETY: forwarded from the caller.
        let m = match unsafe { self::model(model) } {
            Ok(m) => m,
            Err(c) => return c,
        };
        if !(velocity_m_s.is_finite() && load_n.is_finite() && load_n >= 0.0) {
            return fail(
                FN_ERROR_ARGUMENT,
                format!("reset: velocity {velocity_m_s} m/s and load {load_n} N must be finite, the load positive (or 0: each contact's configured load)"),
            );
        }
        for (s, c) in m.solvers.iter_mut().zip(&m.contacts) {
            let load = if load_n > 0.0 {
                load_n
            } else {
                c.config.contact.load_n
            };
            s.initialize_steady(velocity_m_s, load);
        }
        FN_OK
    })
}

/// The lubricant's temperature, °C: with `lubricant.viscosity_model: vogel`
/// the liquid viscosity follows it from the next step on (no allocation);
/// with a constant viscosity it changes nothing.
///
/// # Safety
/// `model` is a handle from this library.
#[no_mangle]
pub unsafe extern "C" fn fn_model_set_temperature(model: *mut FnModel, temperature_c: f64) -> i32 {
    guarded(|| {
        // SAFETY: forwarded from the caller.
        let m = match unsafe { self::model(model) } {
            Ok(m) => m,
            Err(c) => return c,
        };
        if let Err(e) = m.apply_temperature(temperature_c) {
            return fail(FN_ERROR_ARGUMENT, e);
        }
        m.temperature_c = Some(temperature_c);
        FN_OK
    })
}

/// Change one parameter that may change while running (those `ros2 param`
/// can set on the node: load, mass, boundary friction, lubricant,
/// roughness, drivetrain...), `key` dotted (`lubricant.viscosity_pa_s`;
/// with several contacts `contacts.NAME.lubricant.viscosity_pa_s`),
/// `value` in YAML (`0.05`, `vogel`, `[1, 2]`). The film state is kept and
/// a temperature set before is re-applied.
/// Allocates (the model's tables are rebuilt): call it between steps, not
/// from the real-time loop. A refused change leaves the model unchanged and
/// the message names the key and value.
///
/// # Safety
/// `model` is a handle from this library; `key` and `value` are
/// NUL-terminated strings.
#[no_mangle]
pub unsafe extern "C" fn fn_model_set_parameter(
    model: *mut FnModel,
    key: *const c_char,
    value: *const c_char,
) -> i32 {
    guarded(|| {
        // SAFETY: forwarded from the caller.
        let m = match unsafe { self::model(model) } {
            Ok(m) => m,
            Err(c) => return c,
        };
        // SAFETY: forwarded from the caller.
        let (key, value) = match unsafe { (text(key, "key"), text(value, "value")) } {
            (Ok(k), Ok(v)) => (k, v),
            (Err(c), _) | (_, Err(c)) => return c,
        };
        let new = match set_from_text(&m.config, &m.declared, key, value) {
            Ok(c) => c,
            Err(e) => return fail(FN_ERROR_PARAMETER, e.to_string()),
        };
        let contacts = new.resolved_contacts();
        if let Some(t) = m.temperature_c {
            // The temperature set before must stay valid under the new law.
            for c in &contacts {
                if let Err(e) = ViscosityLaw::of(&c.config).viscosity_at(t) {
                    return fail(
                        FN_ERROR_PARAMETER,
                        format!(
                            "parameter `{key}`: the temperature set before no longer holds: {e}"
                        ),
                    );
                }
            }
        }
        let mut prepared = Vec::with_capacity(contacts.len());
        for (c, s) in contacts.iter().zip(&m.solvers) {
            let p = match Solver::prepare_model(&c.config.model(), &c.config.solver_settings()) {
                Ok(p) => p,
                Err(e) => return fail(FN_ERROR_PARAMETER, format!("parameter `{key}`: {e}")),
            };
            if !s.fits(&p) {
                return fail(
                    FN_ERROR_PARAMETER,
                    format!(
                        "parameter `{key}`: {}",
                        friction_node::physics::ModelMismatch
                    ),
                );
            }
            prepared.push(p);
        }
        // Every contact fits: all change together.
        for (s, p) in m.solvers.iter_mut().zip(prepared.iter_mut()) {
            let _ = s.swap_model(p);
        }
        m.config = new;
        m.contacts = contacts;
        if let Some(t) = m.temperature_c {
            // Checked above: every contact's law accepts it.
            let _ = m.apply_temperature(t);
        }
        FN_OK
    })
}

/// Free a model (null is ignored). The handle must not be used again; a
/// use that still finds the freed marker returns `FN_ERROR_INVALID_HANDLE`.
///
/// # Safety
/// `model` is null or a handle from this library, not yet freed.
#[no_mangle]
pub unsafe extern "C" fn fn_model_free(model: *mut FnModel) {
    let _ = catch_unwind(|| {
        // SAFETY: forwarded from the caller.
        if let Ok(m) = unsafe { self::model(model) } {
            m.magic = FREED;
            // SAFETY: a live model from Box::into_raw.
            drop(unsafe { Box::from_raw(model) });
        }
    });
}

/// Copy the calling thread's last error message into `buf` (at most
/// `len - 1` bytes and a NUL; truncated at a character boundary). Returns the
/// message's full length in bytes (0 when there was no error).
///
/// # Safety
/// `buf` is null (only the length is returned) or points to `len` bytes.
#[no_mangle]
pub unsafe extern "C" fn fn_last_error(buf: *mut c_char, len: usize) -> usize {
    catch_unwind(|| {
        LAST_ERROR.with(|e| {
            let e = e.borrow();
            if !buf.is_null() && len > 0 {
                let mut n = e.len().min(len - 1);
                while !e.is_char_boundary(n) {
                    n -= 1;
                }
                // SAFETY: the caller provides `len` bytes; n < len.
                unsafe {
                    std::ptr::copy_nonoverlapping(e.as_ptr(), buf as *mut u8, n);
                    *buf.add(n) = 0;
                }
            }
            e.len()
        })
    })
    .unwrap_or(0)
}

/// The name of an `FN_STATUS_*` code (`"converged"`, ...), a static string.
#[no_mangle]
pub extern "C" fn fn_status_name(status: u8) -> *const c_char {
    let s: &'static CStr = match status {
        FN_STATUS_CONVERGED => c"converged",
        FN_STATUS_MAX_ITERATIONS => c"max_iterations",
        FN_STATUS_NON_FINITE => c"non_finite",
        FN_STATUS_NON_FINITE_INPUT => c"non_finite_input",
        FN_STATUS_INPUT_OUT_OF_RANGE => c"input_out_of_range",
        _ => c"unknown",
    };
    s.as_ptr()
}
