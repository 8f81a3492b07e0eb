//! Time, from one seam: monotonic time for deadlines, wall time for stamps.
//!
//! Everything that needs time (the loop, the recorder, the benchmarks) takes
//! a [`Clock`]: [`SystemClock`] in production, [`SimClock`] in tests, where
//! sleeping returns at once and moves simulated time forward, so a test can
//! run the loop across a year of uptime in milliseconds and assert exact
//! step counts. All times are integer nanoseconds in `u64` (584 years).
//!
//! | quantity | clock | unit |
//! |---|---|---|
//! | deadlines, timeouts, durations | monotonic ([`Clock::now_ns`]), from an arbitrary origin | ns |
//! | message stamps, log times | wall ([`Clock::wall_ns`]), since the Unix epoch | ns |

use std::sync::atomic::{AtomicI64, AtomicU64, Ordering};
use std::time::{Duration, Instant};

/// A source of monotonic and wall time.
pub trait Clock: Send + Sync {
    /// Monotonic time, ns since the clock's origin; never goes backwards.
    fn now_ns(&self) -> u64;
    /// Return at monotonic time `deadline_ns` or later (at once if past).
    fn sleep_until_ns(&self, deadline_ns: u64);
    /// Return at monotonic time `deadline_ns` or later, busy-waiting where
    /// the clock can (a clock that others drive sleeps instead).
    fn spin_until_ns(&self, deadline_ns: u64) {
        self.sleep_until_ns(deadline_ns)
    }
    /// Wall-clock (ROS) time, ns since the Unix epoch. May jump (NTP).
    fn wall_ns(&self) -> u64;
}

/// The machine's clocks: `Instant` (CLOCK_MONOTONIC) and `SystemTime`.
#[derive(Debug, Clone, Copy)]
pub struct SystemClock {
    origin: Instant,
}

impl Default for SystemClock {
    fn default() -> Self {
        Self::new()
    }
}

impl SystemClock {
    /// The system's clocks (monotonic for deadlines, wall for stamps).
    pub fn new() -> Self {
        Self {
            origin: Instant::now(),
        }
    }
}

/// Wall-clock time now, ns since the Unix epoch (0 before 1970).
pub fn system_wall_ns() -> u64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| u64::try_from(d.as_nanos()).unwrap_or(u64::MAX))
}

impl Clock for SystemClock {
    fn now_ns(&self) -> u64 {
        u64::try_from(self.origin.elapsed().as_nanos()).unwrap_or(u64::MAX)
    }

    /// A kernel sleep to 100 µs before the deadline, then a spin: wake-ups
    /// within a microsecond or two on an idle core.
    fn sleep_until_ns(&self, deadline_ns: u64) {
        const SPIN_NS: u64 = 100_000;
        let now = self.now_ns();
        if deadline_ns <= now {
            return;
        }
        let left = deadline_ns - now;
        if left > SPIN_NS {
            std::thread::sleep(Duration::from_nanos(left - SPIN_NS));
        }
        while self.now_ns() < deadline_ns {
            std::hint::spin_loop();
        }
    }

    fn spin_until_ns(&self, deadline_ns: u64) {
        while self.now_ns() < deadline_ns {
            std::hint::spin_loop();
        }
    }

    fn wall_ns(&self) -> u64 {
        system_wall_ns()
    }
}

/// Time that an outside source drives: ROS 2 `/clock` (`use_sim_time`),
/// as simulators and bag playback publish it. Monotonic time is the time
/// since the first value received (it holds when the source goes back, as
/// a restarted playback does); wall time is the latest value; sleeping
/// waits until the source has passed the deadline, or the node is told to
/// stop. Before the first value, time stands at 0.
#[derive(Debug)]
pub struct ExternalClock {
    /// Latest value, ns since the epoch (0: none yet).
    latest: AtomicU64,
    /// First value received (0: none yet).
    origin: AtomicU64,
    /// Monotonic time handed out so far (never decreases).
    mono: AtomicU64,
    lock: std::sync::Mutex<()>,
    moved: std::sync::Condvar,
    stop: std::sync::Arc<std::sync::atomic::AtomicBool>,
}

impl ExternalClock {
    /// A clock that stops waiting when `stop` is set.
    pub fn new(stop: std::sync::Arc<std::sync::atomic::AtomicBool>) -> Self {
        Self {
            latest: AtomicU64::new(0),
            origin: AtomicU64::new(0),
            mono: AtomicU64::new(0),
            lock: std::sync::Mutex::new(()),
            moved: std::sync::Condvar::new(),
            stop,
        }
    }

