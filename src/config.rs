//! Configuration: one YAML format for everything, in the ROS 2
//! parameter-file shape.
//!
//! ```yaml
//! friction_node:            # the node name (or /**)
//!   ros__parameters:
//!     contact:
//!       load_n: 20762.0
//! ```
//!
//! Every key carries its SI unit in its name. Every default equals the
//! paper's Tables A2–A4 and `MODEL.md` (they are taken from the physics
//! core's `Default` impls, so there is one source of truth).
//! `launch-config/default.yaml` documents every key; it is embedded in the
//! binary and used when no `--config` is given.
//!
//! Unknown keys are rejected with their full dotted name; values outside
//! their physical range are rejected with the key, the value and the range
//! ([`Config::validate`]). Overrides `dotted.key=value` are applied to the
//! YAML tree before it is read, so they are checked exactly like file keys.

use crate::physics::{
    self, Contact, Geometry, Lubricant, Method, ModelParams, Pocket, Profile, ReferenceSettings,
    Roughness, SolverSettings, TimeScheme,
};
use crate::text::Num;
use serde::{Deserialize, Serialize};
use serde_norway::Value;
use std::path::{Path, PathBuf};

/// The shipped default parameter file (also the documentation of every key).
pub const DEFAULT_YAML: &str = include_str!("../launch-config/default.yaml");

/// Top-level keys accepted as the node entry of a parameter file.
pub const DEFAULT_NODE_NAME: &str = "friction_node";

/// Errors of the configuration layer.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("cannot read config file {}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("config {origin} is not valid YAML: {message}")]
    Syntax { origin: String, message: String },
    #[error("config {origin}: {message}")]
    Layout { origin: String, message: String },
    #[error("unknown config key `{key}` ({message})")]
    UnknownKey { key: String, message: String },
    #[error("config key `{key}`: {message}")]
    InvalidValue { key: String, message: String },
    #[error("config key `{key}` = {value} is out of range: allowed {range}")]
    OutOfRange {
        key: String,
        value: String,
        range: String,
    },
    #[error("override `{arg}`: {message}")]
    BadOverride { arg: String, message: String },
}

/// `contact.*`: slider geometry, mass, load and boundary friction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ContactConfig {
    pub length_m: f64,
    pub width_m: f64,
    pub mass_kg: f64,
    pub load_n: f64,
    pub profile: ProfileKind,
    pub profile_depth_m: f64,
    pub boundary_friction: f64,
    pub sign_regularization_m_s: f64,
    pub min_film_m: f64,
}

/// Shape of the global profile.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ProfileKind {
    Parabolic,
    Linear,
    Flat,
}

/// The paper's load for the reciprocating studies (Table A4 says 5 kN, the
/// figures use the text's 20 762 N; MODEL.md §8 decides for the text).
pub const DEFAULT_LOAD_N: f64 = 20_762.0;

impl Default for ContactConfig {
    fn default() -> Self {
        let g = Geometry::default();
        let c = Contact::default();
        let (profile, depth) = match g.profile {
            Profile::Parabolic { depth } => (ProfileKind::Parabolic, depth),
            Profile::Linear { depth } => (ProfileKind::Linear, depth),
            Profile::Flat => (ProfileKind::Flat, 0.0),
        };
        Self {
            length_m: g.length,
            width_m: g.width,
            mass_kg: c.mass,
            load_n: DEFAULT_LOAD_N,
            profile,
            profile_depth_m: depth,
            boundary_friction: c.boundary_friction,
            sign_regularization_m_s: c.sign_regularization,
            min_film_m: c.min_film,
        }
    }
}

/// `texture.*`: rectangular pockets as parallel arrays (ROS 2 parameters
/// cannot hold lists of structs).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TextureConfig {
    pub pocket_start_m: Vec<f64>,
    pub pocket_width_m: Vec<f64>,
    pub pocket_depth_m: Vec<f64>,
}

/// `lubricant.*`: liquid, gas and the cavitation equation of state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LubricantConfig {
    pub viscosity_pa_s: f64,
    pub density_kg_m3: f64,
    pub gas_viscosity_pa_s: f64,
    pub gas_density_kg_m3: f64,
    pub ambient_pressure_pa: f64,
    pub saturation_pressure_pa: f64,
    pub vapour_pressure_pa: f64,
    pub vapour_fraction_at_saturation: f64,
    pub vapour_fraction_at_vapour_pressure: f64,
}

impl Default for LubricantConfig {
    fn default() -> Self {
        let l = Lubricant::default();
        Self {
            viscosity_pa_s: l.viscosity,
            density_kg_m3: l.density,
            gas_viscosity_pa_s: l.gas_viscosity,
            gas_density_kg_m3: l.gas_density,
            ambient_pressure_pa: l.ambient_pressure,
            saturation_pressure_pa: l.saturation_pressure,
            vapour_pressure_pa: l.vapour_pressure,
            vapour_fraction_at_saturation: l.vapour_fraction_saturation,
            vapour_fraction_at_vapour_pressure: l.vapour_fraction_vapour,
        }
    }
}

