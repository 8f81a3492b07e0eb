//! A step allocates nothing: a counting global allocator proves it.

use friction_node::physics::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    // Per thread: the test harness runs tests in parallel and allocates on
    // other threads. A const-initialised Cell needs no allocation itself.
    static ALLOCS: Cell<usize> = const { Cell::new(0) };
}

fn count() {
    let _ = ALLOCS.try_with(|c| c.set(c.get() + 1));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        count();
        unsafe { System.alloc(l) }
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) }
    }
    unsafe fn realloc(&self, p: *mut u8, l: Layout, n: usize) -> *mut u8 {
        count();
        unsafe { System.realloc(p, l, n) }
    }
}

#[global_allocator]
static A: Counting = Counting;

fn allocations(f: impl FnOnce()) -> usize {
    let before = ALLOCS.with(Cell::get);
    f();
    ALLOCS.with(Cell::get) - before
}

#[test]
fn the_counter_sees_allocations() {
    assert!(allocations(|| drop(std::hint::black_box(vec![1u8; 10]))) >= 1);
}

#[test]
fn newton_steps_allocate_nothing_through_reversals_and_vapour_collapse() {
    // The paper's reciprocating case (V1 1 m/s, f 1 Hz, 20 762 N), two cycles.
    let mut s = Solver::new(&ModelParams::default(), &SolverSettings::default()).unwrap();
    s.initialize_steady(0.0, 20_762.0);
    let mut worst = 0;
    let mut iterations = 0;
    for k in 1..=2000 {
        let v = (2.0 * std::f64::consts::PI * k as f64 * 1e-3).sin();
        let n = allocations(|| {
            let e = s.step(v, 20_762.0);
            iterations += e.diagnostics.iterations;
        });
        worst = worst.max(n);
    }
    assert_eq!(worst, 0, "a step allocated");
    assert!(
        iterations > 2000,
        "every step iterated at least once: {iterations}"
    );
    // Rejected input and the theta scheme's history bookkeeping too.
    assert_eq!(
        allocations(|| {
            s.step(f64::NAN, 20_762.0);
        }),
        0
    );
}

#[test]
fn steps_with_every_real_drive_term_on_allocate_nothing_through_reversals() {
    // Pre-sliding, a soft width, a rate-sensitive boundary film and the
    // drivetrain's losses, all on.
    let mut m = ModelParams::default();
    m.terms.presliding = Presliding {
        stiffness: 1e8,
        damping: 50.0,
    };
    m.terms.soft_width = WidthLaw {
        exponent: 0.5,
        reference_load: 20_762.0,
    };
    m.terms.boundary_rate = BoundaryRate {
        sensitivity: 0.01,
        activation_speed: 1e-3,
    };
    m.terms.drivetrain.quadratic = 300.0;
    m.terms.drivetrain.coulomb_asymmetry = 40.0;
    let mut s = Solver::new(
        &m,
        &SolverSettings {
            cells: 64,
            ..Default::default()
        },
    )
    .unwrap();
    s.initialize_steady(0.0, 20_762.0);
    let mut worst = 0;
    for k in 1..=1000 {
        let v = (2.0 * std::f64::consts::PI * 2.0 * k as f64 * 1e-3).sin();
        let f = 20_762.0 + 5000.0 * (std::f64::consts::PI * k as f64 * 1e-3).sin();
        let n = allocations(|| {
            let e = s.step(v, f);
            assert!(e.status.is_converged(), "step {k}: {:?}", e.status);
        });
        worst = worst.max(n);
    }
    assert_eq!(worst, 0, "a step allocated");
}

