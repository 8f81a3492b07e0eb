//! The node's parameter services, called by clients of both DDS service
//! layouts with the real `rcl_interfaces` types, and a remapped node that
//! publishes where it is told.

use super::*;

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