/// `roughness.*`: GW contact and flow factors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RoughnessConfig {
    pub sigma_m: f64,
    pub asperity_density_per_m2: f64,
    pub asperity_radius_m: f64,
    pub effective_modulus_pa: f64,
    pub flow_factors: bool,
    pub lay_gamma: f64,
}

impl Default for RoughnessConfig {
    fn default() -> Self {
        let r = Roughness::default();
        Self {
            sigma_m: r.sigma,
            asperity_density_per_m2: r.asperity_density,
            asperity_radius_m: r.asperity_radius,
            effective_modulus_pa: r.effective_modulus,
            flow_factors: r.flow_factors,
            lay_gamma: r.lay_gamma,
        }
    }
}

/// `solver.method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MethodKind {
    Newton,
    Reference,
}

/// `solver.scheme`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum SchemeKind {
    Bdf2,
    Theta,
}

/// `solver.*`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SolverConfig {
    pub cells: usize,
    pub dt_s: f64,
    pub method: MethodKind,
    pub scheme: SchemeKind,
    pub theta1: f64,
    pub theta2: f64,
    pub tolerance: f64,
    pub max_iterations: u32,
    pub reference: ReferenceConfig,
}

impl Default for SolverConfig {
    fn default() -> Self {
        let s = SolverSettings::default();
        let TimeScheme::Theta { theta1, theta2 } = TimeScheme::PAPER else {
            unreachable!()
        };
        Self {
            cells: s.cells,
            dt_s: s.dt,
            method: MethodKind::Newton,
            scheme: SchemeKind::Bdf2,
            theta1,
            theta2,
            tolerance: s.tolerance,
            max_iterations: s.max_iterations,
            reference: ReferenceConfig::default(),
        }
    }
}

/// `solver.reference.*`: the paper's Algorithm 1.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ReferenceConfig {
    pub fluid_relaxation: f64,
    pub fluid_relaxation_min: f64,
    pub max_fluid_iterations: u32,
    pub fluid_tolerance: f64,
    pub motion_relaxation: f64,
    pub max_motion_iterations: u32,
    pub motion_tolerance: f64,
}

impl Default for ReferenceConfig {
    fn default() -> Self {
        let r = ReferenceSettings::default();
        Self {
            fluid_relaxation: r.fluid_relaxation,
            fluid_relaxation_min: r.fluid_relaxation_min,
            max_fluid_iterations: r.max_fluid_iterations,
            fluid_tolerance: r.fluid_tolerance,
            motion_relaxation: r.motion_relaxation,
            max_motion_iterations: r.max_motion_iterations,
            motion_tolerance: r.motion_tolerance,
        }
    }
}

/// The whole configuration (the `ros__parameters` mapping).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Config {
    pub contact: ContactConfig,
    pub texture: TextureConfig,
    pub lubricant: LubricantConfig,
    pub roughness: RoughnessConfig,
    pub solver: SolverConfig,
    pub node: NodeConfig,
    pub ros: RosConfig,
    pub iceoryx2: Iceoryx2Config,
    pub recording: RecordingConfig,
}

/// `node.step_mode`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum StepMode {
    /// Fixed real-time steps against absolute deadlines; zero-order hold of
    /// the latest command.
    Timer,
    /// One step per received velocity command, stamped with the command's
    /// time (deterministic: tests and replay).
    Lockstep,
}

/// `node.transport` (the `run --transport` flag overrides it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TransportKind {
    Ros2,
    Iceoryx2,
    Both,
}

/// `node.timeout_behaviour`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeoutBehaviour {
    /// Keep the last velocity.
    Hold,
    /// Decelerate to zero at `node.timeout_deceleration_m_s2`.
    RampToZero,
}

/// `node.realtime.*`: applied when enabled and permitted, with a warning
/// otherwise.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RealtimeConfig {
    /// Run the loop thread under SCHED_FIFO.
    pub fifo: bool,
    /// SCHED_FIFO priority, 1..99.
    pub priority: i32,
    /// mlockall(MCL_CURRENT | MCL_FUTURE).
    pub lock_memory: bool,
    /// Pin the loop thread to this CPU; -1 = no pinning.
    pub cpu: i32,
}

impl Default for RealtimeConfig {
    fn default() -> Self {
        Self {
            fifo: false,
            priority: 80,
            lock_memory: false,
            cpu: -1,
        }
    }
}

/// `node.*`: the fixed-step loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NodeConfig {
    pub step_mode: StepMode,
    pub transport: TransportKind,
    /// Velocity of the steady state the node starts from, m/s.
    pub initial_velocity_m_s: f64,
    /// A velocity command older than this is stale, s.
    pub command_timeout_s: f64,
    pub timeout_behaviour: TimeoutBehaviour,
    pub timeout_deceleration_m_s2: f64,
    /// Commands with |v| above this are rejected, m/s.
    pub max_abs_velocity_m_s: f64,
    /// Load commands outside [min, max] are rejected, N.
    pub min_load_n: f64,
    pub max_load_n: f64,
    /// FilmProfile publication rate, Hz (0 = off).
    pub profile_rate_hz: f64,
    /// LoopStatistics publication rate, Hz.
    pub statistics_rate_hz: f64,
    /// Capacity of each output queue (transport I/O, recorder).
    pub queue_capacity: usize,
    /// header.frame_id of the published messages.
    pub frame_id: String,
    /// Lockstep: busy-poll for commands this long before blocking on the
    /// transport's wake-up, µs (0 = always block; a spin trades one core for
    /// a lower wake-up latency).
    pub lockstep_spin_us: u64,
    pub realtime: RealtimeConfig,
}

