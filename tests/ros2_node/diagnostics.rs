//! What the node says about itself: log lines on `/rosout`, health and a
//! speed outside the calibrated range on `/diagnostics`, in the standard
//! layouts.

use super::*;

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
