//! Live parameters under load: the time from a `set_parameters` request to
//! the first estimate that uses it, and the loop's timing with and without
//! parameter traffic, side by side (ROS 2 over loopback, release build).
//!
//! ```sh
//! cargo build --release
//! cargo run --release --example bench_parameters -- [SECONDS [RATE_HZ [PAIRS [NODE ARGS...]]]]
//! # e.g. with the real-time settings:
//! cargo run --release --example bench_parameters -- 60 10 2 \
//!     --set node.realtime.fifo=true --set node.realtime.lock_memory=true --set node.realtime.cpu=1
//! ```
//!
//! For each of PAIRS (default 2), the node (`target/release/friction-node
//! run --demo SECONDS`, timer mode at 1 kHz, driven by the paper's motion)
//! runs twice in turn: once alone, once while this client sets
//! `contact.load_n` RATE_HZ times a second (default 10) through the
//! `set_parameters` service, each time to a new value, and watches `~/friction`
//! for the first estimate with that load. Printed: the latency p50 / p99 /
//! max over all sets, and each run's own summary lines (deadline misses,
//! jitter, compute time).
#![cfg(feature = "ros2")]

use friction_node::msgs::ros_interfaces::{
    parameter_type, Parameter, ParameterValue, SetParametersRequest, SetParametersResponse,
};
use friction_node::msgs::FrictionEstimate;
use ros2_client::dds::rustdds::DomainParticipantBuilder;
use ros2_client::service::ServiceMapping;
use ros2_client::{
    Context, MessageTypeName, Name, NodeName, NodeOptions, QosProfile, ServiceTypeName,
};
use std::collections::HashMap;
use std::io::{BufRead, BufReader};
use std::net::Ipv4Addr;
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |i: usize, d: f64| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let seconds = arg(0, 60.0);
    let rate_hz = arg(1, 10.0);
    let pairs = arg(2, 2.0) as usize;
    let node_args: Vec<String> = args.iter().skip(3).cloned().collect();
    let bin = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target/release/friction-node");
    assert!(bin.exists(), "build the node first: cargo build --release");
    let domain = 150 + std::process::id() % 80;
    let mut latencies = Vec::new();
    for pair in 0..pairs {
        for traffic in [false, true] {
            println!(
                "--- pair {}, {} ---",
                pair + 1,
                if traffic {
                    format!("set_parameters at {rate_hz} Hz")
                } else {
                    "no parameter traffic".into()
                }
            );
            let summary = run_once(
                &bin,
                domain,
                seconds,
                traffic.then_some(rate_hz),
                &node_args,
                &mut latencies,
            );
            for l in summary.lines().filter(|l| {
                l.contains("compute time") || l.contains("jitter") || l.contains("deadline")
            }) {
                println!("{l}");
            }
        }
    }
    latencies.sort_by(f64::total_cmp);
    let q = |p: f64| latencies[((latencies.len() - 1) as f64 * p).round() as usize];
    println!(
        "set_parameters → first estimate using it: {} sets, p50 {:.2} ms, p99 {:.2} ms, max {:.2} ms",
        latencies.len(),
        q(0.5),
        q(0.99),
        latencies.last().unwrap()
    );
}

/// One run of the node; returns its summary (stdout).
fn run_once(
    bin: &std::path::Path,
    domain: u32,
    seconds: f64,
    rate_hz: Option<f64>,
    node_args: &[String],
    latencies: &mut Vec<f64>,
) -> String {
    let mut child = Command::new(bin)
        .args(["run", "--quiet", "--demo", &seconds.to_string()])
        .args(["--set", &format!("ros.domain_id={domain}")])
        .args(node_args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the node starts");
    let stderr = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(stderr).lines().map_while(Result::ok) {
            if line.contains("loop running") {
                let _ = tx.send(());
            }
        }
    });
    rx.recv_timeout(Duration::from_secs(60))
        .expect("the node's loop starts");
    if let Some(rate) = rate_hz {
        set_loads(domain, seconds - 5.0, rate, latencies);
    }
    let out = child.wait_with_output().expect("the node ends");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Set a new load `rate` times a second for `seconds`; push each set's
