//! The exported functions: create a model, step it (one contact or
//! several), ask it, reset it, set its temperature or a parameter, free
//! it, and read the last error or a status's name.

use crate::codes::*;
use crate::handle::*;
use friction_node::config::parameters::set_from_text;
use friction_node::config::{Config, Origin, ViscosityLaw};
use friction_node::physics::Solver;
use friction_node::range_watch::RangeWatch;
use std::ffi::{c_char, CStr};
use std::panic::catch_unwind;

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
        let t = m.temperature_c;
        let e = step_one(
            solver,
            &m.contacts[0].config,
            &m.watches[0],
            t,
            velocity_m_s,
            load_n,
            dt_s,
        );
        // SAFETY: checked non-null; the caller provides the storage.
        unsafe { *out = e };
        FN_OK
    })
}

/// One contact's step of `dt_s` (BDF2 at the configured step, else
/// backward Euler); inputs outside the configuration's envelope
/// (`node.max_abs_velocity_m_s`, `node.min_load_n`…`node.max_load_n`, the
/// rule every entry point checks) are refused with the status
/// `input_out_of_range`, as the node rejects such commands.
/// Then the contact's calibrated range judges the input (`temperature_c`:
/// the last set, else the configuration's reference), and the estimate says
/// where it lay, with the friction `node.outside_envelope` gives.
fn step_one(
    s: &mut Solver,
    config: &Config,
    watch: &RangeWatch,
    temperature_c: Option<f64>,
    v: f64,
    load: f64,
    dt_s: f64,
) -> FnEstimate {
    let limits = friction_node::config::InputLimits::of(config);
    // Non-finite inputs go on to the solver, whose status names them.
    let finite = v.is_finite() && load.is_finite();
    if finite && (limits.check_velocity(v).is_err() || limits.check_load(load).is_err()) {
        return FnEstimate::from(&s.refuse_step());
    }
    let t = temperature_c.unwrap_or(config.lubricant.reference_temperature_c);
    let w = watch.watch(v, load, t);
    let e = s.step_by(w.velocity_m_s, w.load_n, dt_s);
    FnEstimate::watched(&e, watch, &w)
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
        let t = m.temperature_c;
        for (i, (s, c)) in m.solvers.iter_mut().zip(&m.contacts).enumerate() {
            let load = loads.map_or(c.config.contact.load_n, |l| l[i]);
            let w = &m.watches[i];
            let e = step_one(s, &c.config, w, t, c.gain * v[i], load, dt_s);
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
        m.watches = crate::handle::watches(&new, &contacts);
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
