//! ROS 2 topic names of the node, resolved from the configuration (used by
//! the ROS 2 transport, the recorder and replay, whatever is built in).

use super::Config;

/// Expand a topic name: `~/x` → `/<namespace>/<node>/x`, a relative `x` →
/// `/<namespace>/x`, an absolute one as given.
pub fn resolve_topic(topic: &str, namespace: &str, node: &str) -> String {
    let ns = namespace.trim_end_matches('/');
    match topic.strip_prefix("~/") {
        Some(rest) => format!("{ns}/{node}/{rest}"),
        None if topic.starts_with('/') => topic.to_string(),
        None => format!("{ns}/{topic}"),
    }
}

/// A resolved name after the remapping rules `FROM:=TO` (each side
/// resolved as a topic of this node): the first rule whose `FROM` is `name`
/// gives its `TO`, as rcl applies them.
pub fn remap(name: &str, rules: &[String], namespace: &str, node: &str) -> String {
    for r in rules {
        if let Some((from, to)) = r.split_once(":=") {
            if resolve_topic(from, namespace, node) == name {
                return resolve_topic(to, namespace, node);
            }
        }
    }
    name.to_string()
}

/// A name of this node, resolved and remapped.
pub fn node_topic(cfg: &Config, topic: &str) -> String {
    let r = &cfg.ros;
    remap(
        &resolve_topic(topic, &r.namespace, &r.node_name),
        &r.remappings,
        &r.namespace,
        &r.node_name,
    )
}

/// The node's topics, resolved.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicNames {
    /// The commanded velocity.
    pub cmd_velocity: String,
    /// The normal load command.
    pub normal_load: String,
    /// The temperature command.
    pub temperature: String,
    /// The estimates (FrictionEstimate).
    pub friction: String,
    /// The friction force alone (Float64).
    pub friction_force: String,
    /// The film profile.
    pub film_profile: String,
    /// The loop statistics.
    pub loop_statistics: String,
    /// `~/snapshot` (std_msgs/Empty): asks for a snapshot of the last minutes.
    pub snapshot: String,
    /// `/parameter_events` (rcl_interfaces/ParameterEvent).
    pub parameter_events: String,
    /// Several contacts: the joint velocities (JointState).
    pub joint_commands: String,
    /// Several contacts: the efforts in joint order (Float64MultiArray).
    pub joint_efforts: String,
    /// Several contacts: the efforts by joint name (JointState).
    pub joint_friction: String,
    /// One FrictionEstimate topic per contact (several contacts), in the
    /// configured order: `<ros.topics.contact_friction>/<name>`.
    pub contact_friction: Vec<String>,
}

impl TopicNames {
    /// Every topic of `cfg`, resolved (namespace, `~/`, remappings).
    pub fn from_config(cfg: &Config) -> Self {
        let r = &cfg.ros;
        let t = |topic: &str| node_topic(cfg, topic);
        Self {
            cmd_velocity: t(&r.topics.cmd_velocity),
            normal_load: t(&r.topics.normal_load),
            temperature: t(&r.topics.temperature),
            friction: t(&r.topics.friction),
            friction_force: t(&r.topics.friction_force),
            film_profile: t(&r.topics.film_profile),
            loop_statistics: t(&r.topics.loop_statistics),
            snapshot: t("~/snapshot"),
            parameter_events: t("/parameter_events"),
            joint_commands: t(&r.topics.joint_commands),
            joint_efforts: t(&r.topics.joint_efforts),
            joint_friction: t(&r.topics.joint_friction),
            contact_friction: if cfg.output_plan().by_joint() {
                let prefix = r.topics.contact_friction.trim_end_matches('/');
                cfg.contacts
                    .0
                    .iter()
                    .map(|c| t(&format!("{prefix}/{}/friction", c.name)))
                    .collect()
            } else {
                Vec::new()
            },
        }
    }

    /// Every topic the node opens, as (what, resolved name), in the order
    /// `run --check` prints them: the one contact's topics (opened in every
    /// plan), and with joints also the joint commands, the efforts and one
    /// estimate topic per contact (`contacts/NAME/friction`).
    pub fn opened(&self, cfg: &Config) -> Vec<(String, &str)> {
        let mut out: Vec<(String, &str)> = [
            ("cmd_velocity", &self.cmd_velocity),
            ("normal_load", &self.normal_load),
            ("temperature", &self.temperature),
            ("friction", &self.friction),
            ("friction_force", &self.friction_force),
            ("film_profile", &self.film_profile),
            ("loop_statistics", &self.loop_statistics),
            ("snapshot", &self.snapshot),
            ("parameter_events", &self.parameter_events),
        ]
        .into_iter()
        .map(|(what, name)| (what.to_string(), name.as_str()))
        .collect();
        if cfg.output_plan().by_joint() {
            out.push(("joint_commands".into(), &self.joint_commands));
            out.push(("joint_efforts".into(), &self.joint_efforts));
            out.push(("joint_friction".into(), &self.joint_friction));
            for (c, name) in cfg.contacts.0.iter().zip(&self.contact_friction) {
                out.push((format!("contacts/{}/friction", c.name), name));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn private_names_expand_into_the_node_namespace() {
        assert_eq!(
            resolve_topic("~/cmd_velocity", "/", "friction_node"),
            "/friction_node/cmd_velocity"
        );
        assert_eq!(
            resolve_topic("~/cmd_velocity", "/robot", "fn"),
            "/robot/fn/cmd_velocity"
        );
        assert_eq!(resolve_topic("/abs/x", "/robot", "fn"), "/abs/x");
        assert_eq!(resolve_topic("rel/x", "/robot", "fn"), "/robot/rel/x");
        assert_eq!(resolve_topic("rel/x", "/", "fn"), "/rel/x");
        let n = TopicNames::from_config(&Config::default());
        assert_eq!(n.friction, "/friction_node/friction");
    }

    #[test]
    fn remappings_apply_to_every_topic_private_ones_included() {
        let mut c = Config::default();
        c.ros.namespace = "/robot".into();
        c.ros.remappings = vec![
            "~/friction:=/ff/friction".into(),
            "/robot/friction_node/cmd_velocity:=cmd".into(),
            "~/snapshot:=/snapshots/now".into(),
            "~/friction:=/never/this".into(),
        ];
        let n = TopicNames::from_config(&c);
        assert_eq!(n.friction, "/ff/friction", "first rule wins");
        assert_eq!(
            n.cmd_velocity, "/robot/cmd",
            "relative TO in the node's namespace"
        );
        assert_eq!(n.snapshot, "/snapshots/now");
        assert_eq!(
            n.normal_load, "/robot/friction_node/normal_load",
            "untouched"
        );
    }
}
