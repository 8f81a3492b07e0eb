//! An empty 1 kHz loop: how late this machine wakes a sleeping thread.
//!
//! A loop's deadline misses mean something only beside this baseline, run
//! in the same minute on the same machine: it sleeps to absolute deadlines
//! t0 + k·1 ms on the monotonic clock (timer slack 1 ns, as the node asks
//! for) and does nothing else, so every miss it counts is the machine's
//! (the hypervisor, other tenants, power management), not the model's.
//!
//! ```sh
//! cargo run --release --example timer_baseline -- 30      # 30 s (default)
//! ```
//!
//! Prints one line: the periods, how many woke more than 100 µs late, how
//! many more than one period late (a miss), and the worst lateness.

#[cfg(target_os = "linux")]
fn main() {
    let seconds: u64 = match std::env::args().nth(1).map(|a| a.parse::<u64>()) {
        None => 30,
        Some(Ok(s)) if (1..=86_400).contains(&s) => s,
        Some(_) => {
            eprintln!("usage: timer_baseline [SECONDS in 1..=86400] (default 30)");
            std::process::exit(2);
        }
    };
    let r = run(seconds);
    println!(
        "{} periods: woken >100 us late {} ({:.1} %), >1 ms late (a miss) {} ({:.2} %), worst {:.1} ms",
        r.periods,
        r.late_100us,
        100.0 * r.late_100us as f64 / r.periods as f64,
        r.missed,
        100.0 * r.missed as f64 / r.periods as f64,
        r.worst_ns as f64 / 1e6
    );
}

#[cfg(not(target_os = "linux"))]
fn main() {
    eprintln!("timer_baseline needs Linux (clock_nanosleep with TIMER_ABSTIME)");
    std::process::exit(2);
}

/// What the empty loop saw.
#[cfg(target_os = "linux")]
struct Lateness {
    periods: u64,
    late_100us: u64,
    missed: u64,
    worst_ns: u64,
}

/// The monotonic clock, ns.
#[cfg(target_os = "linux")]
fn now_ns() -> u64 {
    let mut t = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: clock_gettime writes into the timespec we own.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut t) };
    u64::try_from(t.tv_sec).unwrap_or(0) * 1_000_000_000 + u64::try_from(t.tv_nsec).unwrap_or(0)
}

/// `seconds` of 1 ms periods against absolute deadlines.
#[cfg(target_os = "linux")]
fn run(seconds: u64) -> Lateness {
    const PERIOD_NS: u64 = 1_000_000;
    // SAFETY: prctl(PR_SET_TIMERSLACK) only changes this thread's timer slack.
    unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, 1 as libc::c_ulong) };
    let mut r = Lateness {
        periods: 0,
        late_100us: 0,
        missed: 0,
        worst_ns: 0,
    };
    let mut deadline = now_ns();
    for _ in 0..seconds * 1000 {
        deadline += PERIOD_NS;
        let at = libc::timespec {
            tv_sec: libc::time_t::try_from(deadline / 1_000_000_000).unwrap_or(0),
            tv_nsec: libc::c_long::try_from(deadline % 1_000_000_000).unwrap_or(0),
        };
        // SAFETY: sleeping to an absolute time given by a timespec we own.
        unsafe {
            libc::clock_nanosleep(
                libc::CLOCK_MONOTONIC,
                libc::TIMER_ABSTIME,
                &at,
                std::ptr::null_mut(),
            )
        };
        let late = now_ns().saturating_sub(deadline);
        r.worst_ns = r.worst_ns.max(late);
        r.late_100us += u64::from(late > 100_000);
        r.missed += u64::from(late > PERIOD_NS);
        r.periods += 1;
    }
    r
}