    /// The source says it is `ns` (since the epoch) now.
    pub fn set(&self, ns: u64) {
        if ns == 0 {
            return;
        }
        let _ = self
            .origin
            .compare_exchange(0, ns, Ordering::SeqCst, Ordering::SeqCst);
        self.latest.store(ns, Ordering::SeqCst);
        let origin = self.origin.load(Ordering::SeqCst);
        self.mono
            .fetch_max(ns.saturating_sub(origin), Ordering::SeqCst);
        let _g = self.lock.lock().unwrap_or_else(|p| p.into_inner());
        self.moved.notify_all();
    }

    /// Whether a value has been received.
    pub fn started(&self) -> bool {
        self.origin.load(Ordering::SeqCst) != 0
    }
}

impl Clock for ExternalClock {
    fn now_ns(&self) -> u64 {
        self.mono.load(Ordering::SeqCst)
    }

    fn sleep_until_ns(&self, deadline_ns: u64) {
        let mut g = self.lock.lock().unwrap_or_else(|p| p.into_inner());
        while self.now_ns() < deadline_ns && !self.stop.load(Ordering::Relaxed) {
            // Woken by every new value; the timeout only re-checks `stop`.
            g = self
                .moved
                .wait_timeout(g, Duration::from_millis(50))
                .map(|(g, _)| g)
                .unwrap_or_else(|p| p.into_inner().0);
        }
    }

    fn wall_ns(&self) -> u64 {
        self.latest.load(Ordering::SeqCst)
    }
}

/// `20261123T131500Z` for a wall time in ns (UTC, to the second).
pub fn utc_stamp(wall_ns: u64) -> String {
    let secs = wall_ns / 1_000_000_000;
    let (d, s) = (secs / 86_400, secs % 86_400);
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = d as i64 + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + (month <= 2) as i64;
    format!(
        "{year:04}{month:02}{day:02}T{:02}{:02}{:02}Z",
        s / 3600,
        (s % 3600) / 60,
        s % 60
    )
}

/// A clock that tests drive: monotonic time moves only when a sleep or
/// [`SimClock::advance`] moves it; the wall clock follows it at a fixed
/// offset, which [`SimClock::jump_wall`] changes (an NTP step).
#[derive(Debug, Default)]
pub struct SimClock {
    mono: AtomicU64,
    wall_offset: AtomicI64,
}

impl SimClock {
    /// Monotonic time 0, wall time `wall_start_ns`.
    pub fn new(wall_start_ns: u64) -> Self {
        Self {
            mono: AtomicU64::new(0),
            wall_offset: AtomicI64::new(i64::try_from(wall_start_ns).unwrap_or(i64::MAX)),
        }
    }

    /// Start at monotonic time `mono_ns` (e.g. just before step 2^32).
    pub fn starting_at(mono_ns: u64, wall_start_ns: u64) -> Self {
        let c = Self::new(wall_start_ns);
        c.mono.store(mono_ns, Ordering::SeqCst);
        c
    }

    /// Move monotonic (and wall) time forward.
    pub fn advance(&self, ns: u64) {
        self.mono.fetch_add(ns, Ordering::SeqCst);
    }

    /// Step the wall clock by `delta_ns` (negative: set back), as NTP does.
    pub fn jump_wall(&self, delta_ns: i64) {
        self.wall_offset.fetch_add(delta_ns, Ordering::SeqCst);
    }
}

impl Clock for SimClock {
    fn now_ns(&self) -> u64 {
        self.mono.load(Ordering::SeqCst)
    }

    fn sleep_until_ns(&self, deadline_ns: u64) {
        self.mono.fetch_max(deadline_ns, Ordering::SeqCst);
    }

    fn wall_ns(&self) -> u64 {
        let mono = self.mono.load(Ordering::SeqCst) as i128;
        let w = mono + self.wall_offset.load(Ordering::SeqCst) as i128;
        w.clamp(0, u64::MAX as i128) as u64
    }
}

