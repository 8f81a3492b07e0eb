//! The node as a ROS 2 citizen, over DDS on loopback: started with
//! `--ros-args` (name, namespace, a remapping, a parameter), its parameter
//! services called by clients of both DDS service layouts (ros2-client with
//! `ServiceMapping::Enhanced`, as rmw_fastrtps, and `ServiceMapping::Cyclone`,
//! as rmw_cyclonedds) with the real `rcl_interfaces` types; every wait is
//! for an event (a line, a match, a reply), with a generous bound.
#![cfg(feature = "ros2")]

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

/// Requests sent by [`call`] (a retried call sends more than one).
static SENT: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);

fn double(x: f64) -> ParameterValue {
    ParameterValue {
        r#type: parameter_type::DOUBLE,
        double_value: x,
        ..Default::default()
    }
}

/// rcl's service QoS: reliable, volatile, keep last 10.
fn service_qos() -> QosProfile {
    QosProfile::publisher_default()
        .reliability_reliable(ros2_client::qos::WhenFull::Wait(Duration::from_millis(100)))
        .history(ros2_client::qos::History::KeepLast { depth: 10 })
}

/// Call one service of `/node` with `mapping`.
fn call<Req, Resp>(
    node: &mut Node,
    mapping: ServiceMapping,
    fqn: &str,
    service: &str,
    ty: &str,
    req: Req,
) -> Resp
where
    Req: ros2_client::Message + Clone + 'static,
    Resp: ros2_client::Message + 'static,
{
    let client = node
        .create_client::<Req, Resp>(
            mapping,
            &Name::new(fqn, service).unwrap(),
            &ServiceTypeName::new("rcl_interfaces", ty),
            service_qos(),
            service_qos(),
        )
        .unwrap();
    // Discovery first (the request and reply endpoints matched); then a
    // request, sent again if no reply comes (ros2-client's match tracking
    // can miss an event; a request sent before the match can be lost).
    let _ = within_for(Duration::from_secs(10), client.wait_for_service(node));
    for _ in 0..6 {
        SENT.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        match within_for(
            Duration::from_secs(10),
            client.async_call_service(req.clone()),
        ) {
            Some(Ok(r)) => return r,
            Some(Err(e)) => panic!("{service}: {e}"),
            None => eprintln!("{service}: no reply within 10 s; sending again"),
        }
    }
    panic!("{service}: no reply to 6 requests")
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
fn parameters_are_listed_described_got_and_set_in_both_dds_layouts_and_a_remapped_node_publishes_where_told(
) {
    let pid = std::process::id();
    let domain = 150 + pid % 80;
    let name = format!("fnp_{pid}");
    let ff = format!("/fnp_{pid}_ff/friction");
    let _node = start(
        domain,
        &[
            "-r",
            &format!("__node:={name}"),
            "-r",
            "__ns:=/test_ns",
            "-r",
            &format!("~/friction:={ff}"),
            "-p",
            "contact.load_n:=20000.0",
        ],
    );
    let fqn = format!("/test_ns/{name}");
    let (_ctx, mut node) = client_node(domain, &format!("fnp_client_{pid}"));
    // The remapped estimate topic.
    let topic = node
        .create_topic(
            &Name::parse(&ff).unwrap(),
            MessageTypeName::new("friction_msgs", "FrictionEstimate"),
            &QosProfile::subscription_default(),
        )
        .unwrap();
    let sub = std::sync::Arc::new(
        node.create_subscription::<FrictionEstimate>(&topic, None)
            .unwrap(),
    );
    let wait_for_load = |load: f64| {
        let s = sub.clone();
        within("an estimate on the remapped topic", async move {
            loop {
                match s.take() {
                    Ok(Some((m, _))) if m.load_n == load => return m,
                    Ok(_) => futures_timer(Duration::from_millis(5)).await,
                    Err(e) => panic!("{e:?}"),
                }
            }
        })
    };
    // -p applied at start; the remapped topic carries it.
    wait_for_load(20_000.0);
    for (mapping, load) in [
        (ServiceMapping::Enhanced, 5000.0),
        (ServiceMapping::Cyclone, 6000.0),
    ] {
        // Each layout's clients in a participant of their own: RustDDS
        // 0.15 hands a volatile writer's earlier samples to a reader that
        // joins from a participant it already knows, and ros2-client fails
        // on a reply it cannot decode instead of skipping it (rmw_fastrtps
        // and rmw_cyclonedds drop replies for other clients before
        // decoding them).
        let (_mctx, mut node) = client_node(domain, &format!("fnp_{mapping:?}_{pid}"));
        let node = &mut node;
        // Counts the get_parameters replies: created now, matched by the
        // time that call is made.
        let replies = reply_counter(domain, &fqn, "get_parameters");
        let list: ListParametersResponse = call(
            node,
            mapping,
            &fqn,
            "list_parameters",
            "ListParameters",
            ListParametersRequest::default(),
        );
        assert!(
            list.result.names.contains(&"contact.load_n".to_string()),
            "{mapping:?}: {:?}",
            list.result.names
        );
        assert!(list.result.names.len() > 60, "{mapping:?}: every key");
        let described: DescribeParametersResponse = call(
            node,
            mapping,
            &fqn,
            "describe_parameters",
            "DescribeParameters",
            NamesRequest {
                names: vec!["contact.load_n".into(), "solver.cells".into()],
            },
        );
        let d = &described.descriptors;
        assert_eq!(d[0].floating_point_range[0].to_value, 1e9, "{mapping:?}");
        assert!(!d[0].read_only && d[1].read_only, "{mapping:?}");
        assert_eq!(d[1].integer_range[0].from_value, 8);
        // A valid load: accepted, and the next estimates use it.
        let set: SetParametersResponse = call(
            node,
            mapping,
            &fqn,
            "set_parameters",
            "SetParameters",
            SetParametersRequest {
                parameters: vec![Parameter {
                    name: "contact.load_n".into(),
                    value: double(load),
                }],
            },
        );
        assert!(set.results[0].successful, "{mapping:?}: {:?}", set.results);
        wait_for_load(load);
        // Out of range, read-only, wrong type: refused, the key named,
        // nothing changed.
        for (p, needle) in [
            (
                Parameter {
                    name: "contact.load_n".into(),
                    value: double(-1.0),
                },
                "contact.load_n",
            ),
            (
                Parameter {
                    name: "solver.cells".into(),
                    value: ParameterValue {
                        r#type: parameter_type::INTEGER,
                        integer_value: 64,
                        ..Default::default()
                    },
                },
                "read-only",
            ),
            (
                Parameter {
                    name: "contact.boundary_friction".into(),
                    value: ParameterValue {
                        r#type: parameter_type::STRING,
                        string_value: "slippery".into(),
                        ..Default::default()
                    },
                },
                "contact.boundary_friction",
            ),
        ] {
            let r: SetParametersResponse = call(
                node,
                mapping,
                &fqn,
                "set_parameters",
                "SetParameters",
                SetParametersRequest {
                    parameters: vec![p.clone()],
                },
            );
            assert!(!r.results[0].successful, "{mapping:?}: {p:?} accepted");
            assert!(
                r.results[0].reason.contains(needle),
                "{mapping:?}: {}",
                r.results[0].reason
            );
        }
        // Exactly one reply per request: a second reader of the reply
        // topic counts what the server wrote for this call.
        assert_eq!(replies(), 0, "{mapping:?}: nothing before the call");
        let sent_before = SENT.load(std::sync::atomic::Ordering::SeqCst);
        let got: GetParametersResponse = call(
            node,
            mapping,
            &fqn,
            "get_parameters",
            "GetParameters",
            NamesRequest {
                names: vec!["contact.load_n".into(), "solver.cells".into()],
            },
        );
        assert_eq!(got.values[0].double_value, load, "{mapping:?}: unchanged");
        assert_eq!(got.values[1].integer_value, 32);
        let mut seen = 0;
        let until = std::time::Instant::now() + WAIT;
        while seen == 0 && std::time::Instant::now() < until {
            std::thread::sleep(Duration::from_millis(10));
            seen += replies();
        }
        // A duplicate would follow within milliseconds on loopback.
        std::thread::sleep(Duration::from_millis(500));
        seen += replies();
        let sent = SENT.load(std::sync::atomic::Ordering::SeqCst) - sent_before;
        // No duplicate: at most one reply per request sent (and when no
        // retry was needed, which is the rule, exactly one).
        assert!(
            seen >= 1 && seen <= sent,
            "{mapping:?}: {seen} replies to {sent} requests"
        );
    }
}

/// Count the replies written on a service's reply topic from now on (a
/// reader in a participant of its own, see above).
fn reply_counter(domain: u32, fqn: &str, service: &str) -> impl Fn() -> usize {
    use friction_node::transport::ros2::raw::{RawAdapter, RawCdr};
    use ros2_client::dds::rustdds::{policy, QosPolicyBuilder, TopicKind};
    let dp = DomainParticipantBuilder::new(domain as u16)
        .with_only_networks([Ipv4Addr::LOCALHOST])
        .build()
        .unwrap();
    let qos = QosPolicyBuilder::new()
        .reliability(policy::Reliability::Reliable {
            max_blocking_time: ros2_client::dds::rustdds::Duration::from_millis(100),
        })
        .history(policy::History::KeepLast { depth: 100 })
        .build();
    let topic = dp
        .create_topic(
            format!("rr{fqn}/{service}Reply"),
            "rcl_interfaces::srv::dds_::GetParameters_Response_".into(),
            &qos,
            TopicKind::NoKey,
        )
        .unwrap();
    let reader = dp
        .create_subscriber(&qos)
        .unwrap()
        .create_simple_datareader_no_key::<RawCdr, RawAdapter>(&topic, Some(qos))
        .unwrap();
    move || {
        let _keep = &dp; // the participant lives as long as the counter
        let mut n = 0;
        while let Ok(Some(_)) = reader.try_take_one() {
            n += 1;
        }
        n
    }
}

/// `diagnostic_msgs` as ROS 2 Humble defines them (written here from the
/// `.msg` files, independently of the node's own structs).
mod diagnostic_msgs {
    use serde::Deserialize;
    #[derive(Debug, Clone, Deserialize)]
    pub struct Time {
        pub sec: i32,
        pub nanosec: u32,
    }
    #[derive(Debug, Clone, Deserialize)]
    pub struct Header {
        pub stamp: Time,
        pub frame_id: String,
    }
    #[derive(Debug, Clone, Deserialize)]
    pub struct KeyValue {
        pub key: String,
        pub value: String,
    }
    #[derive(Debug, Clone, Deserialize)]
    pub struct DiagnosticStatus {
        pub level: u8,
        pub name: String,
        pub message: String,
        pub hardware_id: String,
        pub values: Vec<KeyValue>,
    }
    #[derive(Debug, Clone, Deserialize)]
    pub struct DiagnosticArray {
        pub header: Header,
        pub status: Vec<DiagnosticStatus>,
    }
}

#[test]
fn log_lines_reach_rosout_and_health_reaches_diagnostics_in_the_standard_layouts() {
    let pid = std::process::id();
    let domain = 150 + (pid + 41) % 80;
    let name = format!("fnd_{pid}");
    let _node = start(
        domain,
        &["-r", &format!("__node:={name}"), "--log-level", "info"],
    );
    let (_ctx, mut node) = client_node(domain, &format!("fnd_client_{pid}"));
    // /rosout, read with ros2-client's own Log type.
    let rosout_topic = node
        .create_topic(
            &Name::parse("/rosout").unwrap(),
            MessageTypeName::new("rcl_interfaces", "Log"),
            &QosProfile::subscription_default(),
        )
        .unwrap();
    let rosout_qos = QosProfile::publisher_default()
        .durability(ros2_client::qos::Durability::TransientLocal)
        .history(ros2_client::qos::History::KeepLast { depth: 1000 });
    let rosout = node
        .create_subscription::<ros2_client::log::Log>(&rosout_topic, Some(rosout_qos))
        .unwrap();
    let line = within("a line on /rosout", async {
        loop {
            if let Ok(Some((l, _))) = rosout.take() {
                if l.name == name && l.msg.starts_with("loop running") {
                    return l;
                }
            }
            futures_timer(Duration::from_millis(5)).await;
        }
    });
    assert_eq!(line.level, 20, "INFO");
    assert!(line.msg.contains("Timer mode"), "{}", line.msg);
    // /diagnostics at 1 Hz: five statuses with their values.
    let diag_topic = node
        .create_topic(
            &Name::parse("/diagnostics").unwrap(),
            MessageTypeName::new("diagnostic_msgs", "DiagnosticArray"),
            &QosProfile::subscription_default(),
        )
        .unwrap();
    let diag = node
        .create_subscription::<diagnostic_msgs::DiagnosticArray>(&diag_topic, None)
        .unwrap();
    let a = within("an array on /diagnostics", async {
        loop {
            if let Ok(Some((a, _))) = diag.take() {
                if a.status
                    .first()
                    .is_some_and(|s| s.hardware_id.ends_with(&name))
                {
                    return a;
                }
            }
            futures_timer(Duration::from_millis(5)).await;
        }
    });
    let names: Vec<String> = a
        .status
        .iter()
        .map(|s| s.name.rsplit(": ").next().unwrap().to_string())
        .collect();
    assert_eq!(
        names,
        [
            "loop timing",
            "solver",
            "commands",
            "outputs",
            "recorder",
            "calibrated range"
        ]
    );
    assert!(a.status.iter().all(|s| s.level <= 2));
    let steps: u64 = a.status[0]
        .values
        .iter()
        .find(|v| v.key == "steps")
        .unwrap()
        .value
        .parse()
        .unwrap();
    assert!(steps > 0);
    assert_eq!(a.header.frame_id, "slider");
    // No peer commands anything: the command concern says so.
    assert_eq!(a.status[2].level, 1, "{:?}", a.status[2]);
    assert!(
        a.status[2].message.contains("timed-out"),
        "{}",
        a.status[2].message
    );
    assert!(a.header.stamp.sec > 0 && a.header.stamp.nanosec < 1_000_000_000);
}

#[test]
fn a_speed_outside_the_calibrated_range_warns_on_diagnostics_naming_it_and_clears_when_back() {
    let pid = std::process::id();
    let domain = 150 + (pid + 63) % 80;
    let name = format!("fnr_{pid}");
    let dir = std::env::temp_dir().join(format!("fn-ros2-range-{pid}"));
    std::fs::create_dir_all(&dir).unwrap();
    let cfg = dir.join("fitted.yaml");
    std::fs::write(
        &cfg,
        "/**:\n  ros__parameters:\n    calibrated_range:\n      speed_forward_min_m_s: 0.0\n      \
         speed_forward_max_m_s: 0.35\n      speed_backward_min_m_s: 0.0\n      \
         speed_backward_max_m_s: 0.35\n      training_rms_n: 1.0\n      training_samples: 100\n",
    )
    .unwrap();
    let _node = start_with(
        domain,
        &["--config", cfg.to_str().unwrap()],
        &["-r", &format!("__node:={name}")],
    );
    let (_ctx, mut node) = client_node(domain, &format!("fnr_client_{pid}"));
    let cmd_topic = node
        .create_topic(
            &Name::parse(&format!("/{name}/cmd_velocity")).unwrap(),
            MessageTypeName::new("std_msgs", "Float64"),
            &QosProfile::publisher_default(),
        )
        .unwrap();
    let cmd = node
        .create_publisher::<friction_node::msgs::Float64>(&cmd_topic, None)
        .unwrap();
    let diag_topic = node
        .create_topic(
            &Name::parse("/diagnostics").unwrap(),
            MessageTypeName::new("diagnostic_msgs", "DiagnosticArray"),
            &QosProfile::subscription_default(),
        )
        .unwrap();
    let diag = node
        .create_subscription::<diagnostic_msgs::DiagnosticArray>(&diag_topic, None)
        .unwrap();
    // Command `v` every 5 ms until the node's "calibrated range" status
    // has `level`; that status.
    let until_level = |v: f64, level: u8| {
        within("the calibrated range's status", async {
            loop {
                let _ = cmd.publish(friction_node::msgs::Float64 { data: v });
                while let Ok(Some((a, _))) = diag.take() {
                    let s = a.status.into_iter().find(|s| {
                        s.hardware_id.ends_with(&name) && s.name.ends_with(": calibrated range")
                    });
                    if let Some(s) = s.filter(|s| s.level == level) {
                        return s;
                    }
                }
                futures_timer(Duration::from_millis(5)).await;
            }
        })
    };
    let warn = until_level(1.57, 1);
    assert!(
        warn.message
            .starts_with("speed forward 1.57 m/s outside the calibrated 0 to 0.35 m/s"),
        "{}",
        warn.message
    );
    println!("{}: {}", warn.name, warn.message);
    let ok = until_level(0.2, 0);
    assert!(
        ok.message.starts_with("every input inside"),
        "{}",
        ok.message
    );
    let _ = std::fs::remove_dir_all(&dir);
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
