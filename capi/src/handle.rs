//! The `FnModel` handle behind the C API: built from a configuration (one
//! solver per contact), checked on every call (null, misaligned, freed or
//! foreign), the calling thread's last error, and the guard that turns a
//! panic into `FN_ERROR_PANIC`.

use crate::codes::*;
use friction_node::config::parameters::{declare, Declared};
use friction_node::config::{Config, ResolvedContact, ViscosityLaw};
use friction_node::physics::Solver;
use friction_node::range_watch::RangeWatch;
use std::cell::RefCell;
use std::ffi::{c_char, CStr};
use std::panic::{catch_unwind, AssertUnwindSafe};

pub(crate) const LIVE: u64 = 0x6672_6963_7469_6f6e; // "friction"
pub(crate) const FREED: u64 = 0x6672_6565_6420_2020; // "freed   "

/// A model: one solver per contact and the configuration they were built
/// from. Opaque to C.
pub struct FnModel {
    pub(crate) magic: u64,
    /// One per contact, in the configuration's order.
    pub(crate) solvers: Vec<Solver>,
    /// Each contact's name, joint, gain and own configuration.
    pub(crate) contacts: Vec<ResolvedContact>,
    pub(crate) config: Config,
    pub(crate) declared: Vec<Declared>,
    /// The last temperature set, °C (re-applied after a parameter change).
    pub(crate) temperature_c: Option<f64>,
    /// Each contact's calibrated-range watch, in the contacts' order.
    pub(crate) watches: Vec<RangeWatch>,
}

/// Each contact's watch of its calibrated range under `config`'s
/// `node.outside_envelope`.
pub(crate) fn watches(config: &Config, contacts: &[ResolvedContact]) -> Vec<RangeWatch> {
    contacts
        .iter()
        .map(|c| RangeWatch::of_contact(c, config.node.outside_envelope))
        .collect()
}

impl FnModel {
    /// Each contact's liquid viscosity at `t` °C (where it follows it), or,
    /// changing nothing, why a contact's law refuses `t` (the envelope every
    /// entry point checks: [`friction_node::config::ViscosityLaw`]).
    pub(crate) fn apply_temperature(&mut self, t: f64) -> Result<(), String> {
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
        for (k, ((s, c), mu)) in self
            .solvers
            .iter_mut()
            .zip(&self.contacts)
            .zip(viscosities)
            .enumerate()
        {
            let law = ViscosityLaw::of(&c.config);
            if law.follows_temperature() {
                // Under `node.outside_envelope: hold`, at the calibrated range's edge.
                let held = law.viscosity_at(self.watches[k].temperature_c(t));
                s.set_liquid_viscosity(held.unwrap_or(mu));
            }
        }
        Ok(())
    }
}

thread_local! {
    pub(crate) static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

pub(crate) fn fail(code: i32, message: impl Into<String>) -> i32 {
    let m = message.into();
    LAST_ERROR.with(|e| *e.borrow_mut() = m);
    code
}

/// Run `f`, turning a panic into `FN_ERROR_PANIC`.
pub(crate) fn guarded(f: impl FnOnce() -> i32) -> i32 {
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
pub(crate) unsafe fn model<'a>(h: *mut FnModel) -> Result<&'a mut FnModel, i32> {
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
pub(crate) unsafe fn text<'a>(s: *const c_char, what: &str) -> Result<&'a str, i32> {
    if s.is_null() {
        return Err(fail(FN_ERROR_NULL_ARGUMENT, format!("{what} is null")));
    }
    // SAFETY: the caller passes a NUL-terminated string.
    unsafe { CStr::from_ptr(s) }
        .to_str()
        .map_err(|e| fail(FN_ERROR_UTF8, format!("{what} is not UTF-8: {e}")))
}

pub(crate) fn build(config: Config, out: *mut *mut FnModel) -> i32 {
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
        watches: watches(&config, &contacts),
        contacts,
        declared: declare(&config),
        config,
        temperature_c: None,
    });
    // SAFETY: checked non-null by the callers.
    unsafe { *out = Box::into_raw(m) };
    FN_OK
}

pub(crate) fn config_error(e: friction_node::config::ConfigError) -> i32 {
    let code = match e {
        friction_node::config::ConfigError::Io { .. } => FN_ERROR_IO,
        _ => FN_ERROR_CONFIG,
    };
    fail(code, e.to_string())
}
