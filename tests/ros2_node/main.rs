//! The node as a ROS 2 citizen, over DDS on loopback: started with
//! `--ros-args` (name, namespace, a remapping, a parameter), its parameter
//! services called by clients of both DDS service layouts (ros2-client with
//! `ServiceMapping::Enhanced`, as rmw_fastrtps, and `ServiceMapping::Cyclone`,
//! as rmw_cyclonedds) with the real `rcl_interfaces` types; every wait is
//! for an event (a line, a match, a reply), with a generous bound.
//!
//! This file holds the harness (the node started, a client node, waits)
//! and the simulated clock:
//!
//! | file | job |
//! |---|---|
//! | `parameters.rs` | the parameter services in both DDS layouts, a remapped node |
//! | `diagnostics.rs` | `/rosout` and `/diagnostics`, the calibrated range's warning |
#![cfg(feature = "ros2")]

mod diagnostics;
mod parameters;

use friction_node::msgs::ros_interfaces::{
    parameter_type, DescribeParametersResponse, GetParametersResponse, ListParametersRequest,
    ListParametersResponse, NamesRequest, Parameter, ParameterValue, SetParametersRequest,
    SetParametersResponse,
};
use friction_node::msgs::FrictionEstimate;
use ros2_client::dds::rustdds::DomainParticipantBuilder;
use ros2_client::service::ServiceMapping;
use ros2_client::{
    Context, MessageTypeName, Name, Node, NodeName, NodeOptions, QosProfile, ServiceTypeName,
};
use std::io::{BufRead, BufReader};
use std::net::Ipv4Addr;
use std::process::{Child, Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

const WAIT: Duration = Duration::from_secs(60);

struct Running {
    child: Child,
}

impl Drop for Running {
    fn drop(&mut self) {
        unsafe {
            libc::kill(self.child.id() as i32, libc::SIGTERM);
        }
        let _ = self.child.wait();
    }
}

/// Start `run` with `ros_args`; returns when its loop runs.
fn start(domain: u32, ros_args: &[&str]) -> Running {
    start_with(domain, &[], ros_args)
}

/// Start `run` with `args`, then `ros_args`; returns when its loop runs.
fn start_with(domain: u32, args: &[&str], ros_args: &[&str]) -> Running {
    let mut child = Command::new(env!("CARGO_BIN_EXE_friction-node"))
        .arg("run")
        .args(args)
        .args([
            "--duration",
            "120",
            "--quiet",
            "--set",
            &format!("ros.domain_id={domain}"),
            "--set",
            "solver.cells=32",
            "--ros-args",
        ])
        .args(ros_args)
        .stderr(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if line.contains("loop running") {
                let _ = tx.send(());
            }
        }
    });
    rx.recv_timeout(WAIT).expect("the node's loop starts");
    Running { child }
}

/// A client node on loopback, with its spinner.
fn client_node(domain: u32, name: &str) -> (Context, Node) {
    let dp = DomainParticipantBuilder::new(domain as u16)
        .with_only_networks([Ipv4Addr::LOCALHOST])
        .build()
        .unwrap();
    let ctx = Context::from_domain_participant(dp).unwrap();
    let mut node = ctx
        .new_node(
            NodeName::new("/", name).unwrap(),
            NodeOptions::new()
                .enable_rosout(false)
                .start_parameter_services(false),
        )
        .unwrap();
    let spinner = node.spinner().unwrap();
    std::thread::spawn(move || futures::executor::block_on(spinner.spin()));
    (ctx, node)
}

/// Run a future here, waiting at most [`WAIT`].
fn within<T>(what: &str, f: impl std::future::Future<Output = T>) -> T {
    within_for(WAIT, f).unwrap_or_else(|| panic!("{what}: no answer within {WAIT:?}"))
}

/// Run a future here for at most `limit`.
fn within_for<T>(limit: Duration, f: impl std::future::Future<Output = T>) -> Option<T> {
    match futures::executor::block_on(futures::future::select(
        Box::pin(f),
        Box::pin(futures_timer(limit)),
    )) {
        futures::future::Either::Left((v, _)) => Some(v),
        futures::future::Either::Right(_) => None,
    }
}