/// latency (ms) to the first estimate carrying it.
fn set_loads(domain: u32, seconds: f64, rate: f64, latencies: &mut Vec<f64>) {
    let dp = DomainParticipantBuilder::new(domain as u16)
        .with_only_networks([Ipv4Addr::LOCALHOST])
        .build()
        .unwrap();
    let ctx = Context::from_domain_participant(dp).unwrap();
    let mut node = ctx
        .new_node(
            NodeName::new("/", &format!("bench_params_{}", std::process::id())).unwrap(),
            NodeOptions::new()
                .enable_rosout(false)
                .start_parameter_services(false),
        )
        .unwrap();
    let spinner = node.spinner().unwrap();
    std::thread::spawn(move || futures::executor::block_on(spinner.spin()));
    let topic = node
        .create_topic(
            &Name::parse("/friction_node/friction").unwrap(),
            MessageTypeName::new("friction_msgs", "FrictionEstimate"),
            &QosProfile::subscription_default(),
        )
        .unwrap();
    let sub = node
        .create_subscription::<FrictionEstimate>(&topic, None)
        .unwrap();
    // First arrival of each load value.
    let seen: Arc<Mutex<HashMap<u64, Instant>>> = Arc::default();
    let seen2 = seen.clone();
    std::thread::spawn(move || {
        use futures::StreamExt;
        let stream = sub.async_stream();
        futures::pin_mut!(stream);
        futures::executor::block_on(async {
            while let Some(m) = stream.next().await {
                if let Ok((m, _)) = m {
                    seen2
                        .lock()
                        .unwrap()
                        .entry(m.load_n.to_bits())
                        .or_insert_with(Instant::now);
                }
            }
        });
    });
    let qos = QosProfile::publisher_default()
        .reliability_reliable(ros2_client::qos::WhenFull::Wait(Duration::from_millis(100)))
        .history(ros2_client::qos::History::KeepLast { depth: 10 });
    let client = node
        .create_client::<SetParametersRequest, SetParametersResponse>(
            ServiceMapping::Enhanced,
            &Name::new("/friction_node", "set_parameters").unwrap(),
            &ServiceTypeName::new("rcl_interfaces", "SetParameters"),
            qos.clone(),
            qos,
        )
        .unwrap();
    futures::executor::block_on(client.wait_for_service(&node));
    let start = Instant::now();
    let period = Duration::from_secs_f64(1.0 / rate);
    let mut k = 0u64;
    while start.elapsed().as_secs_f64() < seconds {
        k += 1;
        let load = 20_000.0 + k as f64;
        let req = SetParametersRequest {
            parameters: vec![Parameter {
                name: "contact.load_n".into(),
                value: ParameterValue {
                    r#type: parameter_type::DOUBLE,
                    double_value: load,
                    ..Default::default()
                },
            }],
        };
        let t0 = Instant::now();
        match futures::executor::block_on(client.async_call_service(req)) {
            Ok(r) if r.results.first().is_some_and(|r| r.successful) => {}
            other => panic!("set_parameters failed: {other:?}"),
        }
        let seen_at = loop {
            if let Some(t) = seen.lock().unwrap().get(&load.to_bits()) {
                break Some(*t);
            }
            if t0.elapsed() > Duration::from_secs(5) {
                break None;
            }
            std::thread::sleep(Duration::from_micros(200));
        };
        match seen_at {
            Some(t) => latencies.push(t.saturating_duration_since(t0).as_secs_f64() * 1e3),
            None => eprintln!("load {load}: no estimate within 5 s"),
        }
        let next = start + period * k as u32;
        if let Some(d) = next.checked_duration_since(Instant::now()) {
            std::thread::sleep(d);
        }
    }
}
