//! Which topic and joint a replay reads: named, listed when it must be chosen,
//! and what a bag holds when it has no velocity.

use super::*;

#[test]
fn a_foreign_joint_state_bag_replays_the_named_joint_on_the_model_time_grid() {
    let p = prepare(FOREIGN_BAG, &opts(Some("/joint_states"), Some("slider"))).unwrap();
    assert_eq!(p.config_source, "built-in default");
    match &p.mode {
        InputMode::Topics {
            velocity,
            kind,
            load,
            temperature,
        } => {
            assert_eq!(*temperature, None);
            assert_eq!(velocity, "/joint_states");
            assert!(matches!(kind, SampleKind::JointVelocity(joint) if joint == "slider"));
            assert_eq!(load.as_deref(), Some("/slider/normal_load"));
        }
        other => panic!("{other:?}"),
    }
    assert_eq!(p.velocity_messages, 1001, "2 s at 500 Hz");
    let vel: Vec<_> = p
        .commands
        .iter()
        .filter(|c| c.kind == CommandKind::Velocity)
        .collect();
    assert_eq!(vel.len(), 2001, "2 s on the 1 ms grid");
    let t0 = vel[0].stamp_ns;
    for c in &vel {
        let t = (c.stamp_ns - t0) as f64 / 1e9;
        // Linear interpolation of 2 ms samples of 0.6 sin 2πt: error ≤ v''h²/8.
        let exact = 0.6 * (2.0 * std::f64::consts::PI * t).sin();
        assert!(
            (c.value - exact).abs() <= 1.2e-5,
            "t = {t}: {} vs {exact}",
            c.value
        );
    }
    let loads: Vec<(f64, f64)> = p
        .commands
        .iter()
        .filter(|c| c.kind == CommandKind::Load)
        .map(|c| ((c.stamp_ns - t0) as f64 / 1e9, c.value))
        .collect();
    assert_eq!(
        loads,
        vec![(0.0, 5762.0), (1.0, 4000.0)],
        "the load set points, held"
    );
    assert!(p.gaps.is_empty());

    let r = replay::run(&p, &mut |_, _| Ok(()), &mut |_, _, _| {}).unwrap();
    assert_eq!(r.estimates.len(), 2001);
    assert!(
        r.oracle.is_none(),
        "a foreign bag has nothing to compare with"
    );
    assert_eq!(r.commands_rejected, 0);
    for (e, rec) in &r.estimates {
        assert_eq!(
            rec.status,
            msgs::estimate_constants::STATUS_CONVERGED,
            "{e:?}"
        );
        assert!(e.friction_force.is_finite() && e.h0 > 0.0);
    }
    // The load step reaches the model: before 1 s 5762 N, after 4000 N.
    assert_eq!(r.estimates[999].1.load_n, 5762.0);
    assert_eq!(r.estimates[1000].1.load_n, 4000.0);
}

#[test]
fn a_joint_state_with_several_joints_needs_a_joint_name() {
    let e = prepare(FOREIGN_BAG, &opts(Some("/joint_states"), None)).unwrap_err();
    assert!(
        matches!(e, ReplayError::Bag(BagError::JointRequired { .. })),
        "{e}"
    );
    let m = e.to_string();
    assert!(
        m.contains("base_yaw, slider, gripper") && m.contains("--joint"),
        "{m}"
    );
    let e = prepare(FOREIGN_BAG, &opts(Some("/joint_states"), Some("elbow"))).unwrap_err();
    assert!(
        matches!(e, ReplayError::Bag(BagError::JointMissing { .. })),
        "{e}"
    );
    assert!(e.to_string().contains("`elbow`"), "{e}");
}

#[test]
fn several_velocity_topics_are_listed_until_one_is_chosen() {
    let e = prepare(FOREIGN_BAG, &opts(None, None)).unwrap_err();
    let m = e.to_string();
    assert!(matches!(e, ReplayError::AmbiguousVelocity { .. }), "{m}");
    assert!(
        m.contains("/joint_states") && m.contains("/cmd_vel") && m.contains("--topic"),
        "{m}"
    );
    // A joint's name picks the bag's only JointState topic.
    let p = prepare(FOREIGN_BAG, &opts(None, Some("slider"))).unwrap();
    assert!(
        matches!(&p.mode, InputMode::Topics { velocity, .. } if velocity == "/joint_states"),
        "{:?}",
        p.mode
    );
    // TwistStamped: linear.x at 100 Hz, header stamps.
    let p = prepare(FOREIGN_BAG, &opts(Some("/cmd_vel"), None)).unwrap();
    assert!(matches!(
        &p.mode,
        InputMode::Topics {
            kind: SampleKind::TwistLinearX,
            ..
        }
    ));
    assert_eq!(p.velocity_messages, 201);
    assert_eq!(
        p.commands
            .iter()
            .filter(|c| c.kind == CommandKind::Velocity)
            .count(),
        2001
    );
    let e = prepare(FOREIGN_BAG, &opts(Some("/diagnostics_text"), None)).unwrap_err();
    assert!(
        matches!(e, ReplayError::Bag(BagError::UnsupportedType { .. })),
        "{e}"
    );
    assert!(e.to_string().contains("std_msgs/msg/String"), "{e}");
    let e = prepare(FOREIGN_BAG, &opts(Some("/nope"), None)).unwrap_err();
    assert!(
        e.to_string().contains("`/nope` is not in the bag") && e.to_string().contains("/cmd_vel"),
        "{e}"
    );
}

#[test]
fn a_bag_without_a_velocity_topic_lists_what_it_has() {
    let d = dir("none");
    let bag = d.join("strings.mcap");
    let text = msgs::to_cdr(&"hello".to_string()).unwrap();
    write_bag(
        &bag,
        &[("/chatter", "std_msgs/msg/String", "string data\n")],
        &[(0, text)],
    );
    let e = prepare(bag.to_str().unwrap(), &ReplayOptions::default()).unwrap_err();
    let m = e.to_string();
    assert!(matches!(e, ReplayError::NoVelocityTopic { .. }), "{m}");
    assert!(
        m.contains("/chatter") && m.contains("std_msgs/msg/String") && m.contains("1 messages"),
        "{m}"
    );
    let out = d.join("out.csv");
    let (code, _, err) = run(&[
        "replay",
        bag.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_ne!(code, 0);
    assert!(err.contains("/chatter"), "{err}");
    assert!(!out.exists());
}
