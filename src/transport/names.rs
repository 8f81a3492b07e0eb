//! ROS 2 topic names of the node, resolved from the configuration (used by
//! the ROS 2 transport, the recorder and replay, whatever is built in).

use crate::config::Config;

/// Expand a topic name: `~/x` → `/<namespace>/<node>/x`; other names as given
/// (relative names are resolved by DDS against the node's namespace).
pub fn resolve_topic(topic: &str, namespace: &str, node: &str) -> String {
    match topic.strip_prefix("~/") {
        Some(rest) => {
            let ns = namespace.trim_end_matches('/');
            format!("{ns}/{node}/{rest}")
        }
        None => topic.to_string(),
    }
}

/// The node's topics, resolved.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TopicNames {
    pub cmd_velocity: String,
    pub normal_load: String,
    pub temperature: String,
    pub friction: String,
    pub friction_force: String,
    pub film_profile: String,
    pub loop_statistics: String,
    /// `~/snapshot` (std_msgs/Empty): asks for a snapshot of the last minutes.
    pub snapshot: String,
}

impl TopicNames {
    pub fn from_config(cfg: &Config) -> Self {
        let r = &cfg.ros;
        let t = |topic: &str| resolve_topic(topic, &r.namespace, &r.node_name);
        Self {
            cmd_velocity: t(&r.topics.cmd_velocity),
            normal_load: t(&r.topics.normal_load),
            temperature: t(&r.topics.temperature),
            friction: t(&r.topics.friction),
            friction_force: t(&r.topics.friction_force),
            film_profile: t(&r.topics.film_profile),
            loop_statistics: t(&r.topics.loop_statistics),
            snapshot: t("~/snapshot"),
        }
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
        assert_eq!(resolve_topic("rel/x", "/robot", "fn"), "rel/x");
        let n = TopicNames::from_config(&Config::default());
        assert_eq!(n.friction, "/friction_node/friction");
    }
}
