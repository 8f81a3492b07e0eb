//! Validation of the I/O sections (`node`, `ros`, `iceoryx2`, `recording`):
//! ranges, ROS 2 names, and the memory the snapshot ring needs. Errors name
//! the key, the value and the allowed range (or the rule broken); the model
//! sections are in `validate.rs`.

use super::ros_names::{check_namespace, check_node_name, check_topic};
use super::validate::{cc, oc};
use super::{Config, ConfigError};

impl Config {
    pub(super) fn validate_node(&self) -> Result<(), ConfigError> {
        let n = &self.node;
        oc(
            "node.max_abs_velocity_m_s",
            n.max_abs_velocity_m_s,
            0.0,
            100.0,
        )?;
        let vmax = n.max_abs_velocity_m_s;
        cc(
            "node.initial_velocity_m_s",
            n.initial_velocity_m_s,
            -vmax,
            vmax,
        )?;
        oc("node.command_timeout_s", n.command_timeout_s, 0.0, 3600.0)?;
        oc(
            "node.timeout_deceleration_m_s2",
            n.timeout_deceleration_m_s2,
            0.0,
            1e4,
        )?;
        oc("node.min_load_n", n.min_load_n, 0.0, 1e9)?;
        cc("node.max_load_n", n.max_load_n, n.min_load_n, 1e9)?;
        cc("node.profile_rate_hz", n.profile_rate_hz, 0.0, 1000.0)?;
        oc("node.statistics_rate_hz", n.statistics_rate_hz, 0.0, 1000.0)?;
        cc("node.queue_capacity", n.queue_capacity as f64, 16.0, 1e7)?;
        cc("node.lockstep_spin_us", n.lockstep_spin_us as f64, 0.0, 1e6)?;
        cc("node.timer_spin_us", n.timer_spin_us as f64, 0.0, 1e6)?;
        cc("node.max_catch_up_s", n.max_catch_up_s, 0.0, 60.0)?;
        cc(
            "node.realtime.priority",
            n.realtime.priority as f64,
            1.0,
            99.0,
        )?;
        cc("node.realtime.cpu", n.realtime.cpu as f64, -1.0, 4095.0)?;
        for (i, cpu) in n.realtime.worker_cpus.iter().enumerate() {
            cc(
                &format!("node.realtime.worker_cpus[{i}]"),
                f64::from(*cpu),
                0.0,
                4095.0,
            )?;
        }
        let contacts = self.contacts.0.len().max(1);
        if n.contact_workers >= contacts && n.contact_workers > 0 {
            return Err(ConfigError::InvalidValue {
                key: "node.contact_workers".into(),
                message: format!(
                    "{} workers for {contacts} contact(s): at most {} (one fewer than the contacts; the loop's thread steps a share too)",
                    n.contact_workers,
                    contacts - 1
                ),
            });
        }
        if n.frame_id.chars().any(|c| c.is_control()) {
            return Err(ConfigError::InvalidValue {
                key: "node.frame_id".into(),
                message: format!("{:?} contains a control character", n.frame_id),
            });
        }
        Ok(())
    }

