//! The node's sections of the configuration: `node`, `ros`, `iceoryx2`,
//! `recording`.

use super::DEFAULT_NODE_NAME;
use serde::{Deserialize, Serialize};

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
    /// ROS 2 (ros2-client, DDS).
    Ros2,
    /// iceoryx2 shared memory on one host.
    Iceoryx2,
    /// Both at once.
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

/// `node.outside_envelope`: what a contact publishes while its input lies
/// outside its `calibrated_range` (a contact without one is not watched).
/// Every estimate outside carries `RANGE_OUTSIDE` whatever the choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum OutsideEnvelope {
    /// The model's value: physics past the data, which may be right (the
    /// model's terms are physical) or not (a fitted term extrapolated).
    #[default]
    Warn,
    /// The model's value with the input clamped to the nearest edge of the
    /// range: bounded by what was calibrated, but blind to a real rise or
    /// fall beyond it.
    Hold,
    /// No feed-forward (friction 0): the controller's feedback carries it
    /// alone; the conservative choice when a wrong sign or size costs more
    /// than a missing one.
    Zero,
}

impl OutsideEnvelope {
    /// The name in the configuration.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::Warn => "warn",
            Self::Hold => "hold",
            Self::Zero => "zero",
        }
    }
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
    /// Pin contact worker k (1, 2, …) to `worker_cpus[k - 1]`; workers
    /// beyond the list are not pinned (they share the other settings).
    pub worker_cpus: Vec<i32>,
}

impl Default for RealtimeConfig {
    fn default() -> Self {
        Self {
            fifo: false,
            priority: 80,
            lock_memory: false,
            cpu: -1,
            worker_cpus: Vec::new(),
        }
    }
}

/// `node.*`: the fixed-step loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NodeConfig {
    /// `node.step_mode`: timer: fixed real-time steps; lockstep: one step per velocity command.
    pub step_mode: StepMode,
    /// `node.transport`: ros2 | iceoryx2 | both (run --transport overrides)
    pub transport: TransportKind,
    /// Velocity of the steady state the node starts from, m/s.
    pub initial_velocity_m_s: f64,
    /// A velocity command older than this is stale, s.
    pub command_timeout_s: f64,
    /// `node.timeout_behaviour`: hold: keep the last velocity; ramp_to_zero: decelerate.
    pub timeout_behaviour: TimeoutBehaviour,
    /// `node.outside_envelope`: warn | hold | zero — what a contact publishes
    /// while its input lies outside its calibrated range.
    pub outside_envelope: OutsideEnvelope,
    /// `node.timeout_deceleration_m_s2`: deceleration of ramp_to_zero — range (0, 1e4]
    pub timeout_deceleration_m_s2: f64,
    /// Commands with |v| above this are rejected, m/s.
    pub max_abs_velocity_m_s: f64,
    /// Load commands outside [min, max] are rejected, N.
    pub min_load_n: f64,
    /// `node.max_load_n`: load commands above this are rejected, N.
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
    /// Timer mode: busy-wait this long before each deadline instead of
    /// sleeping, µs (0 = sleep; the period or more = the loop never sleeps).
    /// A spinning loop keeps its core, caches and branch predictors to
    /// itself, so a step after the wait costs what a step in a tight loop
    /// does; it costs one busy core.
    pub timer_spin_us: u64,
    /// Timer mode: a loop that wakes up late catches up the lost steps one
    /// by one (model time = wall time) when it is at most this far behind,
    /// s; further behind, it advances the lost time in one backward-Euler
    /// step and restarts BDF2.
    pub max_catch_up_s: f64,
    /// Worker threads that step contacts beside the loop's own thread
    /// (0: the loop steps every contact; at most one fewer than the
    /// contacts). They wait for each step spinning (up to 50 µs, or
    /// `lockstep_spin_us` if longer), then parked.
    pub contact_workers: usize,
    /// `node.realtime`: applied when permitted, with a warning otherwise.
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
            outside_envelope: OutsideEnvelope::Warn,
            timeout_deceleration_m_s2: 1.0,
            max_abs_velocity_m_s: 10.0,
            min_load_n: 1.0,
            max_load_n: 1e7,
            profile_rate_hz: 10.0,
            statistics_rate_hz: 1.0,
            queue_capacity: 4096,
            frame_id: "slider".into(),
            lockstep_spin_us: 0,
            timer_spin_us: 0,
            max_catch_up_s: 0.1,
            contact_workers: 0,
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

