//! Real-time settings of the loop's thread (when configured and permitted):
//! SCHED_FIFO, mlockall and CPU pinning, with a warning when not permitted.

use crate::config::RealtimeConfig;

/// Apply the real-time settings to the calling thread. Returns what was
/// applied and warnings for what could not be (never fails).
pub fn apply(cfg: &RealtimeConfig) -> (Vec<String>, Vec<String>) {
    let (mut applied, mut warnings) = (Vec::new(), Vec::new());
    // Timer slack 1 ns: sleeps wake on time (default slack is 50 µs).
    // SAFETY: prctl with PR_SET_TIMERSLACK and an integer argument has no memory effects.
    if unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, 1 as libc::c_ulong, 0, 0, 0) } == 0 {
        applied.push("timer slack 1 ns".to_string());
    }
    if cfg.lock_memory {
        // SAFETY: mlockall takes flags only.
        if unsafe { libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE) } == 0 {
            applied.push("memory locked (mlockall)".into());
        } else {
            warnings.push(format!(
                "node.realtime.lock_memory: mlockall failed ({}); needs CAP_IPC_LOCK or a large enough RLIMIT_MEMLOCK",
                std::io::Error::last_os_error()
            ));
        }
    }
    if cfg.cpu >= 0 {
        // SAFETY: a zeroed cpu_set_t is valid; CPU_SET writes inside it.
        let ok = unsafe {
            let mut set: libc::cpu_set_t = std::mem::zeroed();
            libc::CPU_SET(cfg.cpu as usize, &mut set);
            libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set) == 0
        };
        if ok {
            applied.push(format!("pinned to CPU {}", cfg.cpu));
        } else {
            warnings.push(format!(
                "node.realtime.cpu = {}: sched_setaffinity failed ({})",
                cfg.cpu,
                std::io::Error::last_os_error()
            ));
        }
    }
    if cfg.fifo {
        let p = libc::sched_param {
            sched_priority: cfg.priority,
        };
        // SAFETY: sched_setscheduler reads the param struct only.
        if unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &p) } == 0 {
            applied.push(format!("SCHED_FIFO priority {}", cfg.priority));
        } else {
            warnings.push(format!(
                "node.realtime.fifo: SCHED_FIFO priority {} not permitted ({}); needs CAP_SYS_NICE or an rtprio limit; running with normal scheduling",
                cfg.priority,
                std::io::Error::last_os_error()
            ));
        }
    }
    (applied, warnings)
}

/// Resident set size of this process, bytes (Linux; None elsewhere).
pub fn resident_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmRSS:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Peak resident set size of this process, bytes.
pub fn peak_resident_bytes() -> Option<u64> {
    let s = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = s.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}