    pub(super) fn validate_ros(&self) -> Result<(), ConfigError> {
        let r = &self.ros;
        cc("ros.domain_id", r.domain_id as f64, -1.0, 232.0)?;
        for (key, q) in [
            ("ros.qos.commands.depth", &r.qos.commands),
            ("ros.qos.estimates.depth", &r.qos.estimates),
        ] {
            cc(key, q.depth as f64, 1.0, 1e6)?;
        }
        let name = |key: &str, value: &str, rule: Result<(), &'static str>| {
            rule.map_err(|rule| ConfigError::InvalidValue {
                key: key.into(),
                message: format!("`{value}` is not a valid ROS 2 name: {rule}"),
            })
        };
        name("ros.node_name", &r.node_name, check_node_name(&r.node_name))?;
        name("ros.namespace", &r.namespace, check_namespace(&r.namespace))?;
        for (i, rule) in r.remappings.iter().enumerate() {
            let key = format!("ros.remappings[{i}]");
            let Some((from, to)) = rule.split_once(":=") else {
                return Err(ConfigError::InvalidValue {
                    key,
                    message: format!("`{rule}` is not FROM:=TO"),
                });
            };
            name(&key, from, check_topic(from))?;
            name(&key, to, check_topic(to))?;
        }
        let t = &r.topics;
        for (key, value) in [
            ("ros.topics.cmd_velocity", &t.cmd_velocity),
            ("ros.topics.normal_load", &t.normal_load),
            ("ros.topics.temperature", &t.temperature),
            ("ros.topics.friction", &t.friction),
            ("ros.topics.friction_force", &t.friction_force),
            ("ros.topics.film_profile", &t.film_profile),
            ("ros.topics.loop_statistics", &t.loop_statistics),
            ("ros.topics.joint_commands", &t.joint_commands),
            ("ros.topics.joint_efforts", &t.joint_efforts),
            ("ros.topics.joint_friction", &t.joint_friction),
            ("ros.topics.contact_friction", &t.contact_friction),
        ] {
            name(key, value, check_topic(value))?;
        }
        Ok(())
    }

    pub(super) fn validate_iceoryx2(&self) -> Result<(), ConfigError> {
        let i = &self.iceoryx2;
        for (key, value) in [
            ("iceoryx2.cmd_velocity_service", &i.cmd_velocity_service),
            ("iceoryx2.normal_load_service", &i.normal_load_service),
            ("iceoryx2.temperature_service", &i.temperature_service),
            ("iceoryx2.friction_service", &i.friction_service),
            (
                "iceoryx2.loop_statistics_service",
                &i.loop_statistics_service,
            ),
            ("iceoryx2.cmd_event_service", &i.cmd_event_service),
            ("iceoryx2.joint_state_service", &i.joint_state_service),
            ("iceoryx2.efforts_service", &i.efforts_service),
            (
                "iceoryx2.contact_friction_service",
                &i.contact_friction_service,
            ),
        ] {
            if value.is_empty() || value.len() > 255 || value.chars().any(char::is_whitespace) {
                return Err(ConfigError::InvalidValue {
                    key: key.into(),
                    message: format!(
                        "`{value}` is not a valid iceoryx2 service name: 1 to 255 characters, no whitespace"
                    ),
                });
            }
        }
        Ok(())
    }

    pub(super) fn validate_recording(&self) -> Result<(), ConfigError> {
        let r = &self.recording;
        cc(
            "recording.chunk_size_bytes",
            r.chunk_size_bytes as f64,
            1024.0,
            1e9,
        )?;
        let bad = |key: &str, message: String| {
            Err(ConfigError::InvalidValue {
                key: key.into(),
                message,
            })
        };
        if r.split.max_bytes > 0 && r.split.max_bytes < r.chunk_size_bytes {
            return bad(
                "recording.split.max_bytes",
                format!(
                    "{} bytes is smaller than one chunk (recording.chunk_size_bytes = {})",
                    r.split.max_bytes, r.chunk_size_bytes
                ),
            );
        }
        cc(
            "recording.split.max_duration_s",
            r.split.max_duration_s as f64,
            0.0,
            1e7,
        )?;
        if r.budget_bytes > 0 {
            if !r.splits() {
                return bad(
                    "recording.budget_bytes",
                    "a disk budget needs split files (recording.split.max_bytes or max_duration_s)"
                        .into(),
                );
            }
            if r.split.max_bytes > 0 && r.budget_bytes < 2 * r.split.max_bytes {
                return bad(
                    "recording.budget_bytes",
                    format!(
                        "{} bytes holds less than two split files of recording.split.max_bytes = {} (the one being written and one finished)",
                        r.budget_bytes, r.split.max_bytes
                    ),
                );
            }
        }
        cc("recording.snapshot_s", r.snapshot_s as f64, 0.0, 86_400.0)?;
        cc(
            "recording.snapshot_max_bytes",
            r.snapshot_max_bytes as f64,
            1e6,
            1e12,
        )?;
        let need = snapshot_bytes(self);
        if need > r.snapshot_max_bytes {
            return bad(
                "recording.snapshot_s",
                format!(
                    "{} s of every topic needs about {} MB in memory, more than recording.snapshot_max_bytes = {} MB allows",
                    r.snapshot_s,
                    need / 1_000_000,
                    r.snapshot_max_bytes / 1_000_000
                ),
            );
        }
        Ok(())
    }
}

/// Memory the snapshot ring needs for `recording.snapshot_s` seconds of
/// every recorded topic, bytes: serialized sizes plus per-entry bookkeeping,
/// commands assumed to arrive once per step, and a 20 % margin.
pub fn snapshot_bytes(c: &Config) -> u64 {
    const ENTRY: f64 = 64.0;
    let steps = 1.0 / c.solver.dt_s;
    let frame = c.node.frame_id.len() as f64;
    let estimate = 4.0 + 16.0 + frame + 12.0 * 8.0 + 8.0 + 24.0 + ENTRY;
    let force = 12.0 + ENTRY;
    let command = 12.0 + 60.0 + frame + ENTRY;
    let profile = c.node.profile_rate_hz * (40.0 + frame + 16.0 * c.solver.cells as f64 + ENTRY);
    let stats = c.node.statistics_rate_hz * (300.0 + frame + ENTRY);
    let per_s = steps * (estimate + force + command) + profile + stats;
    (1.2 * per_s * c.recording.snapshot_s as f64) as u64
}
