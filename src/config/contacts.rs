//! `contacts.*`: several lubricated contacts in one node (the carriages of a
//! linear stage, the axes of a gantry, the sliding pair of each joint).
//!
//! ```yaml
//! contacts:                 # name → contact; none: the top-level sections are the one contact
//!   carriage_left:
//!     joint: axis_x         # the joint whose velocity drives it and whose effort it adds to
//!     gain: 1.0             # the joint's transmission: contact speed = gain × joint velocity, joint effort = gain × friction force; 1 (linear joint, m/s and N) or the lever arm in m (rotary: rad/s and N·m)
//!     contact: {load_n: 5000.0}
//!     solver: {cells: 128}
//!   carriage_y:
//!     joint: axis_y
//! ```
//!
//! A ROS 2 parameter cannot hold a list of structs, so the contacts are a
//! mapping keyed by name (the file's order is kept, and is the order of
//! the node's outputs), as ros2_control keys per-joint parameters by joint
//! name: every key is a dotted parameter `contacts.NAME.contact.load_n`.
//!
//! Each contact's `contact`, `texture`, `lubricant` and `roughness`
//! sections and its `solver.cells` start from the top-level values and
//! override only the keys they give; `joint` defaults to the contact's name
//! and `gain` to 1. The resolved contacts are what the configuration holds
//! after loading (so `to_yaml` writes every key of every contact).

use super::model::{ContactConfig, LubricantConfig, RoughnessConfig, TextureConfig};
use super::{CalibratedRange, Config, ConfigError};
use serde::de::{MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use serde_norway::{Mapping, Value};

/// Most contacts one node serves (its joint messages are fixed-size on
/// the loop).
pub const MAX_CONTACTS: usize = 64;

/// Longest joint name, bytes (iceoryx2 carries names in fixed fields).
pub const MAX_JOINT_NAME_BYTES: usize = 64;

/// The sections a contact overrides key by key.
pub const CONTACT_SECTIONS: [&str; 4] = ["contact", "texture", "lubricant", "roughness"];

/// One configured contact (resolved: every section complete).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactEntry {
    /// The key under `contacts`.
    pub name: String,
    /// The joint that drives it (its velocity) and takes its effort.
    pub joint: String,
    /// The joint's transmission, m per joint unit: the contact slides at
    /// `gain` × the joint's velocity and puts `gain` × its friction force
    /// on the joint (power is kept). 1 for a linear joint (m/s, N), the
    /// lever arm in m for a rotary one (rad/s, N·m).
    pub gain: f64,
    /// Overrides of the `contact` section.
    pub contact: ContactConfig,
    /// Overrides of the `texture` section.
    pub texture: TextureConfig,
    /// Overrides of the `lubricant` section.
    pub lubricant: LubricantConfig,
    /// Overrides of the `roughness` section.
    pub roughness: RoughnessConfig,
    /// Overrides of the `solver` section (its grid).
    pub solver: ContactSolverConfig,
    /// Where this contact was calibrated (absent: not watched).
    pub calibrated_range: Option<CalibratedRange>,
}

/// `contacts.NAME.solver.*`: what a contact may change of the solver.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ContactSolverConfig {
    /// `solver.cells` of this contact.
    pub cells: usize,
}

impl Default for ContactSolverConfig {
    fn default() -> Self {
        Self {
            cells: super::SolverConfig::default().cells,
        }
    }
}

/// A contact's body in the file (its name is the key).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ContactBody {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    joint: Option<String>,
    #[serde(default = "unit_gain")]
    gain: f64,
    #[serde(default)]
    contact: ContactConfig,
    #[serde(default)]
    texture: TextureConfig,
    #[serde(default)]
    lubricant: LubricantConfig,
    #[serde(default)]
    roughness: RoughnessConfig,
    #[serde(default)]
    solver: ContactSolverConfig,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    calibrated_range: Option<CalibratedRange>,
}

fn unit_gain() -> f64 {
    1.0
}

/// `contacts`: the configured contacts in file order (empty: the top-level
/// sections are the one contact).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ContactList(pub Vec<ContactEntry>);

