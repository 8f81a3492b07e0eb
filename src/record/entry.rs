//! What the recorder writes: every item as a serialized message on one of
//! the node's topics, ready for any file (a single recording, a split file,
//! a snapshot).

use super::WriteError;
use crate::config::{CommandType, OutputPlan};
use crate::link::FilmProfileData;
use crate::link::RecordItem;
use crate::msgs::command_codec::CommandMessage;
use crate::msgs::{self, Command, CommandKind, EstimateRecord, Float64, Header, Time};

/// The node's recorded topics.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum TopicId {
    /// The commanded velocity.
    Velocity,
    /// The normal load.
    Load,
    /// The full estimate (FrictionEstimate).
    Friction,
    /// The friction force alone (Float64).
    FrictionForce,
    /// The film profile.
    FilmProfile,
    /// LoopStatistics.
    Statistics,
    /// The lubricant temperature.
    Temperature,
    /// `/parameter_events`: parameters changed while running, stamped with
    /// the first step that used them (replay re-applies them there).
    ParameterEvents,
    /// Several contacts: the joint velocity commands (`sensor_msgs/JointState`).
    JointCommands,
    /// Several contacts: contact k's FrictionEstimate (`~/contacts/NAME/friction`).
    ContactFriction(u16),
}

/// Topics before the per-contact ones.
pub const BASE_TOPICS: usize = 9;

impl TopicId {
    /// Dense index: the base topics, then one per contact.
    pub fn index(self) -> usize {
        match self {
            TopicId::Velocity => 0,
            TopicId::Load => 1,
            TopicId::Friction => 2,
            TopicId::FrictionForce => 3,
            TopicId::FilmProfile => 4,
            TopicId::Statistics => 5,
            TopicId::Temperature => 6,
            TopicId::ParameterEvents => 7,
            TopicId::JointCommands => 8,
            TopicId::ContactFriction(k) => BASE_TOPICS + usize::from(k),
        }
    }
}

impl Encoder {
    /// The encoder of a recording of `config`.
    pub fn new(config: &crate::config::Config) -> Self {
        Self {
            frame_id: config.node.frame_id.clone(),
            command_type: config.ros.command_type,
            plan: config.output_plan(),
        }
    }
}

/// One serialized message.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// The topic it was on.
    pub topic: TopicId,
    /// When it was received or recorded (wall clock), ns.
    pub log_ns: u64,
    /// The publisher's stamp, ns.
    pub publish_ns: u64,
    /// CDR with its encapsulation header.
    pub data: Vec<u8>,
}

impl Entry {
    /// Bytes it holds in memory (for the snapshot ring's bound).
    pub fn footprint(&self) -> usize {
        self.data.capacity() + std::mem::size_of::<Entry>()
    }
}

/// Turns items into entries.
#[derive(Debug, Clone)]
pub struct Encoder {
    /// The frame id stamped on messages with a header.
    pub frame_id: String,
    /// How commanded velocities are recorded (Float64 or TwistStamped).
    pub command_type: CommandType,
    /// The configuration's output plan, as decided once: with joints,
    /// estimates go to their contact's topic and joint commands to the
    /// JointState topic; with one contact, to the friction topics.
    pub plan: OutputPlan,
}

fn cdr<T: serde::Serialize>(topic: TopicId, m: &T) -> Result<Vec<u8>, WriteError> {
    msgs::to_cdr(m).map_err(|error| WriteError::Encode { topic, error })
}

/// The topic a command of `kind` is recorded on.
fn command_topic(kind: CommandKind) -> TopicId {
    match kind {
        CommandKind::Velocity => TopicId::Velocity,
        CommandKind::JointVelocity { .. } => TopicId::JointCommands,
        CommandKind::Load => TopicId::Load,
        CommandKind::Temperature => TopicId::Temperature,
    }
}

