//! Validation: the physical range of every key and the ROS 2 naming rules,
//! one small function per section. Errors name the key, the value and the
//! allowed range (or the rule broken).

use super::{Config, ConfigError, FluxKind, MethodKind};
use crate::text::Num;

/// One end of an allowed interval.
#[derive(Clone, Copy)]
enum End {
    /// The value may equal it.
    Closed(f64),
    /// The value must not equal it.
    Open(f64),
}

/// The documented range of one numeric key (see [`key_ranges`]).
#[derive(Debug, Clone, PartialEq)]
pub struct KeyRange {
    pub key: String,
    pub lo: f64,
    pub lo_open: bool,
    pub hi: f64,
    pub hi_open: bool,
}

impl std::fmt::Display for KeyRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}{}, {}{}",
            if self.lo_open { '(' } else { '[' },
            Num(self.lo),
            Num(self.hi),
            if self.hi_open { ')' } else { ']' }
        )
    }
}

thread_local! {
    static COLLECT: std::cell::RefCell<Option<Vec<KeyRange>>> = const { std::cell::RefCell::new(None) };
}

/// The range of every numeric key that [`Config::validate`] checks, as it
/// checks them on the default configuration (ranges that depend on another
/// key are given at its default value).
pub fn key_ranges() -> Vec<KeyRange> {
    COLLECT.with(|c| *c.borrow_mut() = Some(Vec::new()));
    let _ = Config::default().validate();
    let mut v = COLLECT.with(|c| c.borrow_mut().take()).unwrap_or_default();
    let mut seen = std::collections::HashSet::new();
    v.retain(|r| seen.insert(r.key.clone()));
    v
}

fn check(key: &str, value: f64, lo: End, hi: End) -> Result<(), ConfigError> {
    COLLECT.with(|c| {
        if let Some(v) = c.borrow_mut().as_mut() {
            let (lo, lo_open) = match lo {
                End::Closed(l) => (l, false),
                End::Open(l) => (l, true),
            };
            let (hi, hi_open) = match hi {
                End::Closed(h) => (h, false),
                End::Open(h) => (h, true),
            };
            v.push(KeyRange {
                key: key.to_string(),
                lo,
                lo_open,
                hi,
                hi_open,
            });
        }
    });
    let above = match lo {
        End::Closed(l) => value >= l,
        End::Open(l) => value > l,
    };
    let below = match hi {
        End::Closed(h) => value <= h,
        End::Open(h) => value < h,
    };
    if value.is_finite() && above && below {
        return Ok(());
    }
    let (lb, l) = match lo {
        End::Closed(l) => ('[', l),
        End::Open(l) => ('(', l),
    };
    let (hb, h) = match hi {
        End::Closed(h) => (']', h),
        End::Open(h) => (')', h),
    };
    Err(ConfigError::OutOfRange {
        key: key.to_string(),
        value: format!("{value}"),
        range: format!("{lb}{}, {}{hb}", Num(l), Num(h)),
    })
}

/// (lo, hi]
fn oc(key: &str, v: f64, lo: f64, hi: f64) -> Result<(), ConfigError> {
    check(key, v, End::Open(lo), End::Closed(hi))
}

/// [lo, hi]
fn cc(key: &str, v: f64, lo: f64, hi: f64) -> Result<(), ConfigError> {
    check(key, v, End::Closed(lo), End::Closed(hi))
}

/// [lo, hi)
fn co(key: &str, v: f64, lo: f64, hi: f64) -> Result<(), ConfigError> {
    check(key, v, End::Closed(lo), End::Open(hi))
}

/// (lo, hi)
fn oo(key: &str, v: f64, lo: f64, hi: f64) -> Result<(), ConfigError> {
    check(key, v, End::Open(lo), End::Open(hi))
}

impl Config {
    /// Physical ranges of every key, and ROS 2 names.
    pub fn validate(&self) -> Result<(), ConfigError> {
        self.validate_contact()?;
        self.validate_texture()?;
        self.validate_lubricant()?;
        self.validate_roughness()?;
        self.validate_solver()?;
        self.validate_drivetrain()?;
        self.validate_node()?;
        self.validate_ros()?;
        self.validate_iceoryx2()?;
        self.validate_recording()?;
        self.validate_contacts()
    }

