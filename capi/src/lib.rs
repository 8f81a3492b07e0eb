//! In-process C API of the friction-node model, for code that runs the
//! model inside its own control loop (a ros2_control controller's
//! `update()`, a hardware plugin's `write()`): no process, no topics, no
//! copies. The header `include/friction_node.h` is generated from this
//! crate by cbindgen and checked to be current by `tests/header.rs`.
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
//! | what | function | allocates | may be called from the control loop |
//! |---|---|---|---|
//! | create | `fn_model_new_from_yaml`, `fn_model_new_from_file` | yes (the solver's buffers) | no: at configure time |
//! | step, ask | `fn_model_step`, `fn_model_step_contacts`, `fn_model_set_temperature`, `fn_model_dt`, `fn_model_contact_count`, `fn_model_contact_index` | **no** | yes |
//! | reset | `fn_model_reset` | no | yes (it solves a steady state: slower than a step) |
//! | set | `fn_model_set_parameter` | yes (rebuilds the model's tables) | no: from a non-real-time thread, between steps |
//! | free, errors | `fn_model_free`, `fn_last_error`, `fn_status_name` | frees / no / no | — |
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

//!
//! | file | job |
//! |---|---|
//! | `codes.rs` | the `FN_*` return codes, status and regime codes, the `FnEstimate` struct |
//! | `handle.rs` | the `FnModel` handle: building it, checking it, the last error, the panic guard |
//! | `calls.rs` | the exported functions: create, step, query, reset, set, free, errors |

mod calls;
mod codes;
mod handle;

pub use calls::*;
pub use codes::*;
pub use handle::FnModel;