impl ContactList {
    /// Whether no contact is configured (the top level is the one contact).
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

impl Serialize for ContactList {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut map = s.serialize_map(Some(self.0.len()))?;
        for e in &self.0 {
            let body = ContactBody {
                joint: Some(e.joint.clone()),
                gain: e.gain,
                contact: e.contact.clone(),
                texture: e.texture.clone(),
                lubricant: e.lubricant.clone(),
                roughness: e.roughness.clone(),
                solver: e.solver.clone(),
                calibrated_range: e.calibrated_range.clone(),
            };
            map.serialize_entry(&e.name, &body)?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for ContactList {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct ListVisitor;
        impl<'de> Visitor<'de> for ListVisitor {
            type Value = ContactList;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a mapping of contact name to its keys")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<ContactList, A::Error> {
                let mut out = Vec::new();
                while let Some(name) = map.next_key::<String>()? {
                    let b: ContactBody = map.next_value()?;
                    out.push(ContactEntry {
                        joint: b.joint.unwrap_or_else(|| name.clone()),
                        name,
                        gain: b.gain,
                        contact: b.contact,
                        texture: b.texture,
                        lubricant: b.lubricant,
                        roughness: b.roughness,
                        solver: b.solver,
                        calibrated_range: b.calibrated_range,
                    });
                }
                Ok(ContactList(out))
            }
        }
        d.deserialize_map(ListVisitor)
    }
}

/// Fill every contact's sections from the top-level ones before the tree
/// is read: a contact's keys override, the rest are the top-level values.
/// Anything malformed is left for the typed reading to report by key.
pub(super) fn inherit_top_level(params: &mut Value) {
    let Value::Mapping(root) = params else { return };
    let top = |k: &str| match root.get(k) {
        Some(Value::Mapping(m)) => m.clone(),
        _ => Mapping::new(),
    };
    let sections: Vec<Mapping> = CONTACT_SECTIONS.iter().map(|s| top(s)).collect();
    let cells = match root.get("solver") {
        Some(Value::Mapping(m)) => m.get("cells").cloned(),
        _ => None,
    };
    let Some(Value::Mapping(contacts)) = root.get_mut("contacts") else {
        return;
    };
    for (_, body) in contacts.iter_mut() {
        let Value::Mapping(body) = body else { continue };
        for (section, base) in CONTACT_SECTIONS.iter().zip(&sections) {
            let mut merged = base.clone();
            match body.get(*section) {
                None => {}
                Some(Value::Mapping(own)) => {
                    for (k, v) in own {
                        merged.insert(k.clone(), v.clone());
                    }
                }
                Some(_) => continue, // not a mapping: the typed reading names it
            }
            body.insert(Value::String((*section).into()), Value::Mapping(merged));
        }
        if let Some(cells) = &cells {
            match body.get_mut("solver") {
                None => {
                    let mut m = Mapping::new();
                    m.insert(Value::String("cells".into()), cells.clone());
                    body.insert(Value::String("solver".into()), Value::Mapping(m));
                }
                Some(Value::Mapping(m)) if !m.contains_key("cells") => {
                    m.insert(Value::String("cells".into()), cells.clone());
                }
                Some(_) => {}
            }
        }
    }
}

/// One contact as the model sees it: its name, joint, gain and the
/// configuration with its own sections in place of the top-level ones.
#[derive(Debug, Clone, PartialEq)]
pub struct ResolvedContact {
    /// The contact's name.
    pub name: String,
    /// The joint whose velocity drives it.
    pub joint: String,
    /// Friction force → joint effort (1, or the lever arm in m).
    pub gain: f64,
    /// The whole configuration of this contact (its sections over the top
    /// level; its `calibrated_range` in the contact's own m/s and N).
    pub config: Config,
    /// A joint's calibrated range as configured, in the joint's units
    /// (`contacts.NAME.calibrated_range`); None for the one contact, whose
    /// range is `config.calibrated_range`.
    pub joint_range: Option<CalibratedRange>,
}

/// The name of the one contact of a configuration without `contacts`.
pub const SINGLE_CONTACT_NAME: &str = "contact";

/// How the node meets the world, decided once from the configuration:
/// the loop, the transports, the recorder, replay and the topic names all
/// ask this, never the number of contacts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum OutputPlan {
    /// No `contacts` list: the one contact of the top-level sections,
    /// driven by velocity commands (Float64 or TwistStamped), its estimate
    /// on `ros.topics.friction` and its force alone (Float64) on
    /// `ros.topics.friction_force`.
    OneContact,
    /// Listed contacts (one or more), each driven by its joint's velocity
    /// in a JointState: each estimate on its contact's own topic, and the
    /// joints' efforts (gain × friction) as one array per step. The joints
    /// in the configured order.
    Joints(Vec<String>),
}

