//! The node watches each contact's calibrated range: every estimate says
//! where its input lay (`calibrated_range`), `node.outside_envelope` says
//! what is published outside (warn, hold, zero, also changed live), and
//! the steps outside are counted in the run summary and the statistics.

use friction_node::config::parameters::{apply_set, declare};
use friction_node::config::{CalibratedRange, Config, OutsideEnvelope, StepMode};
use friction_node::link::{LiveStatus, ParameterChannel, ParameterUpdate};
use friction_node::msgs::ros_interfaces::{parameter_type, ParameterValue};
use friction_node::msgs::{estimate_constants as codes, Command, CommandKind, EstimateRecord};
use friction_node::node::Loop;
use friction_node::transport::memory::MemoryQueues;
use friction_node::transport::PeerPort;
use std::sync::Arc;

/// Calibrated at 0.05–0.35 m/s forward, 0.05–0.3 backward, 15–25 kN.
fn range() -> CalibratedRange {
    CalibratedRange {
        speed_forward_min_m_s: Some(0.05),
        speed_forward_max_m_s: Some(0.35),
        speed_backward_min_m_s: Some(0.05),
        speed_backward_max_m_s: Some(0.3),
        load_min_n: Some(15_000.0),
        load_max_n: Some(25_000.0),
        training_rms_n: Some(1.0),
        training_samples: 100,
        ..Default::default()
    }
}

fn config(range: Option<CalibratedRange>, policy: OutsideEnvelope) -> Config {
    let mut c = Config::default();
    c.solver.cells = 32;
    c.node.step_mode = StepMode::Lockstep;
    c.node.statistics_rate_hz = 1000.0; // one LoopStatistics per step
    c.node.outside_envelope = policy;
    c.calibrated_range = range;
    c.validate().unwrap();
    c
}

/// The velocities fed, one per 1 ms step: inside, out past the top speed
/// (0.2 → 1.0 m/s), back inside, then backward past its range.
fn velocities() -> Vec<f64> {
    let mut v = vec![0.2; 20];
    v.extend(std::iter::repeat_n(1.0, 20));
    v.extend(std::iter::repeat_n(0.2, 20));
    v.extend(std::iter::repeat_n(-0.6, 10));
    v
}

fn command(value: f64, k: usize) -> Command {
    Command {
        kind: CommandKind::Velocity,
        value,
        stamp_ns: (k as u64 + 1) * 1_000_000,
    }
}

/// The loop of `cfg` fed `v`: its estimates, statistics and loop.
fn feed(cfg: &Config, v: &[f64]) -> (Vec<EstimateRecord>, Loop, MemoryQueues) {
    let link = MemoryQueues::new(10_000);
    let mut peer = link.peer();
    let mut l = Loop::new(
        cfg,
        vec![Box::new(link.node())],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )
    .unwrap();
    for (k, x) in v.iter().enumerate() {
        l.feed(command(*x, k));
    }
    let est = std::iter::from_fn(|| peer.try_recv().unwrap()).collect();
    (est, l, link)
}

#[test]
fn every_estimate_says_whether_its_input_lay_inside_the_calibrated_range() {
    let (est, l, link) = feed(&config(Some(range()), OutsideEnvelope::Warn), &velocities());
    assert_eq!(est.len(), 70);
    let codes_of = |r: std::ops::Range<usize>| {
        est[r]
            .iter()
            .map(|e| e.calibrated_range)
            .collect::<Vec<_>>()
    };
    assert!(codes_of(0..20).iter().all(|c| *c == codes::RANGE_INSIDE));
    assert!(codes_of(20..40).iter().all(|c| *c == codes::RANGE_OUTSIDE));
    assert!(codes_of(40..60).iter().all(|c| *c == codes::RANGE_INSIDE));
    assert!(codes_of(60..70).iter().all(|c| *c == codes::RANGE_OUTSIDE));
    assert_eq!(l.summary().steps_outside_calibrated_range, 30);
    // The statistics carry the count and name the latest input outside;
    // a statistics period with no step outside names none.
    let stats = link.take_statistics();
    let last = stats.last().unwrap();
    assert_eq!(last.steps_outside_calibrated_range, 30);
    let o = last.last_outside.expect("the last step was outside");
    assert_eq!(
        (o.input, o.value, o.lo, o.hi),
        ("speed backward", 0.6, 0.05, 0.3)
    );
    let back_inside = &stats[45];
    assert_eq!(back_inside.steps_outside_calibrated_range, 20);
    assert_eq!(back_inside.last_outside, None);
}