    pub(super) fn validate_contact(&self) -> Result<(), ConfigError> {
        let c = &self.contact;
        oc("contact.length_m", c.length_m, 1e-4, 10.0)?;
        oc("contact.width_m", c.width_m, 1e-4, 10.0)?;
        cc("contact.mass_kg", c.mass_kg, 0.0, 1e6)?;
        oc("contact.load_n", c.load_n, 0.0, 1e9)?;
        cc("contact.profile_depth_m", c.profile_depth_m, 0.0, 1e-3)?;
        cc("contact.boundary_friction", c.boundary_friction, 0.0, 2.0)?;
        oc(
            "contact.sign_regularization_m_s",
            c.sign_regularization_m_s,
            1e-9,
            1.0,
        )?;
        cc("contact.min_film_m", c.min_film_m, 0.0, 1e-3)?;
        cc(
            "contact.presliding_stiffness_n_m",
            c.presliding_stiffness_n_m,
            0.0,
            1e15,
        )?;
        cc(
            "contact.presliding_damping_n_s_m",
            c.presliding_damping_n_s_m,
            0.0,
            1e9,
        )?;
        cc(
            "contact.width_load_exponent",
            c.width_load_exponent,
            0.0,
            1.0,
        )?;
        oc(
            "contact.width_reference_load_n",
            c.width_reference_load_n,
            0.0,
            1e9,
        )
    }

    pub(super) fn validate_texture(&self) -> Result<(), ConfigError> {
        let t = &self.texture;
        let n = t.pocket_start_m.len();
        for (key, len) in [
            ("texture.pocket_width_m", t.pocket_width_m.len()),
            ("texture.pocket_depth_m", t.pocket_depth_m.len()),
        ] {
            if len != n {
                return Err(ConfigError::InvalidValue {
                    key: key.into(),
                    message: format!("has {len} entries but texture.pocket_start_m has {n}"),
                });
            }
        }
        let length = self.contact.length_m;
        for i in 0..n {
            let (s, w, d) = (
                t.pocket_start_m[i],
                t.pocket_width_m[i],
                t.pocket_depth_m[i],
            );
            co(&format!("texture.pocket_start_m[{i}]"), s, 0.0, length)?;
            oc(&format!("texture.pocket_width_m[{i}]"), w, 0.0, length - s)?;
            cc(&format!("texture.pocket_depth_m[{i}]"), d, 0.0, 1e-3)?;
        }
        Ok(())
    }

    pub(super) fn validate_lubricant(&self) -> Result<(), ConfigError> {
        let l = &self.lubricant;
        let (mu_lo, mu_hi) = super::envelope::VISCOSITY_RANGE_PA_S;
        oc("lubricant.viscosity_pa_s", l.viscosity_pa_s, mu_lo, mu_hi)?;
        let (t_lo, t_hi) = super::envelope::TEMPERATURE_RANGE_C;
        cc(
            "lubricant.reference_temperature_c",
            l.reference_temperature_c,
            t_lo,
            t_hi,
        )?;
        oc("lubricant.vogel_b_c", l.vogel_b_c, 0.0, 1e5)?;
        cc(
            "lubricant.vogel_c_c",
            l.vogel_c_c,
            -273.15,
            l.reference_temperature_c - 1.0,
        )?;
        cc("lubricant.density_kg_m3", l.density_kg_m3, 100.0, 3e4)?;
        oc(
            "lubricant.gas_viscosity_pa_s",
            l.gas_viscosity_pa_s,
            1e-7,
            1e-2,
        )?;
        oo(
            "lubricant.gas_density_kg_m3",
            l.gas_density_kg_m3,
            1e-4,
            l.density_kg_m3,
        )?;
        oc(
            "lubricant.ambient_pressure_pa",
            l.ambient_pressure_pa,
            0.0,
            1e9,
        )?;
        oc(
            "lubricant.saturation_pressure_pa",
            l.saturation_pressure_pa,
            0.0,
            1e9,
        )?;
        co(
            "lubricant.vapour_pressure_pa",
            l.vapour_pressure_pa,
            0.0,
            l.saturation_pressure_pa,
        )?;
        oo(
            "lubricant.vapour_fraction_at_saturation",
            l.vapour_fraction_at_saturation,
            0.0,
            1.0,
        )?;
        oo(
            "lubricant.vapour_fraction_at_vapour_pressure",
            l.vapour_fraction_at_vapour_pressure,
            l.vapour_fraction_at_saturation,
            1.0,
        )
    }

