//! The demo and soak driver: a peer on the node's own topics commanding a
//! velocity profile, in real time (timer mode) or command by command
//! (lockstep).

use crate::config::{OutputPlan, StepMode};
use crate::msgs::{Command, CommandKind};
use crate::transport::{self, BackendSpec, PeerPort};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// What the demo driver did.
#[derive(Debug, Clone, Default)]
pub struct DemoReport {
    /// Velocity commands published.
    pub commands_sent: u64,
    /// Estimates received back (lockstep waits for each).
    pub estimates_received: u64,
    /// Why the driver stopped early, if it did.
    pub error: Option<String>,
}

/// What the driver commands.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum DemoMotion {
    /// The paper's reciprocating case: v = V1 sin(2π f t), V1 = 1 m/s, f = 1 Hz.
    #[default]
    Paper,
    /// A reproducible random motion (seeded): a new target velocity in
    /// [-1.5, 1.5] m/s every 0.2–3 s, followed with a 0.15 s lag, so that
    /// reversals, dwells and speed changes of every size occur.
    Random {
        /// The random generator's seed (the same seed, the same motion).
        seed: u64,
    },
}

impl DemoMotion {
    fn start(self) -> ProfileState {
        ProfileState {
            motion: self,
            rng: match self {
                DemoMotion::Random { seed } => seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1,
                DemoMotion::Paper => 1,
            },
            v: 0.0,
            target: 0.0,
            next_change: 0.0,
        }
    }
}

/// A motion being played.
struct ProfileState {
    motion: DemoMotion,
    rng: u64,
    v: f64,
    target: f64,
    next_change: f64,
}

impl ProfileState {
    /// xorshift64*: uniform in [0, 1).
    fn uniform(&mut self) -> f64 {
        self.rng ^= self.rng >> 12;
        self.rng ^= self.rng << 25;
        self.rng ^= self.rng >> 27;
        (self.rng.wrapping_mul(0x2545_F491_4F6C_DD1D) >> 11) as f64 / (1u64 << 53) as f64
    }

    /// The velocity at time `t` (called once per step of `dt`).
    fn at(&mut self, t: f64, dt: f64) -> f64 {
        match self.motion {
            DemoMotion::Paper => (2.0 * std::f64::consts::PI * t).sin(),
            DemoMotion::Random { .. } => {
                if t >= self.next_change {
                    self.target = 3.0 * self.uniform() - 1.5;
                    self.next_change = t + 0.2 + 2.8 * self.uniform();
                }
                self.v += (self.target - self.v) * (dt / 0.15).min(1.0);
                self.v
            }
        }
    }
}

/// What the demo drives: the loop's mode and step, for how long, the
/// velocity profile and, with several contacts, the joints (each gets the
/// profile's velocity, in one JointState per step).
#[derive(Debug, Clone)]
pub struct DemoPlan {
    /// Timer or lockstep, as the node runs.
    pub mode: StepMode,
    /// The node's step, s (one command per step).
    pub dt_s: f64,
    /// How long to drive, s.
    pub seconds: f64,
    /// The velocity profile.
    pub motion: DemoMotion,
    /// The configuration's output plan: one contact driven by velocity
    /// commands, or joints driven by JointStates.
    pub output: OutputPlan,
}

/// Wait up to `timeout` for the efforts of a lockstep step.
fn efforts_timeout(peer: &mut dyn transport::PeerPort, timeout: Duration) -> bool {
    let until = Instant::now() + timeout;
    while Instant::now() < until {
        match peer.try_recv_efforts() {
            Ok(Some(_)) => return true,
            Ok(None) => std::thread::sleep(Duration::from_micros(50)),
            Err(_) => return false,
        }
    }
    false
}

/// Drive the node over `spec`'s topics as `plan` says until done or `stop`; `ready` says when its
/// publishers matched (or why not).
pub fn drive(
    spec: BackendSpec,
    plan: DemoPlan,
    ready: std::sync::mpsc::Sender<Result<(), String>>,
    stop: Arc<AtomicBool>,
) -> DemoReport {
    let DemoPlan {
        mode,
        dt_s: dt,
        seconds,
        motion,
        output,
    } = plan;
    let mut report = DemoReport::default();
    let opened = spec
        .open_peer()
        .and_then(|mut p| transport::wait_matched(p.as_mut(), Duration::from_secs(20)).map(|()| p));
    let mut peer = match opened {
        Ok(p) => p,
        Err(e) => {
            let _ = ready.send(Err(e.to_string()));
            report.error = Some(e.to_string());
            return report;
        }
    };
    let _ = ready.send(Ok(()));
    let mut velocity = motion.start();
    let steps = (seconds / dt).round() as u64;
    let start = Instant::now();
    let t0 = crate::clock::system_wall_ns();
    for k in 1..=steps {
        if stop.load(Ordering::Relaxed) {
            break;
        }
        let t = k as f64 * dt;
        if mode == StepMode::Timer {
            // A plain sleep: the driver must not compete with the loop's spin.
            let due = start + Duration::from_secs_f64(t - dt);
            let now = Instant::now();
            if due > now {
                std::thread::sleep(due - now);
            }
        }
        let c = Command {
            kind: CommandKind::Velocity,
            value: velocity.at(t, dt),
            stamp_ns: t0 + (t * 1e9) as u64,
        };
        let sent = match &output {
            OutputPlan::OneContact => peer.send(&c),
            OutputPlan::Joints(joints) => peer.send_joint_state(&transport::JointStateCommand {
                stamp_ns: c.stamp_ns,
                name: joints.clone(),
                velocity: vec![c.value; joints.len()],
            }),
        };
        if let Err(e) = sent {
            report.error.get_or_insert(e.to_string());
            continue;
        }
        report.commands_sent += 1;
        if mode == StepMode::Lockstep && answered(peer.as_mut(), &output) {
            report.estimates_received += 1;
        }
        report.estimates_received += drain(peer.as_mut(), &output);
    }
    // Answers still in flight.
    let until = Instant::now() + Duration::from_millis(300);
    while Instant::now() < until {
        match drain(peer.as_mut(), &output) {
            0 => std::thread::sleep(Duration::from_millis(5)),
            n => report.estimates_received += n,
        }
    }
    report
}

/// Whether the answer to one command (an estimate; joint efforts with
/// joints) arrives within 2 s.
fn answered(peer: &mut dyn PeerPort, output: &OutputPlan) -> bool {
    if output.by_joint() {
        efforts_timeout(peer, Duration::from_secs(2))
    } else {
        matches!(
            transport::recv_timeout(peer, Duration::from_secs(2)),
            Ok(Some(_))
        )
    }
}

/// Take every answer waiting (estimates; joint efforts with joints): how
/// many.
fn drain(peer: &mut dyn PeerPort, output: &OutputPlan) -> u64 {
    let mut n = 0;
    if output.by_joint() {
        while let Ok(Some(_)) = peer.try_recv_efforts() {
            n += 1;
        }
    } else {
        while let Ok(Some(_)) = peer.try_recv() {
            n += 1;
        }
    }
    n
}
