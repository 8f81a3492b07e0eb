//! `friction-node bench-latency`: command → estimate through a transport,
//! model step included, against a lockstep node. With several contacts
//! configured: JointState (every joint) → joint efforts (the
//! Float64MultiArray a ros2_control controller takes), every contact's
//! step included.

use crate::config::Config;
use crate::node::runner::RunError;
use std::time::Instant;

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
    spec: crate::transport::BackendSpec,
    samples: usize,
    warmup: usize,
) -> Result<LatencyReport, RunError> {
    use crate::link::LiveStatus;
    use crate::msgs::{Command, CommandKind};
    use crate::node::Loop;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::sync::Arc;
    use std::time::Duration;
    let mut cfg = config.clone();
    cfg.node.step_mode = crate::config::StepMode::Lockstep;
    cfg.node.profile_rate_hz = 0.0;
    cfg.ros.qos.commands.reliability = crate::config::Reliability::Reliable;
    cfg.ros.qos.commands.depth = 100;
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = std::sync::mpsc::channel();
    let (s2, spec2, cfg2) = (stop.clone(), spec.clone(), cfg.clone());
    let node = std::thread::spawn(move || -> Result<crate::node::RunSummary, RunError> {
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
    let mut peer = spec.open_peer()?;
    crate::transport::wait_matched(peer.as_mut(), Duration::from_secs(20))?;
    let dt = cfg.solver.dt_s;
    let mut times = Vec::with_capacity(samples);
    let mut lost = 0;
    let stamp0 = crate::clock::system_wall_ns();
    let plan = cfg.output_plan();
    let several = plan.by_joint();
    let joints: Vec<String> = cfg
        .resolved_contacts()
        .into_iter()
        .map(|c| c.joint)
        .collect();
    let mut js = crate::transport::JointStateCommand {
        stamp_ns: 0,
        velocity: vec![0.0; joints.len()],
        name: joints,
    };
    for k in 0..warmup + samples {
        let t = (k + 1) as f64 * dt;
        let v = (2.0 * std::f64::consts::PI * t).sin();
        let stamp_ns = stamp0 + k as u64 * 1_000_000;
        let c = Command {
            kind: CommandKind::Velocity,
            value: v,
            stamp_ns,
        };
        js.stamp_ns = stamp_ns;
        for (i, x) in js.velocity.iter_mut().enumerate() {
            *x = v * (1.0 - 0.05 * i as f64);
        }
        let start = Instant::now();
        if several {
            peer.send_joint_state(&js)?;
        } else {
            peer.send(&c)?;
        }
        // Busy-poll: the peer is a tight control loop waiting for its answer.
        let got = loop {
            let answer = if several {
                peer.try_recv_efforts()?.map(|_| ())
            } else {
                peer.try_recv()?.map(|_| ())
            };
            if answer.is_some() {
                break answer;
            }
            if start.elapsed() > Duration::from_secs(2) {
                break None;
            }
            std::hint::spin_loop();
        };
        let ns = start.elapsed().as_nanos() as u64;
        while several && peer.try_recv_contact()?.is_some() {}
        match got {
            Some(_) if k >= warmup => times.push(ns),
            Some(_) => {}
            None => lost += 1,
        }
    }
    stop.store(true, Ordering::Relaxed);
    let summary = node
        .join()
        .map_err(|_| RunError::ThreadPanicked("node"))??;
    let mut sorted = times.clone();
    sorted.sort_unstable();
    let q = |p: f64| {
        sorted
            .get(((p * (sorted.len().max(1) - 1) as f64).round()) as usize)
            .map_or(f64::NAN, |v| *v as f64 / 1e3)
    };
    Ok(LatencyReport {
        contacts: cfg.resolved_contacts().len(),
        transport: spec.name(),
        samples: times.len(),
        latency_us: [
            q(0.5),
            q(0.99),
            q(0.999),
            sorted.last().map_or(f64::NAN, |v| *v as f64 / 1e3),
        ],
        step_us: [
            summary.compute_ns[0] as f64 / 1e3,
            summary.compute_ns[1] as f64 / 1e3,
        ],
        lost,
    })
}