impl Default for NodeConfig {
    fn default() -> Self {
        Self {
            step_mode: StepMode::Timer,
            transport: TransportKind::Ros2,
            initial_velocity_m_s: 0.0,
            command_timeout_s: 0.1,
            timeout_behaviour: TimeoutBehaviour::Hold,
            timeout_deceleration_m_s2: 1.0,
            max_abs_velocity_m_s: 10.0,
            min_load_n: 1.0,
            max_load_n: 1e7,
            profile_rate_hz: 10.0,
            statistics_rate_hz: 1.0,
            queue_capacity: 4096,
            frame_id: "slider".into(),
            lockstep_spin_us: 0,
            realtime: RealtimeConfig::default(),
        }
    }
}

/// `ros.discovery_range`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DiscoveryRange {
    /// From ROS_AUTOMATIC_DISCOVERY_RANGE / ROS_LOCALHOST_ONLY (default
    /// SUBNET when neither is set, as in ROS 2).
    Env,
    /// Loopback only (what shipped configs, tests and CI use).
    Localhost,
    /// Every interface (real robot networks).
    Subnet,
    /// No discovery beyond this host's loopback.
    Off,
}

/// `ros.command_type`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CommandType {
    /// std_msgs/msg/Float64, m/s.
    Float64,
    /// geometry_msgs/msg/TwistStamped, linear.x in m/s.
    TwistStamped,
}

/// `ros.qos.*`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Reliability {
    BestEffort,
    Reliable,
}

/// `ros.qos.*.durability`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Durability {
    /// Samples go to the readers matched when they are written.
    #[default]
    Volatile,
    /// The writer keeps its last `depth` samples for readers that match
    /// later (and a reader asks for them).
    TransientLocal,
}

/// QoS of one group of topics.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct QosConfig {
    pub reliability: Reliability,
    /// Keep-last depth.
    pub depth: usize,
    pub durability: Durability,
}

impl Default for QosConfig {
    fn default() -> Self {
        Self {
            reliability: Reliability::Reliable,
            depth: 10,
            durability: Durability::Volatile,
        }
    }
}

/// `ros.qos`: commands best effort keep-last 1, estimates reliable depth 10.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct QosProfiles {
    pub commands: QosConfig,
    pub estimates: QosConfig,
}

impl Default for QosProfiles {
    fn default() -> Self {
        Self {
            commands: QosConfig {
                reliability: Reliability::BestEffort,
                depth: 1,
                durability: Durability::Volatile,
            },
            estimates: QosConfig::default(),
        }
    }
}

/// `ros.topics`: `~/` is the node's private namespace.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TopicsConfig {
    pub cmd_velocity: String,
    pub normal_load: String,
    pub friction: String,
    pub friction_force: String,
    pub film_profile: String,
    pub loop_statistics: String,
}

impl Default for TopicsConfig {
    fn default() -> Self {
        Self {
            cmd_velocity: "~/cmd_velocity".into(),
            normal_load: "~/normal_load".into(),
            friction: "~/friction".into(),
            friction_force: "~/friction_force".into(),
            film_profile: "~/film_profile".into(),
            loop_statistics: "~/loop_statistics".into(),
        }
    }
}

/// `ros.*`: ROS 2 conventions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RosConfig {
    pub node_name: String,
    pub namespace: String,
    /// DDS domain; -1 = ROS_DOMAIN_ID (or 0 when unset).
    pub domain_id: i64,
    pub discovery_range: DiscoveryRange,
    pub command_type: CommandType,
    pub topics: TopicsConfig,
    pub qos: QosProfiles,
}

impl Default for RosConfig {
    fn default() -> Self {
        Self {
            node_name: DEFAULT_NODE_NAME.into(),
            namespace: "/".into(),
            domain_id: -1,
            discovery_range: DiscoveryRange::Localhost,
            command_type: CommandType::Float64,
            topics: TopicsConfig::default(),
            qos: QosProfiles::default(),
        }
    }
}

/// `iceoryx2.*`: service names of the zero-copy IPC transport.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Iceoryx2Config {
    pub cmd_velocity_service: String,
    pub normal_load_service: String,
    pub friction_service: String,
    /// Event service that wakes a lockstep node when a command is sent.
    pub cmd_event_service: String,
}

impl Default for Iceoryx2Config {
    fn default() -> Self {
        Self {
            cmd_velocity_service: "friction_node/cmd_velocity".into(),
            normal_load_service: "friction_node/normal_load".into(),
            friction_service: "friction_node/friction".into(),
            cmd_event_service: "friction_node/cmd_event".into(),
        }
    }
}

/// `recording.compression`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Compression {
    None,
    Zstd,
    Lz4,
}