/// `ros.command_type`: the wire's choice, defined with the messages.
pub use crate::msgs::command_codec::CommandType;

/// `ros.qos.*`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Reliability {
    /// `best_effort`.
    BestEffort,
    /// `reliable`.
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
    /// `ros.qos.commands.reliability`: best_effort | reliable.
    pub reliability: Reliability,
    /// Keep-last depth.
    pub depth: usize,
    /// `ros.qos.commands.durability`: volatile | transient_local (late readers get the last depth
    /// samples)
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
    /// The `ros.qos.commands` section.
    pub commands: QosConfig,
    /// The `ros.qos.estimates` section.
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
    /// `ros.topics.cmd_velocity`: the commanded velocity (std_msgs/Float64 or TwistStamped).
    pub cmd_velocity: String,
    /// `ros.topics.normal_load`: the normal load command (std_msgs/Float64, N).
    pub normal_load: String,
    /// `sensor_msgs/msg/Temperature` of the lubricant, °C.
    pub temperature: String,
    /// `ros.topics.friction`: the estimate (friction_msgs/FrictionEstimate).
    pub friction: String,
    /// `ros.topics.friction_force`: the friction force alone (std_msgs/Float64, N).
    pub friction_force: String,
    /// `ros.topics.film_profile`: the film along the slider (friction_msgs/FilmProfile).
    pub film_profile: String,
    /// `ros.topics.loop_statistics`: the loop's health (friction_msgs/LoopStatistics).
    pub loop_statistics: String,
    /// Several contacts: `sensor_msgs/msg/JointState`, velocities by joint
    /// name (m/s of each contact's slider).
    pub joint_commands: String,
    /// Several contacts: `std_msgs/msg/Float64MultiArray` of efforts in the
    /// configured joint order (a forward_command_controller's input).
    pub joint_efforts: String,
    /// Several contacts: `sensor_msgs/msg/JointState` with the efforts.
    pub joint_friction: String,
    /// Several contacts: the prefix of each contact's FrictionEstimate
    /// topic, `<contact_friction>/<contact name>/friction`.
    pub contact_friction: String,
}

impl Default for TopicsConfig {
    fn default() -> Self {
        Self {
            cmd_velocity: "~/cmd_velocity".into(),
            normal_load: "~/normal_load".into(),
            temperature: "~/temperature".into(),
            friction: "~/friction".into(),
            friction_force: "~/friction_force".into(),
            film_profile: "~/film_profile".into(),
            loop_statistics: "~/loop_statistics".into(),
            joint_commands: "~/joint_commands".into(),
            joint_efforts: "~/joint_efforts".into(),
            joint_friction: "~/joint_friction".into(),
            contact_friction: "~/contacts".into(),
        }
    }
}

/// `ros.*`: ROS 2 conventions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RosConfig {
    /// `ros.node_name`: the node's name.
    pub node_name: String,
    /// `ros.namespace`: the node's namespace.
    pub namespace: String,
    /// DDS domain; -1 = ROS_DOMAIN_ID (or 0 when unset).
    pub domain_id: i64,
    /// `ros.discovery_range`: localhost | subnet | off | env (ROS_AUTOMATIC_DISCOVERY_RANGE /
    /// ROS_LOCALHOST_ONLY)
    pub discovery_range: DiscoveryRange,
    /// `ros.command_type`: float64: std_msgs/Float64; twist_stamped: geometry_msgs/TwistStamped
    /// linear.x.
    pub command_type: CommandType,
    /// `ros.topics`: ~/ is the node's private namespace.
    pub topics: TopicsConfig,
    /// The `ros.qos` section: quality of service of commands and estimates.
    pub qos: QosProfiles,
    /// Topic remappings `FROM:=TO` (what `--ros-args -r` gives), applied
    /// to every topic the node has, `~/` ones included.
    pub remappings: Vec<String>,
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
            remappings: Vec::new(),
        }
    }
}