#[test]
fn muscl_flux_steps_allocate_nothing_through_reversals() {
    // The paper's case with the second-order flux (pentadiagonal solve).
    let st = SolverSettings {
        cells: 64,
        flux: CouetteFlux::Muscl(Limiter::VanLeer),
        ..Default::default()
    };
    let mut s = Solver::new(&ModelParams::default(), &st).unwrap();
    s.initialize_steady(0.0, 20_762.0);
    let mut worst = 0;
    let mut iterations = 0;
    for k in 1..=2000 {
        let v = (2.0 * std::f64::consts::PI * k as f64 * 1e-3).sin();
        worst = worst.max(allocations(|| {
            let e = s.step(v, 20_762.0);
            assert_eq!(e.status, Status::Converged, "step {k}");
            iterations += e.diagnostics.iterations;
        }));
    }
    assert_eq!(worst, 0, "a step allocated");
    assert!(iterations > 2000, "every step iterated: {iterations}");
}

#[test]
fn theta_scheme_steady_solves_and_reference_steps_allocate_nothing() {
    let st = SolverSettings {
        cells: 64,
        scheme: TimeScheme::PAPER,
        ..Default::default()
    };
    let mut s = Solver::new(&ModelParams::default(), &st).unwrap();
    s.initialize_steady(0.2, 20_762.0);
    assert_eq!(
        allocations(|| for k in 0..200 {
            s.step(0.2 + 1e-3 * k as f64, 20_762.0);
        }),
        0
    );
    // Steady solves, including a cold continuation to high speed.
    let mut s = Solver::new(
        &ModelParams::default(),
        &SolverSettings {
            cells: 64,
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(
        allocations(|| {
            s.steady(4.5, 20_762.0);
        }),
        0
    );
    let st = SolverSettings {
        cells: 16,
        method: Method::Reference,
        flux: CouetteFlux::Upwind,
        ..Default::default()
    };
    let mut r = Solver::new(&ModelParams::default(), &st).unwrap();
    r.initialize_steady(0.0, 20_762.0);
    assert_eq!(
        allocations(|| for _ in 0..3 {
            r.step(0.05, 20_762.0);
        }),
        0
    );
}

#[test]
fn the_loop_allocates_nothing_while_a_transport_refuses_every_output_for_ten_minutes() {
    use friction_node::clock::SimClock;
    use friction_node::config::{Config, StepMode};
    use friction_node::link::LiveStatus;
    use friction_node::msgs::{Command, CommandKind};
    use friction_node::node::Loop;
    use friction_node::transport::memory::MemoryQueues;
    use friction_node::transport::PeerPort;
    use std::sync::atomic::AtomicBool;
    use std::sync::Arc;
    use std::time::Duration;
    let mut cfg = Config::default();
    cfg.solver.cells = 8;
    cfg.node.step_mode = StepMode::Timer;
    cfg.node.profile_rate_hz = 0.0;
    // Nobody reads: the estimate queue is full after 16 steps, statistics
    // overwrite each other.
    let link = MemoryQueues::new(16);
    link.peer()
        .send(&Command {
            kind: CommandKind::Velocity,
            value: 0.3,
            stamp_ns: 1,
        })
        .unwrap();
    let clock = Arc::new(SimClock::new(1_763_900_000_000_000_000));
    let mut l = Loop::new(
        &cfg,
        vec![Box::new(link.node())],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )
    .unwrap()
    .with_clock(clock);
    let stop = AtomicBool::new(false);
    l.run(&stop, Some(Duration::from_secs(1)));
    let mut steps = 0;
    let n = allocations(|| {
        steps = l.run(&stop, Some(Duration::from_secs(600))).steps;
    });
    assert_eq!(steps, 601_000, "the loop kept its pace");
    assert_eq!(n, 0, "{n} allocations in ten simulated minutes");
}

#[test]
fn a_prepared_model_swaps_in_between_two_steps_without_allocating() {
    let model = ModelParams::default();
    let settings = SolverSettings {
        cells: 64,
        ..Default::default()
    };
    let mut s = Solver::new(&model, &settings).unwrap();
    s.initialize_steady(0.05, 20_762.0);
    let before = s.step(0.05, 20_762.0);
    // Boundary friction halved, rougher surfaces, a thicker oil: built here,
    // off the "loop".
    let mut changed = model.clone();
    changed.terms.boundary_film.friction = 0.15;
    changed.roughness.sigma = 6e-6;
    changed.lubricant.viscosity = 0.08;
    let mut prepared = Solver::prepare_model(&changed, &settings).unwrap();
    let n = allocations(|| s.swap_model(&mut prepared).unwrap());
    assert_eq!(n, 0, "the swap allocates nothing");
    let mut after = s.step(0.05, 20_762.0);
    for _ in 0..200 {
        after = s.step(0.05, 20_762.0);
    }
    assert!(after.status.is_converged());
    // Mostly boundary friction at 5 cm/s: halving mu_bl about halves it.
    let ratio = after.friction_force / before.friction_force;
    assert!((0.4..0.65).contains(&ratio), "ratio {ratio}");
    // Swapping back restores the original numbers at the steady state.
    s.swap_model(&mut prepared).unwrap();
    let mut back = s.step(0.05, 20_762.0);
    for _ in 0..3000 {
        back = s.step(0.05, 20_762.0);
    }
    let steady = Solver::new(&model, &settings)
        .unwrap()
        .initialize_steady(0.05, 20_762.0);
    approx::assert_relative_eq!(
        back.friction_force,
        steady.friction_force,
        max_relative = 1e-5
    );
    // Another geometry cannot be swapped in.
    let mut other = model.clone();
    other.geometry.length *= 2.0;
    let mut wrong = Solver::prepare_model(&other, &settings).unwrap();
    assert!(s.swap_model(&mut wrong).is_err());
}

#[test]
fn a_parameter_change_is_applied_by_the_loop_between_two_steps_without_allocating() {
    use friction_node::config::parameters::{apply_set, declare};
    use friction_node::config::{Config, StepMode};
    use friction_node::link::LiveStatus;
    use friction_node::link::{ParameterChannel, ParameterUpdate};
    use friction_node::msgs::ros_interfaces::{parameter_type, ParameterValue};
    use friction_node::msgs::{Command, CommandKind};
    use friction_node::node::Loop;
    use friction_node::transport::memory::MemoryQueues;
    use friction_node::transport::PeerPort;
    use std::sync::Arc;
    let mut cfg = Config::default();
    cfg.solver.cells = 32;
    cfg.node.step_mode = StepMode::Lockstep;
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
    let v = |k: u64| Command {
        kind: CommandKind::Velocity,
        value: 0.1,
        stamp_ns: k * 1_000_000,
    };
    for k in 1..=10 {
        l.feed(v(k));
    }
    let double = |x: f64| ParameterValue {
        r#type: parameter_type::DOUBLE,
        double_value: x,
        ..Default::default()
    };
    let changes = vec![
        ("contact.load_n".to_string(), double(5762.0)),
        ("contact.boundary_friction".to_string(), double(0.15)),
    ];
    let new = apply_set(&cfg, &declare(&cfg), &changes).unwrap();
    // Prepared here, off the loop.
    ch.submit(ParameterUpdate::prepare(&cfg, new, changes).unwrap())
        .unwrap();
    let n = allocations(|| l.feed(v(11)));
    assert_eq!(n, 0, "the step that applies the change allocates nothing");
    for k in 12..=20 {
        l.feed(v(k));
    }
    let est: Vec<_> = std::iter::from_fn(|| peer.try_recv().unwrap()).collect();
    assert_eq!(est.len(), 20);
    assert!(est[..10].iter().all(|e| e.load_n == 20_762.0));
    assert!(
        est[10..].iter().all(|e| e.load_n == 5762.0),
        "from the next step on"
    );
    let applied = ch.take_applied().expect("handed back");
    assert_eq!(
        applied.applied_stamp_ns, 11_000_000,
        "stamped with its first step"
    );
    assert_eq!(l.summary().parameter_updates, 1);
    // Lower load and half the boundary friction: much less friction.
    assert!(est[19].friction_force_n < 0.5 * est[9].friction_force_n);
}

#[test]
fn a_loop_of_several_contacts_allocates_nothing_per_joint_state() {
    use friction_node::config::{Config, Origin};
    use friction_node::link::LiveStatus;
    use friction_node::node::Loop;
    use friction_node::transport::memory::MemoryQueues;
    use friction_node::transport::{JointStateCommand, PeerPort};
    use std::sync::Arc;
    let cfg = Config::from_yaml(
        "/**:
  ros__parameters:
    solver: {cells: 8}
    node: {step_mode: lockstep, profile_rate_hz: 0.0}
    contacts:
      a: {joint: ja}
      b: {joint: jb, gain: 0.1}
      c: {joint: jc, solver: {cells: 16}}
",
        &Origin::Embedded,
        &[],
    )
    .unwrap();
    let joints = vec!["ja".to_string(), "jb".to_string(), "jc".to_string()];
    // Nobody reads: the output queues fill up, and a full queue is a
    // counted drop, never an allocation.
    let link =
        MemoryQueues::new(64).for_plan(&friction_node::config::OutputPlan::Joints(joints.clone()));
    let mut peer = link.peer();
    let mut l = Loop::new(
        &cfg,
        vec![Box::new(link.node())],
        None,
        None,
        Arc::new(LiveStatus::default()),
    )
    .unwrap();
    let mut steps = 0;
    let mut worst = 0;
    for batch in 0..20u64 {
        // 20 JointStates (60 commands) sent outside the counted region.
        for i in 0..20u64 {
            let k = batch * 20 + i + 1;
            let v = (k as f64 * 0.01).sin();
            peer.send_joint_state(&JointStateCommand {
                stamp_ns: k,
                name: joints.clone(),
                velocity: vec![v, -v, 0.5 * v],
            })
            .unwrap();
        }
        worst = worst.max(allocations(|| {
            l.poll_once();
        }));
        steps = l.summary().steps;
    }
    assert_eq!(steps, 400, "one step per JointState");
    assert_eq!(
        worst, 0,
        "{worst} allocations in a batch of 20 steps of 3 contacts"
    );
}

#[test]
fn the_calibrated_range_watch_allocates_nothing_inside_outside_or_holding() {
    use friction_node::config::{CalibratedRange, Config, OutsideEnvelope, StepMode};
    use friction_node::link::LiveStatus;
    use friction_node::msgs::{Command, CommandKind};
    use friction_node::node::Loop;
    use friction_node::transport::memory::MemoryQueues;
    use std::sync::Arc;
    for policy in [
        OutsideEnvelope::Warn,
        OutsideEnvelope::Hold,
        OutsideEnvelope::Zero,
    ] {
        let mut cfg = Config::default();
        cfg.solver.cells = 32;
        cfg.node.step_mode = StepMode::Lockstep;
        cfg.node.statistics_rate_hz = 1000.0;
        cfg.node.outside_envelope = policy;
        cfg.calibrated_range = Some(CalibratedRange {
            speed_forward_min_m_s: Some(0.0),
            speed_forward_max_m_s: Some(0.3),
            speed_backward_min_m_s: Some(0.0),
            speed_backward_max_m_s: Some(0.3),
            training_rms_n: Some(1.0),
            training_samples: 10,
            ..Default::default()
        });
        let link = MemoryQueues::new(1000);
        let mut l = Loop::new(
            &cfg,
            vec![Box::new(link.node())],
            None,
            None,
            Arc::new(LiveStatus::default()),
        )
        .unwrap();
        let v = |k: u64, value: f64| Command {
            kind: CommandKind::Velocity,
            value,
            stamp_ns: k * 1_000_000,
        };
        for k in 1..=5 {
            l.feed(v(k, 0.1));
        }
        let mut worst = 0;
        for k in 6..=40 {
            // In, out forward, out backward, back in.
            let x = [0.1, 0.9, -0.9, 0.2][(k % 4) as usize];
            worst = worst.max(allocations(|| l.feed(v(k, x))));
        }
        assert_eq!(worst, 0, "{policy:?}");
        assert!(l.summary().steps_outside_calibrated_range > 10);
    }
}