/// `recording.*`: MCAP recording (the `run --record FILE` flag enables it).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RecordingConfig {
    pub enabled: bool,
    /// File to write; empty = bags/friction_node_<UTC time>.mcap.
    pub path: String,
    /// Chunk size, bytes: a crash loses at most the open chunk.
    pub chunk_size_bytes: u64,
    pub compression: Compression,
}

impl Default for RecordingConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            path: String::new(),
            chunk_size_bytes: 256 * 1024,
            compression: Compression::Zstd,
        }
    }
}

/// ROS 2 base names: letters, digits, underscores; not starting with a digit;
/// no double underscore.
pub fn valid_ros_token(s: &str) -> bool {
    !s.is_empty()
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && s.starts_with(|c: char| c.is_ascii_alphabetic() || c == '_')
        && !s.contains("__")
}

/// A ROS 2 topic name: absolute (`/a/b`), relative (`a/b`) or private (`~/a`).
pub fn valid_topic(s: &str) -> bool {
    let body = s
        .strip_prefix("~/")
        .or_else(|| s.strip_prefix('/'))
        .unwrap_or(s);
    !body.is_empty() && body.split('/').all(valid_ros_token)
}

/// Where a configuration came from (for messages).
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Origin {
    Embedded,
    File(PathBuf),
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Origin::Embedded => write!(f, "(built-in launch-config/default.yaml)"),
            Origin::File(p) => write!(f, "{}", p.display()),
        }
    }
}

fn range_check(
    key: &str,
    value: f64,
    lo: f64,
    hi: f64,
    lo_open: bool,
    hi_open: bool,
) -> Result<(), ConfigError> {
    let ok = value.is_finite()
        && (if lo_open { value > lo } else { value >= lo })
        && (if hi_open { value < hi } else { value <= hi });
    if ok {
        Ok(())
    } else {
        Err(ConfigError::OutOfRange {
            key: key.to_string(),
            value: format!("{value}"),
            range: format!(
                "{}{}, {}{}",
                if lo_open { "(" } else { "[" },
                Num(lo),
                Num(hi),
                if hi_open { ")" } else { "]" }
            ),
        })
    }
}

impl Config {
    /// Read a parameter file (or the embedded default when `path` is None),
    /// apply `dotted.key=value` overrides, deserialize and validate.
    pub fn load(path: Option<&Path>, overrides: &[String]) -> Result<Config, ConfigError> {
        let (text, origin) = match path {
            Some(p) => (
                std::fs::read_to_string(p).map_err(|source| ConfigError::Io {
                    path: p.to_path_buf(),
                    source,
                })?,
                Origin::File(p.to_path_buf()),
            ),
            None => (DEFAULT_YAML.to_string(), Origin::Embedded),
        };
        Self::from_yaml(&text, &origin, overrides)
    }

