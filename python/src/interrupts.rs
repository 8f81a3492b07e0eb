//! Ctrl-C during long calls. Python runs signal handlers only on the main
//! thread with the GIL, so a call that released it for seconds would see
//! Ctrl-C only when it returns. [`interruptible`] runs the work on a scoped
//! thread and checks Python's signals every 50 ms on the calling thread; a
//! `KeyboardInterrupt` requests the library's stop ([`Stop`]), waits for
//! the work to wind down (its temporary outputs removed) and is raised.

use friction_node::interrupt::Stop;
use pyo3::prelude::*;
use std::time::Duration;

/// Run `work` with the GIL released, interruptible by Ctrl-C.
pub fn interruptible<R: Send>(py: Python<'_>, work: impl FnOnce(&Stop) -> R + Send) -> PyResult<R> {
    let stop = Stop::new();
    let done = (std::sync::Mutex::new(false), std::sync::Condvar::new());
    std::thread::scope(|scope| {
        let worker_stop = stop.clone();
        let done_ref = &done;
        let handle = scope.spawn(move || {
            let r = work(&worker_stop);
            *done_ref.0.lock().unwrap_or_else(|p| p.into_inner()) = true;
            done_ref.1.notify_all();
            r
        });
        loop {
            let finished = py.detach(|| {
                let g = done.0.lock().unwrap_or_else(|p| p.into_inner());
                let (g, _) = done
                    .1
                    .wait_timeout_while(g, Duration::from_millis(50), |d| !*d)
                    .unwrap_or_else(|p| p.into_inner());
                *g
            });
            if finished {
                break;
            }
            if let Err(e) = py.check_signals() {
                stop.request(2);
                // The work stops at its next check; wait for it (its
                // outputs' temporary files are removed as it unwinds).
                let _ = py.detach(|| handle.join());
                return Err(e);
            }
        }
        match handle.join() {
            Ok(r) => Ok(r),
            Err(p) => std::panic::resume_unwind(p),
        }
    })
}