    fn validate_drivetrain(&self) -> Result<(), ConfigError> {
        let d = &self.drivetrain;
        cc("drivetrain.coulomb_n", d.coulomb_n, 0.0, 1e9)?;
        cc("drivetrain.viscous_n_s_m", d.viscous_n_s_m, 0.0, 1e9)?;
        cc("drivetrain.load_coefficient", d.load_coefficient, 0.0, 10.0)?;
        cc(
            "drivetrain.quadratic_n_s2_m2",
            d.quadratic_n_s2_m2,
            0.0,
            1e9,
        )?;
        cc(
            "drivetrain.coulomb_asymmetry_n",
            d.coulomb_asymmetry_n,
            -1e9,
            1e9,
        )
    }

    pub(super) fn validate_roughness(&self) -> Result<(), ConfigError> {
        let r = &self.roughness;
        oc("roughness.sigma_m", r.sigma_m, 1e-10, 1e-4)?;
        cc(
            "roughness.asperity_density_per_m2",
            r.asperity_density_per_m2,
            0.0,
            1e16,
        )?;
        oc(
            "roughness.asperity_radius_m",
            r.asperity_radius_m,
            1e-9,
            1e-2,
        )?;
        oc(
            "roughness.effective_modulus_pa",
            r.effective_modulus_pa,
            1e5,
            1e13,
        )?;
        if r.flow_factors {
            use crate::physics::flow_factors::{FlowFactors, SUPPORTED_GAMMAS};
            FlowFactors::new(r.lay_gamma, r.sigma_m).map_err(|_| ConfigError::OutOfRange {
                key: "roughness.lay_gamma".into(),
                value: format!("{}", r.lay_gamma),
                range: format!("one of {SUPPORTED_GAMMAS}"),
            })?;
        }
        Ok(())
    }

    pub(super) fn validate_solver(&self) -> Result<(), ConfigError> {
        let s = &self.solver;
        cc("solver.cells", s.cells as f64, 8.0, 65536.0)?;
        oc("solver.dt_s", s.dt_s, 1e-7, 1.0)?;
        // The loop keeps deadlines in integer nanoseconds: the step must be one.
        let ns = s.dt_s * 1e9;
        if (ns - ns.round()).abs() > 1e-3 {
            return Err(ConfigError::InvalidValue {
                key: "solver.dt_s".into(),
                message: format!(
                    "{} s is not a whole number of nanoseconds (deadlines are integer ns)",
                    s.dt_s
                ),
            });
        }
        oc("solver.tolerance", s.tolerance, 1e-14, 1e-1)?;
        cc("solver.max_iterations", s.max_iterations as f64, 1.0, 1e4)?;
        cc("solver.theta1", s.theta1, 0.5, 10.0)?;
        oc("solver.theta2", s.theta2, 0.0, 10.0)?;
        if s.method == MethodKind::Reference && s.flux != FluxKind::Upwind {
            return Err(ConfigError::InvalidValue {
                key: "solver.flux".into(),
                message: format!(
                    "{} is not supported by solver.method: reference (the paper's Picard solver has the upwind flux only); allowed with it: upwind (with solver.method: newton: {})",
                    s.flux.name(),
                    FluxKind::NAMES
                ),
            });
        }
        let r = &s.reference;
        let k = |name: &str| format!("solver.reference.{name}");
        oc(&k("fluid_relaxation"), r.fluid_relaxation, 0.0, 1.0)?;
        oc(
            &k("fluid_relaxation_min"),
            r.fluid_relaxation_min,
            0.0,
            r.fluid_relaxation,
        )?;
        cc(
            &k("max_fluid_iterations"),
            r.max_fluid_iterations as f64,
            1.0,
            1e7,
        )?;
        oc(&k("fluid_tolerance"), r.fluid_tolerance, 1e-14, 1.0)?;
        oc(&k("motion_relaxation"), r.motion_relaxation, 0.0, 1.0)?;
        cc(
            &k("max_motion_iterations"),
            r.max_motion_iterations as f64,
            1.0,
            1e6,
        )?;
        oc(&k("motion_tolerance"), r.motion_tolerance, 1e-14, 1.0)
    }

