//! `friction-node bench-latency`: command → estimate through a transport,
//! model step included, against a lockstep node. With several contacts
//! configured: JointState (every joint) → joint efforts (the
//! Float64MultiArray a ros2_control controller takes), every contact's
//! step included.

use crate::config::Config;
use crate::link::LiveStatus;
use crate::msgs::{Command, CommandKind};
use crate::node::runner::RunError;
use crate::node::{Loop, RunSummary};
use crate::transport::{BackendSpec, JointStateCommand, PeerPort};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Command → estimate latency through a transport (lockstep node, model step
/// included), measured by a peer in this process.
#[derive(Debug, Clone)]
pub struct LatencyReport {
    /// The transport measured.
    pub transport: &'static str,
    /// Contacts stepped per round trip (several: JointState → efforts).
    pub contacts: usize,
    /// Round trips measured.
    pub samples: usize,
    /// p50, p99, p99.9, max of command → estimate, µs.
    pub latency_us: [f64; 4],
    /// The node's model step, p50 / p99, µs.
    pub step_us: [f64; 2],
    /// Round trips without an answer.
    pub lost: usize,
}

/// Measure the latency of `spec` with `samples` round trips after `warmup`.
pub fn latency(
    config: &Config,
    spec: BackendSpec,
    samples: usize,
    warmup: usize,
) -> Result<LatencyReport, RunError> {
    let mut cfg = config.clone();
    cfg.node.step_mode = crate::config::StepMode::Lockstep;
    cfg.node.profile_rate_hz = 0.0;
    cfg.ros.qos.commands.reliability = crate::config::Reliability::Reliable;
    cfg.ros.qos.commands.depth = 100;
    let stop = Arc::new(AtomicBool::new(false));
    let node = start_node(&cfg, &spec, &stop);
    let mut peer = spec.open_peer()?;
    crate::transport::wait_matched(peer.as_mut(), Duration::from_secs(20))?;
    let mut trip = RoundTrip::new(&cfg);
    let mut times = Vec::with_capacity(samples);
    let mut lost = 0;
    for k in 0..warmup + samples {
        match trip.run(peer.as_mut(), k)? {
            Some(ns) if k >= warmup => times.push(ns),
            Some(_) => {}
            None => lost += 1,
        }
    }
    stop.store(true, Ordering::Relaxed);
    let summary = node
        .join()
        .map_err(|_| RunError::ThreadPanicked("node"))??;
    times.sort_unstable();
    let us = |ns: Option<&u64>| ns.map_or(f64::NAN, |v| *v as f64 / 1e3);
    let q = |p: f64| us(times.get(((p * (times.len().max(1) - 1) as f64).round()) as usize));
    Ok(LatencyReport {
        contacts: cfg.resolved_contacts().len(),
        transport: spec.name(),
        samples: times.len(),
        latency_us: [q(0.5), q(0.99), q(0.999), us(times.last())],
        step_us: [
            summary.compute_ns[0] as f64 / 1e3,
            summary.compute_ns[1] as f64 / 1e3,
        ],
        lost,
    })
}

/// A lockstep node on `spec` on its own thread, started once its port is
/// open (or after 30 s), running until `stop`.
fn start_node(
    cfg: &Config,
    spec: &BackendSpec,
    stop: &Arc<AtomicBool>,
) -> std::thread::JoinHandle<Result<RunSummary, RunError>> {
    let (tx, rx) = std::sync::mpsc::channel();
    let (s2, spec2, cfg2) = (stop.clone(), spec.clone(), cfg.clone());
    let node = std::thread::spawn(move || -> Result<RunSummary, RunError> {
        let port = spec2.open_node(Default::default())?;
        let mut l = Loop::new(
            &cfg2,
            vec![port],
            None,
            None,
            Arc::new(LiveStatus::default()),
        )?;
        let _ = tx.send(());
        Ok(l.run(&s2, None))
    });
    let _ = rx.recv_timeout(Duration::from_secs(30));
    node
}

/// One command (or JointState, with joints) → its answer, timed.
struct RoundTrip {
    dt: f64,
    stamp0: u64,
    by_joint: bool,
    joint_state: JointStateCommand,
}

impl RoundTrip {
    fn new(cfg: &Config) -> Self {
        let joints: Vec<String> = cfg
            .resolved_contacts()
            .into_iter()
            .map(|c| c.joint)
            .collect();
        Self {
            dt: cfg.solver.dt_s,
            stamp0: crate::clock::system_wall_ns(),
            by_joint: cfg.output_plan().by_joint(),
            joint_state: JointStateCommand {
                stamp_ns: 0,
                velocity: vec![0.0; joints.len()],
                name: joints,
            },
        }
    }

    /// Round trip `k` (a 1 Hz sine of velocity): its time, ns, or None
    /// without an answer in 2 s.
    fn run(&mut self, peer: &mut dyn PeerPort, k: usize) -> Result<Option<u64>, RunError> {
        let t = (k + 1) as f64 * self.dt;
        let v = (2.0 * std::f64::consts::PI * t).sin();
        let stamp_ns = self.stamp0 + k as u64 * 1_000_000;
        let js = &mut self.joint_state;
        js.stamp_ns = stamp_ns;
        for (i, x) in js.velocity.iter_mut().enumerate() {
            *x = v * (1.0 - 0.05 * i as f64);
        }
        let start = Instant::now();
        if self.by_joint {
            peer.send_joint_state(js)?;
        } else {
            peer.send(&Command {
                kind: CommandKind::Velocity,
                value: v,
                stamp_ns,
            })?;
        }
        // Busy-poll: the peer is a tight control loop waiting for its answer.
        let got = loop {
            let answer = if self.by_joint {
                peer.try_recv_efforts()?.map(|_| ())
            } else {
                peer.try_recv()?.map(|_| ())
            };
            if answer.is_some() || start.elapsed() > Duration::from_secs(2) {
                break answer;
            }
            std::hint::spin_loop();
        };
        let ns = u64::try_from(start.elapsed().as_nanos()).unwrap_or(u64::MAX);
        while self.by_joint && peer.try_recv_contact()?.is_some() {}
        Ok(got.map(|_| ns))
    }
}