/// `iceoryx2.*`: service names of the zero-copy IPC transport.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Iceoryx2Config {
    /// `iceoryx2.cmd_velocity_service`: the commanded velocity.
    pub cmd_velocity_service: String,
    /// `iceoryx2.normal_load_service`: the normal load command.
    pub normal_load_service: String,
    /// `iceoryx2.temperature_service`: the temperature command.
    pub temperature_service: String,
    /// `iceoryx2.friction_service`: the estimates.
    pub friction_service: String,
    /// `iceoryx2.loop_statistics_service`: the loop statistics.
    pub loop_statistics_service: String,
    /// Event service that wakes a lockstep node when a command is sent.
    pub cmd_event_service: String,
    /// Several contacts: JointState-like velocities by joint name.
    pub joint_state_service: String,
    /// Several contacts: every contact's effort in joint order.
    pub efforts_service: String,
    /// Several contacts: each contact's estimate (tagged with its index).
    pub contact_friction_service: String,
}

impl Default for Iceoryx2Config {
    fn default() -> Self {
        Self {
            cmd_velocity_service: "friction_node/cmd_velocity".into(),
            normal_load_service: "friction_node/normal_load".into(),
            temperature_service: "friction_node/temperature".into(),
            friction_service: "friction_node/friction".into(),
            loop_statistics_service: "friction_node/loop_statistics".into(),
            cmd_event_service: "friction_node/cmd_event".into(),
            joint_state_service: "friction_node/joint_states".into(),
            efforts_service: "friction_node/joint_efforts".into(),
            contact_friction_service: "friction_node/contact_friction".into(),
        }
    }
}

/// `recording.compression`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Compression {
    /// No compression.
    None,
    /// zstd (the default).
    Zstd,
    /// lz4.
    Lz4,
}

/// `recording.split.*`: rosbag2-style split files (0 = off).
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SplitConfig {
    /// Start a new file when the current one reaches this size, bytes.
    pub max_bytes: u64,
    /// Start a new file when the current one spans this much recorded time, s.
    pub max_duration_s: u64,
}

/// `recording.*`: MCAP recording (the `run --record PATH` flag enables it).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RecordingConfig {
    /// `recording.enabled`: record every run (`run --record FILE` enables it too).
    pub enabled: bool,
    /// File (no split) or directory (split) to write; empty =
    /// `bags/friction_node_<UTC time>.mcap` (or that name without `.mcap`).
    pub path: String,
    /// Chunk size, bytes: a crash loses at most the open chunk.
    pub chunk_size_bytes: u64,
    /// `recording.compression`: zstd | lz4 | none.
    pub compression: Compression,
    /// `recording.split`: rosbag2-style split files in a directory (0 = off: one file)
    pub split: SplitConfig,
    /// Split recordings: delete the oldest files when the directory's files
    /// exceed this many bytes (0 = no limit).
    pub budget_bytes: u64,
    /// Keep the last this many seconds of every topic in memory, written
    /// as one MCAP file on request (SIGUSR1, `~/snapshot`); 0 = off.
    pub snapshot_s: u64,
    /// The most memory the snapshot ring may use, bytes.
    pub snapshot_max_bytes: u64,
}

impl RecordingConfig {
    /// Whether the recording is a directory of split files.
    pub fn splits(&self) -> bool {
        self.split.max_bytes > 0 || self.split.max_duration_s > 0
    }
}

impl Default for RecordingConfig {
    fn default() -> Self {
        Self {
            enabled: false,
            path: String::new(),
            chunk_size_bytes: 256 * 1024,
            compression: Compression::Zstd,
            split: SplitConfig::default(),
            budget_bytes: 0,
            snapshot_s: 0,
            snapshot_max_bytes: 256 << 20,
        }
    }
}