/// Maps monotonic instants to wall-clock stamps that never go backwards.
///
/// A stamp is the wall time of a monotonic instant, `wall_anchor +
/// (mono − mono_anchor)`: deadlines k·Δt apart give stamps exactly k·Δt
/// apart. When the wall clock steps (NTP) by more than [`Self::JUMP_NS`]
/// against the monotonic clock, the jump is counted and the anchor moves to
/// the new wall time; stamps stay strictly increasing (after a backward step
/// they advance 1 ns per stamp until the wall clock has caught up).
#[derive(Debug, Clone, Copy)]
pub struct WallStamps {
    mono_anchor: u64,
    wall_anchor: u64,
    last: Option<u64>,
    /// Wall-clock steps seen.
    pub jumps: u64,
}

impl WallStamps {
    /// A difference between wall and monotonic time larger than this is a
    /// step of the wall clock, not drift.
    pub const JUMP_NS: u64 = 1_000_000;

    /// Stamps that start at `clock`'s wall time now.
    pub fn new(clock: &dyn Clock) -> Self {
        let mono = clock.now_ns();
        Self {
            mono_anchor: mono,
            wall_anchor: clock.wall_ns(),
            last: None,
            jumps: 0,
        }
    }

    fn mapped(&self, mono_ns: u64) -> u64 {
        if mono_ns >= self.mono_anchor {
            self.wall_anchor.saturating_add(mono_ns - self.mono_anchor)
        } else {
            self.wall_anchor.saturating_sub(self.mono_anchor - mono_ns)
        }
    }

    /// The wall clock read between two monotonic reads at most this far
    /// apart is a clean sample; a thread preempted between the reads would
    /// otherwise see a "jump" of its own making.
    pub const READ_WINDOW_NS: u64 = 20_000;

    /// Compare the wall clock with the mapping now; re-anchor on a step.
    /// Returns true when a jump was detected. The wall clock is read between
    /// two monotonic reads and compared with their midpoint; a sample whose
    /// reads lie further apart than [`Self::READ_WINDOW_NS`] (the thread was
    /// preempted) is retried, and after three such samples no decision is
    /// taken until the next check.
    pub fn check(&mut self, clock: &dyn Clock) -> bool {
        let mut sample = None;
        for _ in 0..3 {
            let m1 = clock.now_ns();
            let wall = clock.wall_ns();
            let m2 = clock.now_ns();
            if m2.saturating_sub(m1) <= Self::READ_WINDOW_NS {
                sample = Some((m1 + (m2.saturating_sub(m1)) / 2, wall));
                break;
            }
        }
        let Some((mono, wall)) = sample else {
            return false;
        };
        if wall.abs_diff(self.mapped(mono)) > Self::JUMP_NS {
            self.jumps += 1;
            self.mono_anchor = mono;
            self.wall_anchor = wall;
            return true;
        }
        false
    }

