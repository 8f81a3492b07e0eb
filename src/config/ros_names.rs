//! The ROS 2 naming rules (topics, node names, namespaces), each refusal
//! saying which rule a name breaks.

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
