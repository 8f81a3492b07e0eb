//! Topics of a bag as a measurement table.
//!
//! The friction samples set the grid (they are the measurement); the
//! velocity is interpolated linearly at their stamps (samples outside the
//! velocity's span are dropped), the load and the temperature are held
//! (the latest value at or before the stamp; the first one before it).
//! Columns: `t_s` (from the first friction sample), `velocity_m_s`,
//! `friction_n`, and `load_n`, `temperature_c` when their topics are given.

use super::FitError;
use crate::bag::{read_topics, Bag, BagError, SampleKind, TopicDecoder};
use crate::table::Table;
use std::path::Path;

/// Which topics hold what.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BagTopics {
    /// The velocity topic.
    pub velocity: String,
    /// `std_msgs/msg/Float64`, or `sensor_msgs/msg/JointState` effort.
    pub friction: String,
    /// The joint of JointState topics (optional when there is one).
    pub joint: Option<String>,
    /// `std_msgs/msg/Float64`, N (default: as replay, a Float64 topic
    /// ending in `normal_load`, if the bag has one).
    pub load: Option<String>,
    /// `sensor_msgs/msg/Temperature`, °C (default: as replay, a Temperature
    /// topic ending in `temperature`, if the bag has one).
    pub temperature: Option<String>,
    /// A rotary joint's data (rad/s): a velocity in m/s is refused.
    pub rotary: bool,
}

fn friction_kind(schema: &str, joint: Option<&str>) -> Option<SampleKind> {
    match schema {
        "std_msgs/msg/Float64" => Some(SampleKind::Float64),
        "sensor_msgs/msg/JointState" => Some(SampleKind::JointEffort(
            joint.unwrap_or_default().to_string(),
        )),
        _ => None,
    }
}

fn held(samples: &[(u64, f64)], stamp: u64, j: &mut usize) -> f64 {
    while *j + 1 < samples.len() && samples[*j + 1].0 <= stamp {
        *j += 1;
    }
    samples[*j].1
}

/// Read the topics of `path` into a table; the second value notes damage
/// (reading stopped there; the table holds what came before). The load and
/// temperature topics default as in replay; the topics used are returned.
pub fn read(
    path: &Path,
    topics: &BagTopics,
) -> Result<(Table, Option<String>, BagTopics), FitError> {
    let bag = Bag::open(path)?;
    let scan = bag.scan()?;
    let mut topics = topics.clone();
    if topics.load.is_none() {
        topics.load = crate::bag::decode::default_load_topic(&scan);
    }
    if topics.temperature.is_none() {
        topics.temperature = crate::bag::decode::default_temperature_topic(&scan);
    }
    let mut decoders = decoders(&scan, &topics)?;
    let mut read = read_topics(&bag, &mut decoders)?;
    for s in &mut read.samples {
        s.sort_by_key(|x| x.0);
    }
    // The samples of every given topic, in the order velocity, friction,
    // load, temperature (absent topics left out).
    let named = [
        ("velocity", Some(&topics.velocity)),
        ("friction", Some(&topics.friction)),
        ("load", topics.load.as_ref()),
        ("temperature", topics.temperature.as_ref()),
    ];
    let given = named.iter().filter_map(|(name, t)| t.map(|t| (*name, t)));
    for ((name, t), samples) in given.zip(&read.samples) {
        if samples.is_empty() {
            return Err(FitError::Data {
                what: format!("{} ({name} topic `{t}`)", path.display()),
                message: "no message could be read".into(),
            });
        }
    }
    let (names, columns) = on_friction_grid(path, &topics, &read.samples)?;
    let note = read
        .damage
        .map(|d| format!("{}: reading stopped {d}", path.display()));
    Ok((Table::from_columns(path, names, columns), note, topics))
}