    /// Parse parameter-file text (see [`Config::load`]).
    pub fn from_yaml(
        text: &str,
        origin: &Origin,
        overrides: &[String],
    ) -> Result<Config, ConfigError> {
        let doc: Value = serde_norway::from_str(text).map_err(|e| ConfigError::Syntax {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
        let mut params = ros_parameters(doc, origin)?;
        for o in overrides {
            apply_override(&mut params, o)?;
        }
        let cfg: Config = serde_path_to_error::deserialize(params).map_err(|e| {
            let key = e.path().to_string();
            let message = e.inner().to_string();
            if message.starts_with("unknown field") {
                ConfigError::UnknownKey { key, message }
            } else {
                ConfigError::InvalidValue { key, message }
            }
        })?;
        cfg.validate()?;
        Ok(cfg)
    }

    /// Physical ranges of every key.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let c = &self.contact;
        range_check("contact.length_m", c.length_m, 1e-4, 10.0, true, false)?;
        range_check("contact.width_m", c.width_m, 1e-4, 10.0, true, false)?;
        range_check("contact.mass_kg", c.mass_kg, 0.0, 1e6, false, false)?;
        range_check("contact.load_n", c.load_n, 0.0, 1e9, true, false)?;
        range_check(
            "contact.profile_depth_m",
            c.profile_depth_m,
            0.0,
            1e-3,
            false,
            false,
        )?;
        range_check(
            "contact.boundary_friction",
            c.boundary_friction,
            0.0,
            2.0,
            false,
            false,
        )?;
        range_check(
            "contact.sign_regularization_m_s",
            c.sign_regularization_m_s,
            1e-9,
            1.0,
            true,
            false,
        )?;
        range_check("contact.min_film_m", c.min_film_m, 0.0, 1e-3, false, false)?;
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
        for i in 0..n {
            let (s, w, d) = (
                t.pocket_start_m[i],
                t.pocket_width_m[i],
                t.pocket_depth_m[i],
            );
            range_check(
                &format!("texture.pocket_start_m[{i}]"),
                s,
                0.0,
                c.length_m,
                false,
                true,
            )?;
            range_check(
                &format!("texture.pocket_width_m[{i}]"),
                w,
                0.0,
                c.length_m - s,
                true,
                false,
            )?;
            range_check(
                &format!("texture.pocket_depth_m[{i}]"),
                d,
                0.0,
                1e-3,
                false,
                false,
            )?;
        }
        let l = &self.lubricant;
        range_check(
            "lubricant.viscosity_pa_s",
            l.viscosity_pa_s,
            1e-5,
            100.0,
            true,
            false,
        )?;
        range_check(
            "lubricant.density_kg_m3",
            l.density_kg_m3,
            100.0,
            3e4,
            false,
            false,
        )?;
        range_check(
            "lubricant.gas_viscosity_pa_s",
            l.gas_viscosity_pa_s,
            1e-7,
            1e-2,
            true,
            false,
        )?;
        range_check(
            "lubricant.gas_density_kg_m3",
            l.gas_density_kg_m3,
            1e-4,
            l.density_kg_m3,
            true,
            true,
        )?;
        range_check(
            "lubricant.ambient_pressure_pa",
            l.ambient_pressure_pa,
            0.0,
            1e9,
            true,
            false,
        )?;
        range_check(
            "lubricant.saturation_pressure_pa",
            l.saturation_pressure_pa,
            0.0,
            1e9,
            true,
            false,
        )?;
        range_check(
            "lubricant.vapour_pressure_pa",
            l.vapour_pressure_pa,
            0.0,
            l.saturation_pressure_pa,
            false,
            true,
        )?;
        range_check(
            "lubricant.vapour_fraction_at_saturation",
            l.vapour_fraction_at_saturation,
            0.0,
            1.0,
            true,
            true,
        )?;
        range_check(
            "lubricant.vapour_fraction_at_vapour_pressure",
            l.vapour_fraction_at_vapour_pressure,
            l.vapour_fraction_at_saturation,
            1.0,
            true,
            true,
        )?;
        let r = &self.roughness;
        range_check("roughness.sigma_m", r.sigma_m, 1e-10, 1e-4, true, false)?;
        range_check(
            "roughness.asperity_density_per_m2",
            r.asperity_density_per_m2,
            0.0,
            1e16,
            false,
            false,
        )?;
        range_check(
            "roughness.asperity_radius_m",
            r.asperity_radius_m,
            1e-9,
            1e-2,
            true,
            false,
        )?;
        range_check(
            "roughness.effective_modulus_pa",
            r.effective_modulus_pa,
            1e5,
            1e13,
            true,
            false,
        )?;
        if r.flow_factors {
            physics::flow_factors::FlowFactors::new(r.lay_gamma, r.sigma_m).map_err(|_| {
                ConfigError::OutOfRange {
                    key: "roughness.lay_gamma".into(),
                    value: format!("{}", r.lay_gamma),
                    range: format!("one of {}", physics::flow_factors::SUPPORTED_GAMMAS),
                }
            })?;
        }
        let s = &self.solver;
        range_check("solver.cells", s.cells as f64, 8.0, 65536.0, false, false)?;
        range_check("solver.dt_s", s.dt_s, 1e-7, 1.0, true, false)?;
        range_check("solver.tolerance", s.tolerance, 1e-14, 1e-1, true, false)?;
        range_check(
            "solver.max_iterations",
            s.max_iterations as f64,
            1.0,
            10_000.0,
            false,
            false,
        )?;
        range_check("solver.theta1", s.theta1, 0.5, 10.0, false, false)?;
        range_check("solver.theta2", s.theta2, 0.0, 10.0, true, false)?;
        let rf = &s.reference;
        range_check(
            "solver.reference.fluid_relaxation",
            rf.fluid_relaxation,
            0.0,
            1.0,
            true,
            false,
        )?;
        range_check(
            "solver.reference.fluid_relaxation_min",
            rf.fluid_relaxation_min,
            0.0,
            rf.fluid_relaxation,
            true,
            false,
        )?;
        range_check(
            "solver.reference.max_fluid_iterations",
            rf.max_fluid_iterations as f64,
            1.0,
            1e7,
            false,
            false,
        )?;
        range_check(
            "solver.reference.fluid_tolerance",
            rf.fluid_tolerance,
            1e-14,
            1.0,
            true,
            false,
        )?;
        range_check(
            "solver.reference.motion_relaxation",
            rf.motion_relaxation,
            0.0,
            1.0,
            true,
            false,
        )?;
        range_check(
            "solver.reference.max_motion_iterations",
            rf.max_motion_iterations as f64,
            1.0,
            1e6,
            false,
            false,
        )?;
        range_check(
            "solver.reference.motion_tolerance",
            rf.motion_tolerance,
            1e-14,
            1.0,
            true,
            false,
        )?;
        self.validate_io()
    }

    /// Ranges of the node, ROS 2 and recording sections.
    fn validate_io(&self) -> Result<(), ConfigError> {
        let n = &self.node;
        range_check(
            "node.max_abs_velocity_m_s",
            n.max_abs_velocity_m_s,
            0.0,
            100.0,
            true,
            false,
        )?;
        let vmax = n.max_abs_velocity_m_s;
        range_check(
            "node.initial_velocity_m_s",
            n.initial_velocity_m_s,
            -vmax,
            vmax,
            false,
            false,
        )?;
        range_check(
            "node.command_timeout_s",
            n.command_timeout_s,
            0.0,
            3600.0,
            true,
            false,
        )?;
        range_check(
            "node.timeout_deceleration_m_s2",
            n.timeout_deceleration_m_s2,
            0.0,
            1e4,
            true,
            false,
        )?;
        range_check("node.min_load_n", n.min_load_n, 0.0, 1e9, true, false)?;
        range_check(
            "node.max_load_n",
            n.max_load_n,
            n.min_load_n,
            1e9,
            false,
            false,
        )?;
        range_check(
            "node.profile_rate_hz",
            n.profile_rate_hz,
            0.0,
            1000.0,
            false,
            false,
        )?;
        range_check(
            "node.statistics_rate_hz",
            n.statistics_rate_hz,
            0.0,
            1000.0,
            true,
            false,
        )?;
        range_check(
            "node.queue_capacity",
            n.queue_capacity as f64,
            16.0,
            1e7,
            false,
            false,
        )?;
        range_check(
            "node.lockstep_spin_us",
            n.lockstep_spin_us as f64,
            0.0,
            1e6,
            false,
            false,
        )?;
        range_check(
            "node.realtime.priority",
            n.realtime.priority as f64,
            1.0,
            99.0,
            false,
            false,
        )?;
        range_check(
            "node.realtime.cpu",
            n.realtime.cpu as f64,
            -1.0,
            4095.0,
            false,
            false,
        )?;
        range_check(
            "ros.domain_id",
            self.ros.domain_id as f64,
            -1.0,
            232.0,
            false,
            false,
        )?;
        for (key, q) in [
            ("ros.qos.commands.depth", &self.ros.qos.commands),
            ("ros.qos.estimates.depth", &self.ros.qos.estimates),
        ] {
            range_check(key, q.depth as f64, 1.0, 1e6, false, false)?;
        }
        range_check(
            "recording.chunk_size_bytes",
            self.recording.chunk_size_bytes as f64,
            1024.0,
            1e9,
            false,
            false,
        )?;
        Ok(())
    }

    /// The physics core's parameters.
    pub fn model(&self) -> ModelParams {
        let c = &self.contact;
        let t = &self.texture;
        ModelParams {
            geometry: Geometry {
                length: c.length_m,
                width: c.width_m,
                profile: match c.profile {
                    ProfileKind::Parabolic => Profile::Parabolic {
                        depth: c.profile_depth_m,
                    },
                    ProfileKind::Linear => Profile::Linear {
                        depth: c.profile_depth_m,
                    },
                    ProfileKind::Flat => Profile::Flat,
                },
                pockets: (0..t.pocket_start_m.len())
                    .map(|i| Pocket {
                        start: t.pocket_start_m[i],
                        width: t.pocket_width_m[i],
                        depth: t.pocket_depth_m[i],
                    })
                    .collect(),
            },
            lubricant: Lubricant {
                viscosity: self.lubricant.viscosity_pa_s,
                density: self.lubricant.density_kg_m3,
                gas_viscosity: self.lubricant.gas_viscosity_pa_s,
                gas_density: self.lubricant.gas_density_kg_m3,
                ambient_pressure: self.lubricant.ambient_pressure_pa,
                saturation_pressure: self.lubricant.saturation_pressure_pa,
                vapour_pressure: self.lubricant.vapour_pressure_pa,
                vapour_fraction_saturation: self.lubricant.vapour_fraction_at_saturation,
                vapour_fraction_vapour: self.lubricant.vapour_fraction_at_vapour_pressure,
            },
            roughness: Roughness {
                sigma: self.roughness.sigma_m,
                asperity_density: self.roughness.asperity_density_per_m2,
                asperity_radius: self.roughness.asperity_radius_m,
                effective_modulus: self.roughness.effective_modulus_pa,
                flow_factors: self.roughness.flow_factors,
                lay_gamma: self.roughness.lay_gamma,
            },
            contact: Contact {
                mass: c.mass_kg,
                boundary_friction: c.boundary_friction,
                sign_regularization: c.sign_regularization_m_s,
                min_film: c.min_film_m,
            },
        }
    }

    /// The solver's settings.
    pub fn solver_settings(&self) -> SolverSettings {
        let s = &self.solver;
        let r = &s.reference;
        SolverSettings {
            cells: s.cells,
            dt: s.dt_s,
            method: match s.method {
                MethodKind::Newton => Method::Newton,
                MethodKind::Reference => Method::Reference,
            },
            scheme: match s.scheme {
                SchemeKind::Bdf2 => TimeScheme::Bdf2,
                SchemeKind::Theta => TimeScheme::Theta {
                    theta1: s.theta1,
                    theta2: s.theta2,
                },
            },
            tolerance: s.tolerance,
            max_iterations: s.max_iterations,
            reference: ReferenceSettings {
                fluid_relaxation: r.fluid_relaxation,
                fluid_relaxation_min: r.fluid_relaxation_min,
                max_fluid_iterations: r.max_fluid_iterations,
                fluid_tolerance: r.fluid_tolerance,
                motion_relaxation: r.motion_relaxation,
                max_motion_iterations: r.max_motion_iterations,
                motion_tolerance: r.motion_tolerance,
            },
        }
    }

    /// The resolved configuration as a ROS 2 parameter file.
    pub fn to_yaml(&self) -> String {
        let mut root = serde_norway::Mapping::new();
        let mut node = serde_norway::Mapping::new();
        node.insert(
            Value::String("ros__parameters".into()),
            serde_norway::to_value(self).expect("config serializes"),
        );
        root.insert(
            Value::String(DEFAULT_NODE_NAME.into()),
            Value::Mapping(node),
        );
        serde_norway::to_string(&Value::Mapping(root)).expect("config serializes")
    }
}

/// Extract the `ros__parameters` mapping of the single node entry.
fn ros_parameters(doc: Value, origin: &Origin) -> Result<Value, ConfigError> {
    let layout = |message: String| ConfigError::Layout {
        origin: origin.to_string(),
        message,
    };
    let Value::Mapping(top) = doc else {
        return Err(layout(format!(
            "expected `{DEFAULT_NODE_NAME}: {{ros__parameters: {{...}}}}` at the top level"
        )));
    };
    if top.len() != 1 {
        let keys: Vec<String> = top
            .keys()
            .map(|k| {
                serde_norway::to_string(k)
                    .unwrap_or_default()
                    .trim()
                    .to_string()
            })
            .collect();
        return Err(layout(format!(
            "expected exactly one top-level node entry (`{DEFAULT_NODE_NAME}` or `/**`), found {keys:?}"
        )));
    }
    let (name, body) = top.into_iter().next().expect("one entry");
    let name = name.as_str().unwrap_or("").to_string();
    let name_ok = name == "/**" || name.rsplit('/').next() == Some(DEFAULT_NODE_NAME);
    if !name_ok {
        return Err(layout(format!(
            "top-level key `{name}` is not this node: use `{DEFAULT_NODE_NAME}` (optionally namespaced, e.g. `/robot/{DEFAULT_NODE_NAME}`) or `/**`"
        )));
    }
    let Value::Mapping(mut body) = body else {
        return Err(layout(format!("`{name}` must contain `ros__parameters:`")));
    };
    let params = body
        .remove("ros__parameters")
        .ok_or_else(|| layout(format!("`{name}` has no `ros__parameters:` entry")))?;
    if let Some(k) = body.keys().next() {
        return Err(ConfigError::UnknownKey {
            key: format!("{name}.{}", k.as_str().unwrap_or("?")),
            message: "only `ros__parameters` is allowed under the node entry".into(),
        });
    }
    match params {
        Value::Null => Ok(Value::Mapping(Default::default())),
        v @ Value::Mapping(_) => Ok(v),
        _ => Err(layout("`ros__parameters` must be a mapping".into())),
    }
}

/// Apply one `dotted.key=value` override (the value is a YAML scalar or flow
/// sequence, e.g. `0.05`, `true`, `reference`, `[0.01, 0.02]`).
pub fn apply_override(params: &mut Value, arg: &str) -> Result<(), ConfigError> {
    let bad = |message: &str| ConfigError::BadOverride {
        arg: arg.to_string(),
        message: message.to_string(),
    };
    let (key, value) = arg
        .split_once('=')
        .ok_or_else(|| bad("expected dotted.key=value"))?;
    let key = key.trim();
    if key.is_empty() || key.split('.').any(|p| p.is_empty()) {
        return Err(bad("the key must be a dotted path such as contact.load_n"));
    }
    let value: Value = serde_norway::from_str(value.trim())
        .map_err(|e| bad(&format!("value is not a YAML scalar: {e}")))?;
    let mut node = params;
    let parts: Vec<&str> = key.split('.').collect();
    for (i, part) in parts.iter().enumerate() {
        let Value::Mapping(map) = node else {
            return Err(bad(&format!("`{}` is not a section", parts[..i].join("."))));
        };
        if i + 1 == parts.len() {
            map.insert(Value::String((*part).into()), value);
            return Ok(());
        }
        node = map
            .entry(Value::String((*part).into()))
            .or_insert_with(|| Value::Mapping(Default::default()));
    }
    unreachable!("the loop returns at the last part")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn load(text: &str, sets: &[&str]) -> Result<Config, ConfigError> {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        Config::from_yaml(text, &Origin::Embedded, &sets)
    }

    #[test]
    fn shipped_default_file_equals_the_built_in_defaults() {
        let c = Config::load(None, &[]).unwrap();
        assert_eq!(c, Config::default());
        assert_eq!(c.model(), ModelParams::default());
        assert_eq!(c.solver_settings(), SolverSettings::default());
        assert_eq!(c.contact.load_n, 20_762.0);
    }

    #[test]
    fn every_shipped_parameter_file_loads() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("launch-config");
        let mut n = 0;
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "yaml") {
                let c = Config::load(Some(&path), &[])
                    .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
                // Shipped configs keep ROS 2 discovery on this host.
                assert_eq!(
                    c.ros.discovery_range,
                    DiscoveryRange::Localhost,
                    "{}",
                    path.display()
                );
                n += 1;
            }
        }
        assert!(n >= 2);
    }

    #[test]
    fn unknown_key_is_named_with_its_full_path() {
        let e = load(
            "friction_node:\n  ros__parameters:\n    contact:\n      lenght_m: 0.1\n",
            &[],
        )
        .unwrap_err();
        assert!(
            matches!(e, ConfigError::UnknownKey { ref key, .. } if key == "contact.lenght_m"),
            "{e}"
        );
        assert!(
            e.to_string().contains("length_m"),
            "suggests the valid keys: {e}"
        );
    }

    #[test]
    fn out_of_range_value_names_key_value_and_range() {
        let e = load(
            "friction_node:\n  ros__parameters:\n    lubricant:\n      viscosity_pa_s: -1.0\n",
            &[],
        )
        .unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("lubricant.viscosity_pa_s")
                && msg.contains("-1")
                && msg.contains("(1e-5, 100]"),
            "{msg}"
        );
    }

    #[test]
    fn overrides_apply_and_are_validated_like_file_keys() {
        let c = load(
            DEFAULT_YAML,
            &[
                "contact.load_n=5762",
                "solver.method=reference",
                "roughness.flow_factors=true",
            ],
        )
        .unwrap();
        assert_eq!(c.contact.load_n, 5762.0);
        assert_eq!(c.solver.method, MethodKind::Reference);
        assert!(c.roughness.flow_factors);
        let e = load(DEFAULT_YAML, &["contact.lode_n=5"]).unwrap_err();
        assert!(matches!(e, ConfigError::UnknownKey { ref key, .. } if key == "contact.lode_n"));
        let e = load(DEFAULT_YAML, &["solver.cells=3"]).unwrap_err();
        assert!(e.to_string().contains("solver.cells"), "{e}");
        let e = load(DEFAULT_YAML, &["solver.method=magic"]).unwrap_err();
        assert!(e.to_string().contains("newton"), "{e}");
        assert!(matches!(
            load(DEFAULT_YAML, &["nokey"]).unwrap_err(),
            ConfigError::BadOverride { .. }
        ));
    }

    #[test]
    fn node_ros_and_recording_values_outside_their_ranges_are_named() {
        for (set, key) in [
            ("node.command_timeout_s=-1", "node.command_timeout_s"),
            ("node.max_abs_velocity_m_s=0", "node.max_abs_velocity_m_s"),
            ("node.initial_velocity_m_s=20", "node.initial_velocity_m_s"),
            ("node.max_load_n=0.5", "node.max_load_n"),
            ("node.queue_capacity=2", "node.queue_capacity"),
            ("node.realtime.priority=0", "node.realtime.priority"),
            ("ros.domain_id=300", "ros.domain_id"),
            ("ros.qos.estimates.depth=0", "ros.qos.estimates.depth"),
            (
                "recording.chunk_size_bytes=10",
                "recording.chunk_size_bytes",
            ),
        ] {
            let e = load(DEFAULT_YAML, &[set]).unwrap_err();
            assert!(
                matches!(e, ConfigError::OutOfRange { key: ref k, .. } if k == key),
                "{set}: {e}"
            );
        }
        let c = load(
            DEFAULT_YAML,
            &["ros.qos.estimates.durability=transient_local"],
        )
        .unwrap();
        assert_eq!(c.ros.qos.estimates.durability, Durability::TransientLocal);
    }

    #[test]
    fn wrong_file_layout_is_explained() {
        let e = load("contact:\n  load_n: 1\n", &[]).unwrap_err();
        assert!(e.to_string().contains("`contact` is not this node"), "{e}");
        let e = load("friction_node:\n  params: {}\n", &[]).unwrap_err();
        assert!(e.to_string().contains("ros__parameters"), "{e}");
        let e = load("friction_node: [", &[]).unwrap_err();
        assert!(matches!(e, ConfigError::Syntax { .. }));
        assert!(load(
            "/**:\n  ros__parameters:\n    contact: {load_n: 100.0}\n",
            &[]
        )
        .is_ok());
        assert!(load("/robot/friction_node:\n  ros__parameters: {}\n", &[]).is_ok());
    }

    #[test]
    fn texture_arrays_must_have_equal_lengths_and_fit_the_slider() {
        let base = "friction_node:\n  ros__parameters:\n    texture:\n";
        let e = load(&format!("{base}      pocket_start_m: [0.01]\n      pocket_width_m: []\n      pocket_depth_m: [1e-6]\n"), &[]).unwrap_err();
        assert!(e.to_string().contains("texture.pocket_width_m"), "{e}");
        let e = load(&format!("{base}      pocket_start_m: [0.07]\n      pocket_width_m: [0.01]\n      pocket_depth_m: [1e-6]\n"), &[]).unwrap_err();
        assert!(e.to_string().contains("texture.pocket_width_m[0]"), "{e}");
        let c = load(&format!("{base}      pocket_start_m: [0.01]\n      pocket_width_m: [0.005]\n      pocket_depth_m: [5e-6]\n"), &[]).unwrap();
        assert_eq!(c.model().geometry.pockets.len(), 1);
    }

    #[test]
    fn resolved_config_round_trips_through_yaml() {
        let c = load(
            DEFAULT_YAML,
            &[
                "contact.load_n=1234.5",
                "texture.pocket_start_m=[0.01]",
                "texture.pocket_width_m=[0.002]",
                "texture.pocket_depth_m=[3e-6]",
            ],
        )
        .unwrap();
        let again = Config::from_yaml(&c.to_yaml(), &Origin::Embedded, &[]).unwrap();
        assert_eq!(again, c);
    }
}