    /// The stamp of monotonic instant `mono_ns`, strictly after the last one.
    pub fn stamp(&mut self, mono_ns: u64) -> u64 {
        let s = self.mapped(mono_ns);
        let s = match self.last {
            Some(l) if s <= l => l.saturating_add(1),
            _ => s,
        };
        self.last = Some(s);
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_system_spin_returns_at_or_after_its_deadline_and_a_simulated_one_moves_time() {
        let c = SystemClock::new();
        let due = c.now_ns() + 200_000;
        c.spin_until_ns(due);
        assert!(c.now_ns() >= due);
        // A driven clock cannot be spun on: the default waits like a sleep.
        let s = SimClock::new(0);
        s.spin_until_ns(3_000_000);
        assert_eq!(s.now_ns(), 3_000_000);
    }

    #[test]
    fn a_simulated_sleep_moves_time_to_the_deadline_at_once() {
        let c = SimClock::new(1_000);
        c.sleep_until_ns(5_000_000);
        assert_eq!(c.now_ns(), 5_000_000);
        c.sleep_until_ns(1_000); // in the past: no change
        assert_eq!(c.now_ns(), 5_000_000);
        assert_eq!(c.wall_ns(), 5_001_000);
        c.jump_wall(-2_000);
        assert_eq!(c.wall_ns(), 4_999_000);
    }

    #[test]
    fn stamps_follow_deadlines_exactly_and_never_go_back_when_the_wall_clock_does() {
        let c = SimClock::new(1_700_000_000_000_000_000);
        let mut w = WallStamps::new(&c);
        let a = w.stamp(1_000_000);
        let b = w.stamp(2_000_000);
        assert_eq!(b - a, 1_000_000);
        c.sleep_until_ns(2_000_000);
        c.jump_wall(-10_000_000_000); // NTP sets the clock back 10 s
        assert!(w.check(&c));
        assert_eq!(w.jumps, 1);
        let s = w.stamp(3_000_000);
        assert!(s > b, "monotonic stamps");
        assert_eq!(s, b + 1);
        assert!(!w.check(&c), "one jump, counted once");
        c.jump_wall(5_000_000_000);
        assert!(w.check(&c));
        assert_eq!(w.jumps, 2);
    }

    /// A thread preempted between its clock reads: the wall clock is read
    /// `stall_ns` after the monotonic read before it, the first `stalls`
    /// times.
    struct Preempted {
        mono: AtomicU64,
        wall0: u64,
        stall_ns: u64,
        stalls: AtomicU64,
    }

    impl Clock for Preempted {
        fn now_ns(&self) -> u64 {
            self.mono.load(Ordering::Relaxed)
        }
        fn sleep_until_ns(&self, deadline_ns: u64) {
            self.mono.fetch_max(deadline_ns, Ordering::Relaxed);
        }
        fn wall_ns(&self) -> u64 {
            if self.stalls.load(Ordering::Relaxed) > 0 {
                self.stalls.fetch_sub(1, Ordering::Relaxed);
                self.mono.fetch_add(self.stall_ns, Ordering::Relaxed);
            }
            self.wall0 + self.mono.load(Ordering::Relaxed)
        }
    }

    #[test]
    fn a_thread_preempted_between_its_clock_reads_sees_no_jump() {
        let c = Preempted {
            mono: AtomicU64::new(0),
            wall0: 1_700_000_000_000_000_000,
            stall_ns: 3_000_000,
            stalls: AtomicU64::new(0),
        };
        let mut w = WallStamps::new(&c);
        // Two samples spoiled by 3 ms stalls, the third clean.
        c.stalls.store(2, Ordering::Relaxed);
        assert!(!w.check(&c));
        // Every sample spoiled: no decision, no jump.
        c.stalls.store(3, Ordering::Relaxed);
        assert!(!w.check(&c));
        assert_eq!(w.jumps, 0);
        let s = w.stamp(c.now_ns());
        assert_eq!(s, c.wall0 + c.now_ns(), "the mapping was not moved");
    }

    #[test]
    fn an_external_clock_follows_its_source_and_never_goes_back() {
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        let c = std::sync::Arc::new(ExternalClock::new(stop.clone()));
        assert_eq!((c.now_ns(), c.started()), (0, false));
        c.set(1_000_000_000_000);
        assert_eq!(c.now_ns(), 0, "time starts at the first value");
        assert_eq!(c.wall_ns(), 1_000_000_000_000);
        c.set(1_000_005_000_000);
        assert_eq!(c.now_ns(), 5_000_000);
        c.set(1_000_001_000_000); // playback restarted
        assert_eq!(c.now_ns(), 5_000_000, "monotonic time holds");
        assert_eq!(c.wall_ns(), 1_000_001_000_000, "stamps follow the source");
        // A sleeper wakes when the source passes its deadline.
        let c2 = c.clone();
        let t = std::thread::spawn(move || {
            c2.sleep_until_ns(7_000_000);
            c2.now_ns()
        });
        c.set(1_000_006_000_000);
        c.set(1_000_008_000_000);
        assert!(t.join().unwrap() >= 7_000_000, "not before the deadline");
        // And returns when told to stop, however far the deadline.
        let c3 = c.clone();
        let t = std::thread::spawn(move || c3.sleep_until_ns(u64::MAX));
        stop.store(true, Ordering::Relaxed);
        t.join().unwrap();
    }

    #[test]
    fn utc_stamps_are_civil_dates() {
        assert_eq!(utc_stamp(0), "19700101T000000Z");
        assert_eq!(utc_stamp(1_763_900_000_000_000_000), "20251123T121320Z");
        assert_eq!(utc_stamp(951_782_400_000_000_000), "20000229T000000Z");
    }

    #[test]
    fn the_system_clock_is_monotonic_and_sleeps_until_its_deadline() {
        let c = SystemClock::new();
        let t0 = c.now_ns();
        c.sleep_until_ns(t0 + 200_000);
        assert!(c.now_ns() >= t0 + 200_000);
        assert!(c.wall_ns() > 1_600_000_000_000_000_000);
    }
}