#[test]
fn without_a_calibrated_range_nothing_is_watched_and_nothing_changes() {
    let (plain, l, _) = feed(&config(None, OutsideEnvelope::Zero), &velocities());
    assert!(plain
        .iter()
        .all(|e| e.calibrated_range == codes::RANGE_NOT_WATCHED));
    assert_eq!(l.summary().steps_outside_calibrated_range, 0);
    // warn publishes the model's value: the same numbers as unwatched.
    let (warn, _, _) = feed(&config(Some(range()), OutsideEnvelope::Warn), &velocities());
    for (a, b) in plain.iter().zip(&warn) {
        assert_eq!(a.friction_force_n.to_bits(), b.friction_force_n.to_bits());
        assert_eq!(a.h0_m.to_bits(), b.h0_m.to_bits());
    }
}

#[test]
fn hold_publishes_what_the_model_gives_at_the_nearest_edge_of_the_range() {
    let (hold, _, _) = feed(&config(Some(range()), OutsideEnvelope::Hold), &velocities());
    // The same loop without a range, fed the clamped velocities.
    let clamped: Vec<f64> = velocities()
        .iter()
        .map(|v| if *v > 0.0 { v.min(0.35) } else { v.max(-0.3) })
        .collect();
    let (edge, _, _) = feed(&config(None, OutsideEnvelope::Warn), &clamped);
    for (k, (a, b)) in hold.iter().zip(&edge).enumerate() {
        assert_eq!(
            a.friction_force_n.to_bits(),
            b.friction_force_n.to_bits(),
            "step {k}"
        );
    }
    assert_eq!(hold[30].velocity_m_s, 0.35, "the model ran at the edge");
    assert_eq!(hold[30].calibrated_range, codes::RANGE_OUTSIDE);
}

#[test]
fn zero_publishes_no_feed_forward_outside_and_the_model_inside() {
    let (zero, _, _) = feed(&config(Some(range()), OutsideEnvelope::Zero), &velocities());
    let (warn, _, _) = feed(&config(Some(range()), OutsideEnvelope::Warn), &velocities());
    for (k, (z, w)) in zero.iter().zip(&warn).enumerate() {
        if w.calibrated_range == codes::RANGE_OUTSIDE {
            assert_eq!(z.friction_force_n, 0.0, "step {k}");
            assert_eq!(z.contact_friction_force_n, 0.0, "step {k}");
            assert!(w.friction_force_n != 0.0);
        } else {
            assert_eq!(z.friction_force_n, w.friction_force_n, "step {k}");
        }
        // The model itself ran at the input: the film is the same.
        assert_eq!(z.h0_m.to_bits(), w.h0_m.to_bits(), "step {k}");
    }
}

#[test]
fn the_policy_changes_live_from_the_next_step() {
    let cfg = config(Some(range()), OutsideEnvelope::Warn);
    let link = MemoryQueues::new(1000);
    let mut peer = link.peer();
    let ch = Arc::new(ParameterChannel::default());
    let mut l = Loop::new(
        &cfg,
        vec![Box::new(link.node())],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )
    .unwrap()
    .with_parameters(ch.clone());
    for k in 0..5 {
        l.feed(command(1.0, k));
    }
    let changes = vec![(
        "node.outside_envelope".to_string(),
        ParameterValue {
            r#type: parameter_type::STRING,
            string_value: "zero".into(),
            ..Default::default()
        },
    )];
    let new = apply_set(&cfg, &declare(&cfg), &changes).unwrap();
    ch.submit(ParameterUpdate::prepare(&cfg, new, changes).unwrap())
        .unwrap();
    for k in 5..10 {
        l.feed(command(1.0, k));
    }
    let est: Vec<_> = std::iter::from_fn(|| peer.try_recv().unwrap()).collect();
    assert!(est[..5].iter().all(|e| e.friction_force_n != 0.0));
    assert!(est[5..].iter().all(|e| e.friction_force_n == 0.0));
}