impl OutputPlan {
    /// The joints, in the configured order (none for one contact).
    pub fn joints(&self) -> &[String] {
        match self {
            Self::OneContact => &[],
            Self::Joints(j) => j,
        }
    }

    /// Whether the contacts are driven by joints.
    pub fn by_joint(&self) -> bool {
        matches!(self, Self::Joints(_))
    }
}

impl Config {
    /// The output plan: [`OutputPlan::Joints`] whenever `contacts` lists
    /// any (a rotary joint fitted by `fit --rotary` is one listed
    /// contact), else [`OutputPlan::OneContact`].
    pub fn output_plan(&self) -> OutputPlan {
        if self.contacts.0.is_empty() {
            OutputPlan::OneContact
        } else {
            OutputPlan::Joints(self.contacts.0.iter().map(|c| c.joint.clone()).collect())
        }
    }

    /// Every contact with its own configuration; a configuration without
    /// `contacts` is one contact named `contact` on joint `""`, gain 1.
    pub fn resolved_contacts(&self) -> Vec<ResolvedContact> {
        if self.contacts.is_empty() {
            return vec![ResolvedContact {
                name: SINGLE_CONTACT_NAME.into(),
                joint: String::new(),
                gain: 1.0,
                config: Config {
                    contacts: ContactList::default(),
                    ..self.clone()
                },
                joint_range: None,
            }];
        }
        self.contacts
            .0
            .iter()
            .map(|e| self.for_contact(e))
            .collect()
    }

    fn for_contact(&self, e: &ContactEntry) -> ResolvedContact {
        let mut config = Config {
            contacts: ContactList::default(),
            contact: e.contact.clone(),
            texture: e.texture.clone(),
            lubricant: e.lubricant.clone(),
            roughness: e.roughness.clone(),
            calibrated_range: e
                .calibrated_range
                .as_ref()
                .map(|r| r.in_contact_units(e.gain)),
            ..self.clone()
        };
        config.solver.cells = e.solver.cells;
        ResolvedContact {
            name: e.name.clone(),
            joint: e.joint.clone(),
            gain: e.gain,
            config,
            joint_range: e.calibrated_range.clone(),
        }
    }

    /// `contacts.*`: names, joints and gains, then every contact's own
    /// sections with their physical ranges (errors name
    /// `contacts.NAME.section.key`).
    pub(super) fn validate_contacts(&self) -> Result<(), ConfigError> {
        let mut joints: Vec<(&str, &str)> = Vec::new();
        if self.contacts.0.len() > MAX_CONTACTS {
            return Err(ConfigError::OutOfRange {
                key: "contacts".into(),
                value: format!("{} contacts", self.contacts.0.len()),
                range: format!("at most {MAX_CONTACTS} contacts per node (run several nodes)"),
            });
        }
        for e in &self.contacts.0 {
            let key = |k: &str| format!("contacts.{}.{k}", e.name);
            if let Err(why) = check_contact_name(&e.name) {
                return Err(ConfigError::InvalidValue {
                    key: format!("contacts.{}", e.name),
                    message: format!("contact name `{}` {why}", e.name),
                });
            }
            if e.joint.trim().is_empty() || e.joint.chars().any(char::is_control) {
                return Err(ConfigError::InvalidValue {
                    key: key("joint"),
                    message: format!("joint name {:?} must be non-empty text", e.joint),
                });
            }
            if e.joint.len() > MAX_JOINT_NAME_BYTES {
                return Err(ConfigError::InvalidValue {
                    key: key("joint"),
                    message: format!(
                        "joint name `{}` is {} bytes long: at most {MAX_JOINT_NAME_BYTES}",
                        e.joint,
                        e.joint.len()
                    ),
                });
            }
            if let Some((other, _)) = joints.iter().find(|(_, j)| *j == e.joint) {
                return Err(ConfigError::InvalidValue {
                    key: key("joint"),
                    message: format!(
                        "joint `{}` is already the joint of contact `{other}`: one contact per joint \
                         (give the contacts of one axis one joint each, or one contact with their combined load)",
                        e.joint
                    ),
                });
            }
            joints.push((&e.name, &e.joint));
            if !(e.gain.is_finite() && e.gain > 0.0 && e.gain <= 1e3) {
                return Err(ConfigError::OutOfRange {
                    key: key("gain"),
                    value: e.gain.to_string(),
                    range: "(0, 1e3] (1 for a linear joint, the lever arm in m for a rotary one)"
                        .into(),
                });
            }
            let c = self.for_contact(e).config;
            c.validate_contact()
                .and_then(|_| c.validate_texture())
                .and_then(|_| c.validate_lubricant())
                .and_then(|_| c.validate_roughness())
                .and_then(|_| c.validate_solver())
                .map_err(|err| prefix_key(err, &format!("contacts.{}.", e.name)))?;
            if let Some(r) = &e.calibrated_range {
                r.validate(&key("calibrated_range"), true)?;
            }
        }
        if self.calibrated_range.is_some() && !self.contacts.0.is_empty() {
            return Err(ConfigError::InvalidValue {
                key: "calibrated_range".into(),
                message:
                    "with `contacts`, each contact has its own: contacts.NAME.calibrated_range"
                        .into(),
            });
        }
        Ok(())
    }
}