    fn validate_node(&self) -> Result<(), ConfigError> {
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

    fn validate_ros(&self) -> Result<(), ConfigError> {
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

    fn validate_iceoryx2(&self) -> Result<(), ConfigError> {
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

    fn validate_recording(&self) -> Result<(), ConfigError> {
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

/// A ROS 2 name token: letters, digits and underscores, not starting with a
/// digit, no `__` (reserved by ROS 2 for `__node`, `__ns`, …).
fn check_token(t: &str) -> Result<(), &'static str> {
    if t.is_empty() {
        return Err("empty token (a repeated `/` or a `/` at the end)");
    }
    if !t.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        return Err("only letters, digits, `_` and `/` are allowed");
    }
    if t.starts_with(|c: char| c.is_ascii_digit()) {
        return Err("a token must not start with a digit");
    }
    if t.contains("__") {
        return Err("`__` is reserved by ROS 2");
    }
    Ok(())
}

/// A ROS 2 topic name: absolute (`/a/b`), relative (`a/b`) or private
/// (`~/a`); no `//`, no trailing `/`.
pub fn check_topic(s: &str) -> Result<(), &'static str> {
    if s.is_empty() {
        return Err("the name is empty");
    }
    let misplaced_tilde = s
        .char_indices()
        .any(|(i, c)| c == '~' && !(i == 0 && s[1..].starts_with('/')));
    if misplaced_tilde {
        return Err("`~` may only start a private name, as `~/name`");
    }
    if s.contains("//") {
        return Err("`//` is not allowed");
    }
    if s.len() > 1 && s.ends_with('/') {
        return Err("a name must not end with `/`");
    }
    let body = s
        .strip_prefix("~/")
        .or_else(|| s.strip_prefix('/'))
        .unwrap_or(s);
    if body.is_empty() {
        return Err("the name has no token after its prefix");
    }
    body.split('/').try_for_each(check_token)
}

/// A ROS 2 node base name: one token.
pub fn check_node_name(s: &str) -> Result<(), &'static str> {
    if s.contains('/') {
        return Err("a node name is one token: put the path in ros.namespace");
    }
    check_token(s)
}

/// A ROS 2 namespace: `/` or an absolute path of tokens, no trailing `/`.
pub fn check_namespace(s: &str) -> Result<(), &'static str> {
    if s == "/" {
        return Ok(());
    }
    if !s.starts_with('/') {
        return Err("a namespace is absolute: it starts with `/`");
    }
    if s.contains("//") {
        return Err("`//` is not allowed");
    }
    if s.ends_with('/') {
        return Err("a namespace must not end with `/`");
    }
    s[1..].split('/').try_for_each(check_token)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ros_names_follow_the_ros2_rules_and_say_which_one_is_broken() {
        for ok in [
            "~/cmd_velocity",
            "/a/b",
            "rel/x",
            "x1",
            "/friction_node/friction",
        ] {
            assert_eq!(check_topic(ok), Ok(()), "{ok}");
        }
        for (bad, rule) in [
            ("", "empty"),
            ("a b", "only letters"),
            ("/a//b", "`//`"),
            ("/a/", "end with `/`"),
            ("/1a", "digit"),
            ("a/~/b", "`~`"),
            ("~x", "`~`"),
            ("/a__b", "reserved"),
            ("~/", "end with `/`"),
        ] {
            let e = check_topic(bad).unwrap_err();
            assert!(e.contains(rule), "{bad}: {e}");
        }
        assert!(check_node_name("friction_node").is_ok());
        assert!(check_node_name("a/b").unwrap_err().contains("namespace"));
        assert!(check_node_name("2fast").is_err());
        assert!(check_namespace("/").is_ok());
        assert!(check_namespace("/robot/arm").is_ok());
        assert!(check_namespace("robot").unwrap_err().contains("absolute"));
        assert!(check_namespace("/robot/").unwrap_err().contains("end"));
    }
}
