//! What drives a replay: a velocity topic, a friction-node bag's recorded
//! estimates (one contact or several), or a JointState topic for several
//! contacts.

use crate::bag::SampleKind;

/// What drives the replay.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum InputMode {
    /// A velocity (and optional load) topic.
    Topics {
        /// The velocity topic.
        velocity: String,
        /// How its messages carry the velocity.
        kind: SampleKind,
        /// The load topic, if any.
        load: Option<String>,
        /// The temperature topic, if any.
        temperature: Option<String>,
    },
    /// A friction-node bag: the recorded estimates' velocity and load.
    RecordedEstimates {
        /// The FrictionEstimate topic.
        topic: String,
    },
    /// A friction-node bag of several contacts: each contact's recorded
    /// estimates (configured order), stepped together.
    RecordedContacts {
        /// Each contact's FrictionEstimate topic, in configured order.
        topics: Vec<String>,
    },
    /// Several contacts from a `sensor_msgs/JointState` topic: every
    /// configured joint's velocity, resampled onto the step grid like one
    /// joint's, and the load and temperature topics (applied to every
    /// contact).
    JointStates {
        /// The JointState topic.
        topic: String,
        /// The configured joints, one per contact.
        joints: Vec<String>,
        /// The load topic, if any (every contact).
        load: Option<String>,
        /// The temperature topic, if any (every contact).
        temperature: Option<String>,
    },
}

impl InputMode {
    /// Whether the replay has recorded estimates to compare with (the
    /// determinism oracle).
    pub fn has_recorded_estimates(&self) -> bool {
        matches!(
            self,
            InputMode::RecordedEstimates { .. } | InputMode::RecordedContacts { .. }
        )
    }

    /// One line for logs and reports.
    pub fn describe(&self) -> String {
        match self {
            InputMode::Topics {
                velocity,
                kind,
                load,
                temperature,
            } => format!(
                "velocity `{velocity}` ({}){}{}",
                match kind {
                    SampleKind::TwistLinearX =>
                        "geometry_msgs/msg/TwistStamped, linear.x".to_string(),
                    SampleKind::JointVelocity(joint) =>
                        format!("sensor_msgs/msg/JointState, joint `{joint}`"),
                    other => other.msg_type().full_name(),
                },
                load.as_ref()
                    .map_or(String::new(), |l| format!(", load `{l}`")),
                temperature
                    .as_ref()
                    .map_or(String::new(), |t| format!(", temperature `{t}`"))
            ),
            InputMode::RecordedEstimates { topic } => {
                format!("the recorded estimates `{topic}` (velocity and load each step applied)")
            }
            InputMode::RecordedContacts { topics } => format!(
                "the recorded estimates of {} contacts (`{}` …; velocity and load each step applied)",
                topics.len(),
                topics.first().map_or("", String::as_str)
            ),
            InputMode::JointStates {
                topic,
                joints,
                load,
                temperature,
            } => format!(
                "velocity of joints {} from `{topic}` (sensor_msgs/msg/JointState){}{}",
                joints.join(", "),
                load.as_ref()
                    .map_or(String::new(), |l| format!(", load `{l}`")),
                temperature
                    .as_ref()
                    .map_or(String::new(), |t| format!(", temperature `{t}`"))
            ),
        }
    }
}