/// A contact name is one segment of a ROS 2 parameter name.
fn check_contact_name(s: &str) -> Result<(), &'static str> {
    let mut chars = s.chars();
    match chars.next() {
        None => Err("is empty"),
        Some(c) if !(c.is_ascii_alphabetic() || c == '_') => {
            Err("must start with a letter or `_` (it is a ROS 2 parameter name segment)")
        }
        _ if !s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') => {
            Err("may hold only letters, digits and `_` (it is a ROS 2 parameter name segment)")
        }
        _ => Ok(()),
    }
}

/// The same error about `PREFIX + key`.
fn prefix_key(err: ConfigError, prefix: &str) -> ConfigError {
    match err {
        ConfigError::OutOfRange { key, value, range } => ConfigError::OutOfRange {
            key: format!("{prefix}{key}"),
            value,
            range,
        },
        ConfigError::InvalidValue { key, message } => ConfigError::InvalidValue {
            key: format!("{prefix}{key}"),
            message,
        },
        ConfigError::UnknownKey { key, message } => ConfigError::UnknownKey {
            key: format!("{prefix}{key}"),
            message,
        },
        other => other,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Origin;

    fn load(text: &str, sets: &[&str]) -> Result<Config, ConfigError> {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        Config::from_yaml(text, &Origin::Embedded, &sets)
    }

    const TWO: &str = "friction_node:\n  ros__parameters:\n    contact: {load_n: 8000.0, boundary_friction: 0.2}\n    solver: {cells: 64}\n    contacts:\n      right:\n        joint: axis_y\n        gain: 0.05\n        contact: {load_n: 3000.0}\n        solver: {cells: 32}\n      left:\n        lubricant: {viscosity_pa_s: 0.1}\n";

    #[test]
    fn listed_contacts_are_driven_by_joints_even_one_and_a_plain_configuration_is_one_contact() {
        assert_eq!(Config::default().output_plan(), OutputPlan::OneContact);
        let one = load(
            "/**:\n  ros__parameters:\n    contacts:\n      elbow: {joint: elbow_joint, gain: 0.04}\n",
            &[],
        )
        .unwrap();
        let plan = one.output_plan();
        assert_eq!(plan, OutputPlan::Joints(vec!["elbow_joint".into()]));
        assert!(plan.by_joint());
        // The node's topics follow the plan: the contact's own estimate topic.
        let topics = crate::config::topics::TopicNames::from_config(&one);
        assert_eq!(topics.contact_friction.len(), 1);
        assert!(topics.contact_friction[0].ends_with("/elbow/friction"));
        assert_eq!(
            load(TWO, &[]).unwrap().output_plan().joints(),
            ["axis_y", "left"]
        );
    }

    #[test]
    fn a_contact_overrides_the_top_level_key_by_key_and_keeps_the_file_order() {
        let c = load(TWO, &[]).unwrap();
        let r = c.resolved_contacts();
        assert_eq!(r.len(), 2);
        assert_eq!(
            (r[0].name.as_str(), r[0].joint.as_str()),
            ("right", "axis_y")
        );
        assert_eq!(r[0].gain, 0.05);
        assert_eq!(r[0].config.contact.load_n, 3000.0);
        // Not overridden: the top-level value, not the built-in default.
        assert_eq!(r[0].config.contact.boundary_friction, 0.2);
        assert_eq!(r[0].config.solver.cells, 32);
        assert_eq!(r[1].joint, "left", "the joint defaults to the name");
        assert_eq!(r[1].gain, 1.0);
        assert_eq!(r[1].config.contact.load_n, 8000.0);
        assert_eq!(r[1].config.solver.cells, 64);
        assert_eq!(r[1].config.lubricant.viscosity_pa_s, 0.1);
        assert!(r.iter().all(|x| x.config.contacts.is_empty()));
    }

    #[test]
    fn a_config_without_contacts_is_one_contact_equal_to_the_top_level() {
        let c = Config::load(None, &[]).unwrap();
        let r = c.resolved_contacts();
        assert_eq!(r.len(), 1);
        assert_eq!(r[0].name, SINGLE_CONTACT_NAME);
        assert_eq!(r[0].config, c);
        let yaml = c.to_yaml();
        assert!(
            !yaml
                .lines()
                .any(|l| l.trim_start().starts_with("contacts:")),
            "{yaml}"
        );
    }

    #[test]
    fn the_resolved_contacts_survive_a_round_trip_through_yaml() {
        let c = load(TWO, &[]).unwrap();
        let again = load(&c.to_yaml(), &[]).unwrap();
        assert_eq!(again, c);
    }

    #[test]
    fn per_contact_keys_take_set_overrides() {
        let c = load(
            TWO,
            &[
                "contacts.left.contact.load_n=1234",
                "contacts.left.gain=0.1",
            ],
        )
        .unwrap();
        let r = c.resolved_contacts();
        assert_eq!(r[1].config.contact.load_n, 1234.0);
        assert_eq!(r[1].gain, 0.1);
    }

    fn err(text: &str, sets: &[&str]) -> String {
        load(text, sets).unwrap_err().to_string()
    }

    #[test]
    fn contact_mistakes_name_the_contact_and_the_key() {
        let e = err(TWO, &["contacts.left.contact.load_nn=1"]);
        assert!(e.contains("contacts.left.contact.load_nn"), "{e}");
        let e = err(TWO, &["contacts.left.texture_depth=1"]);
        assert!(e.contains("contacts.left.texture_depth"), "{e}");
        let e = err(TWO, &["contacts.left.contact.load_n=-5"]);
        assert!(
            e.contains("contacts.left.contact.load_n") && e.contains("-5"),
            "{e}"
        );
        let e = err(TWO, &["contacts.right.solver.cells=4"]);
        assert!(e.contains("contacts.right.solver.cells"), "{e}");
        let e = err(TWO, &["contacts.right.solver.dt_s=0.01"]);
        assert!(e.contains("contacts.right.solver.dt_s"), "{e}");
        for gain in ["0", ".nan", "-1", "1e9", ".inf"] {
            let e = err(TWO, &[&format!("contacts.left.gain={gain}")]);
            assert!(e.contains("contacts.left.gain"), "{gain}: {e}");
        }
        let e = err(TWO, &["contacts.left.joint=axis_y"]);
        assert!(
            e.contains("contacts.left.joint") && e.contains("axis_y") && e.contains("right"),
            "{e}"
        );
        let e = err(TWO, &["contacts.left.joint=''"]);
        assert!(e.contains("contacts.left.joint"), "{e}");
        let e = err(TWO, &["contacts.left.lubricant=7"]);
        assert!(e.contains("contacts.left.lubricant"), "{e}");
        let e = err(TWO, &["contacts.9lives.gain=1"]);
        assert!(e.contains("contacts.9lives") && e.contains("letter"), "{e}");
        let e = err(TWO, &["contacts=[1, 2]"]);
        assert!(e.contains("contacts") && e.contains("mapping"), "{e}");
    }

    #[test]
    fn a_duplicate_contact_name_is_a_config_error() {
        let text = TWO.replace("      left:", "      right:");
        let e = err(&text, &[]);
        assert!(e.contains("right") || e.contains("duplicate"), "{e}");
    }
}