/// Decoders of the given topics: velocity, friction, then load and
/// temperature when given. A TwistStamped velocity with `--rotary` is
/// refused (m/s is not a joint's rad/s).
fn decoders(scan: &crate::bag::BagScan, topics: &BagTopics) -> Result<Vec<TopicDecoder>, FitError> {
    let joint = topics.joint.as_deref();
    let vc = scan.require(&topics.velocity)?;
    let vkind = SampleKind::velocity_for(&vc.schema_name, joint).ok_or_else(|| {
        BagError::UnsupportedType {
            topic: vc.topic.clone(),
            type_name: vc.schema_name.clone(),
            expected: crate::bag::decode::VELOCITY_TYPES.into(),
        }
    })?;
    if topics.rotary && vc.schema_name == "geometry_msgs/msg/TwistStamped" {
        return Err(FitError::Data {
            what: format!("--rotary, topic {}", vc.topic),
            message: "is a geometry_msgs/msg/TwistStamped, a linear velocity in m/s; a rotary joint's velocity is in rad/s (a sensor_msgs/msg/JointState topic with --joint): drop --rotary to fit it as a linear axis".into(),
        });
    }
    let fc = scan.require(&topics.friction)?;
    let fkind = friction_kind(&fc.schema_name, joint).ok_or_else(|| BagError::UnsupportedType {
        topic: fc.topic.clone(),
        type_name: fc.schema_name.clone(),
        expected: "std_msgs/msg/Float64 or sensor_msgs/msg/JointState (effort)".into(),
    })?;
    let mut decoders = vec![TopicDecoder::new(vc, vkind)?, TopicDecoder::new(fc, fkind)?];
    if let Some(l) = &topics.load {
        decoders.push(TopicDecoder::new(scan.require(l)?, SampleKind::Float64)?);
    }
    if let Some(t) = &topics.temperature {
        decoders.push(TopicDecoder::new(
            scan.require(t)?,
            SampleKind::Temperature,
        )?);
    }
    Ok(decoders)
}

/// The columns on the friction samples' stamps (within the velocity's
/// span): time from the first, the velocity interpolated, the friction,
/// the load and temperature held. `samples` as `read` orders them.
fn on_friction_grid(
    path: &Path,
    topics: &BagTopics,
    samples: &[Vec<(u64, f64)>],
) -> Result<(Vec<String>, Vec<Vec<f64>>), FitError> {
    let vel = &samples[0];
    let (v_first, v_last) = (vel[0].0, vel[vel.len() - 1].0);
    let grid: Vec<(u64, f64)> = samples[1]
        .iter()
        .copied()
        .filter(|(s, _)| (v_first..=v_last).contains(s))
        .collect();
    let Some(&(t0, _)) = grid.first() else {
        return Err(FitError::Data {
            what: path.display().to_string(),
            message: format!(
                "no friction sample on `{}` lies within the span of the velocity on `{}`",
                topics.friction, topics.velocity
            ),
        });
    };
    let mut columns: Vec<Vec<f64>> = (0..3).map(|_| Vec::with_capacity(grid.len())).collect();
    let mut j = 0usize;
    for &(stamp, f) in &grid {
        while j + 2 < vel.len() && vel[j + 1].0 <= stamp {
            j += 1;
        }
        let v = if vel.len() == 1 {
            vel[0].1
        } else {
            let (a, b) = (vel[j], vel[j + 1]);
            let w = if b.0 > a.0 {
                (stamp.saturating_sub(a.0)) as f64 / (b.0 - a.0) as f64
            } else {
                1.0
            };
            a.1 + w.clamp(0.0, 1.0) * (b.1 - a.1)
        };
        columns[0].push((stamp - t0) as f64 / 1e9);
        columns[1].push(v);
        columns[2].push(f);
    }
    let mut names = vec![
        "t_s".to_string(),
        "velocity_m_s".into(),
        "friction_n".into(),
    ];
    // The held columns: the samples after velocity and friction, in order.
    let held_topics = [
        ("load_n", topics.load.is_some()),
        ("temperature_c", topics.temperature.is_some()),
    ];
    let present = held_topics.iter().filter(|(_, given)| *given);
    for ((name, _), s) in present.zip(&samples[2..]) {
        let mut j = 0;
        columns.push(grid.iter().map(|(st, _)| held(s, *st, &mut j)).collect());
        names.push((*name).into());
    }
    Ok((names, columns))
}