/// A future that completes after `d` (a thread sleeps; no runtime needed).
fn futures_timer(d: Duration) -> impl std::future::Future<Output = ()> {
    let (tx, rx) = futures::channel::oneshot::channel::<()>();
    std::thread::spawn(move || {
        std::thread::sleep(d);
        let _ = tx.send(());
    });
    async move {
        let _ = rx.await;
    }
}

#[test]
fn with_use_sim_time_the_loop_steps_on_clock_and_stamps_with_it() {
    use friction_node::msgs::ros_interfaces::Clock;
    use friction_node::msgs::Time;
    let pid = std::process::id();
    let domain = 150 + (pid + 17) % 80;
    let name = format!("fns_{pid}");
    let _node = start(
        domain,
        &["-r", &format!("__node:={name}"), "-p", "use_sim_time:=true"],
    );
    let (_ctx, mut node) = client_node(domain, &format!("fns_client_{pid}"));
    let clock_topic = node
        .create_topic(
            &Name::parse("/clock").unwrap(),
            MessageTypeName::new("rosgraph_msgs", "Clock"),
            &QosProfile::publisher_default(),
        )
        .unwrap();
    let clock = node.create_publisher::<Clock>(&clock_topic, None).unwrap();
    let est_topic = node
        .create_topic(
            &Name::parse(&format!("/{name}/friction")).unwrap(),
            MessageTypeName::new("friction_msgs", "FrictionEstimate"),
            &QosProfile::subscription_default(),
        )
        .unwrap();
    let est_qos = QosProfile::publisher_default()
        .history(ros2_client::qos::History::KeepLast { depth: 1000 });
    let sub = node
        .create_subscription::<FrictionEstimate>(&est_topic, Some(est_qos))
        .unwrap();
    // Simulated time from an arbitrary epoch, 1 ms per message, published
    // every 2 ms of wall time (half speed); the node must follow it.
    let t0: u64 = 1_000_000_000_000_000_000;
    let publish = |k: u64| {
        let _ = clock.publish(Clock {
            clock: Time::from_ns(t0 + k * 1_000_000),
        });
    };
    // Until the node has matched us and stepped at least once.
    let mut k = 0;
    let mut stamps = Vec::new();
    let until = std::time::Instant::now() + WAIT;
    while stamps.is_empty() && std::time::Instant::now() < until {
        publish(k);
        k += 1;
        std::thread::sleep(Duration::from_millis(2));
        while let Ok(Some((e, _))) = sub.take() {
            stamps.push(e.header.stamp);
        }
    }
    assert!(!stamps.is_empty(), "the node steps once /clock moves");
    for _ in 0..200 {
        publish(k);
        k += 1;
        std::thread::sleep(Duration::from_millis(2));
        while let Ok(Some((e, _))) = sub.take() {
            stamps.push(e.header.stamp);
        }
    }
    let last_clock = t0 + (k - 1) * 1_000_000;
    // Let the last messages arrive; time then stands still.
    std::thread::sleep(Duration::from_millis(300));
    while let Ok(Some((e, _))) = sub.take() {
        stamps.push(e.header.stamp);
    }
    let ns: Vec<u64> = stamps.iter().map(|t| t.to_ns()).collect();
    assert!(
        ns.windows(2).all(|w| w[1] - w[0] == 1_000_000),
        "one step per simulated millisecond, stamped with /clock"
    );
    assert!(ns
        .iter()
        .all(|s| (s - t0).is_multiple_of(1_000_000) && *s <= last_clock));
    assert!(ns.len() >= 150, "{} steps for {} simulated ms", ns.len(), k);
    assert!(
        *ns.last().unwrap() >= last_clock - 5_000_000,
        "the loop keeps up with /clock"
    );
    // Paused /clock: no more steps.
    std::thread::sleep(Duration::from_millis(300));
    assert!(sub.take().unwrap().is_none(), "time stands still");
    // Sim time is not a wall-clock jump.
    drop(_node);
}