impl Encoder {
    fn command(&self, c: &Command, received_ns: u64) -> Result<Entry, WriteError> {
        let joint = match c.kind {
            CommandKind::JointVelocity { contact, .. } => Some(
                self.plan
                    .joints()
                    .get(usize::from(contact))
                    .ok_or(WriteError::NoSuchContact {
                        what: "a joint velocity",
                        contact,
                        contacts: self.plan.joints().len(),
                    })?
                    .as_str(),
            ),
            _ => None,
        };
        let topic = command_topic(c.kind);
        let data = CommandMessage::of(c, self.command_type, &self.frame_id, joint)
            .ok_or(msgs::CdrError::JointByName)
            .and_then(|m| m.to_cdr())
            .map_err(|error| WriteError::Encode { topic, error })?;
        Ok(Entry {
            topic,
            log_ns: received_ns,
            publish_ns: c.stamp_ns,
            data,
        })
    }

    /// The entries of one item (an estimate is two: the full estimate and
    /// the plain friction force), logged when the item says it was received
    /// or published.
    pub fn encode(&self, item: &RecordItem, out: &mut Vec<Entry>) -> Result<(), WriteError> {
        match item {
            RecordItem::Command {
                command,
                received_ns,
            } => out.push(self.command(command, *received_ns)?),
            RecordItem::Raw(r) => out.push(Entry {
                topic: command_topic(r.kind),
                log_ns: r.received_ns,
                publish_ns: r.publish_ns,
                data: r.cdr.clone(),
            }),
            &RecordItem::Estimate {
                record: ref e,
                logged_ns,
                contact,
            } => self.estimate(e, logged_ns, contact, out)?,
            &RecordItem::Statistics {
                record: ref s,
                logged_ns: log_ns,
            } => out.push(Entry {
                topic: TopicId::Statistics,
                log_ns,
                publish_ns: s.stamp_ns,
                data: cdr(TopicId::Statistics, &s.to_wire(&self.frame_id))?,
            }),
            RecordItem::ParameterEvent {
                cdr,
                stamp_ns,
                logged_ns,
            } => out.push(Entry {
                topic: TopicId::ParameterEvents,
                log_ns: *logged_ns,
                publish_ns: *stamp_ns,
                data: cdr.clone(),
            }),
        }
        Ok(())
    }

    /// An estimate's entries: per joint its contact-friction topic; with
    /// one contact the full estimate and the plain friction force.
    fn estimate(
        &self,
        e: &EstimateRecord,
        log_ns: u64,
        contact: u16,
        out: &mut Vec<Entry>,
    ) -> Result<(), WriteError> {
        if let OutputPlan::Joints(joints) = &self.plan {
            if usize::from(contact) >= joints.len() {
                return Err(WriteError::NoSuchContact {
                    what: "an estimate",
                    contact,
                    contacts: joints.len(),
                });
            }
            out.push(Entry {
                topic: TopicId::ContactFriction(contact),
                log_ns,
                publish_ns: e.stamp_ns,
                data: cdr(
                    TopicId::ContactFriction(contact),
                    &e.to_wire(&self.frame_id),
                )?,
            });
            return Ok(());
        }
        if contact != 0 {
            return Err(WriteError::NoSuchContact {
                what: "an estimate",
                contact,
                contacts: 1,
            });
        }
        out.push(Entry {
            topic: TopicId::Friction,
            log_ns,
            publish_ns: e.stamp_ns,
            data: cdr(TopicId::Friction, &e.to_wire(&self.frame_id))?,
        });
        out.push(Entry {
            topic: TopicId::FrictionForce,
            log_ns,
            publish_ns: e.stamp_ns,
            data: cdr(
                TopicId::FrictionForce,
                &Float64 {
                    data: e.friction_force_n,
                },
            )?,
        });
        Ok(())
    }

    /// A film profile's entry.
    pub fn film_profile(&self, p: FilmProfileData, log_ns: u64) -> Result<Entry, WriteError> {
        let stamp = p.stamp_ns;
        let m = msgs::FilmProfile {
            header: Header {
                stamp: Time::from_ns(stamp),
                frame_id: self.frame_id.clone(),
            },
            dx_m: p.dx_m,
            h_m: p.h_m,
            p_pa: p.p_pa,
        };
        Ok(Entry {
            topic: TopicId::FilmProfile,
            log_ns,
            publish_ns: stamp,
            data: cdr(TopicId::FilmProfile, &m)?,
        })
    }
}
