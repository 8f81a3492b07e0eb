//! `--ros-args`, as rcl parses them, so that a `launch_ros` `Node` action
//! starts the node unchanged.
//!
//! ```text
//! friction-node run --ros-args -r __node:=axis_x -r __ns:=/robot \
//!     -r ~/friction:=/ff/friction --params-file params.yaml \
//!     -p contact.load_n:=5762.0 --log-level warn
//! ```
//!
//! | flag | meaning |
//! |---|---|
//! | `-r`, `--remap` `[node:]FROM:=TO` | `__node`, `__ns`, or a topic remapping (`FROM` as written or fully qualified) |
//! | `-p`, `--param` `[node:]KEY:=VALUE` | a parameter (dotted key, YAML value) |
//! | `--params-file FILE` | a ROS 2 parameter file: the entries matching this node apply |
//! | `--log-level [NAME:=]LEVEL` | debug, info, warn, error, fatal |
//! | `--enable-/--disable-rosout-logs`, `--enable-/--disable-stdout-logs`, `--enable-/--disable-external-lib-logs` | logging outputs |
//!
//! Precedence as in rcl: the configuration file (or the built-in defaults)
//! < parameter files in order < `-p` in order. `--set` overrides come last.
//! A parameter file may hold several nodes: entries are matched against the
//! node's fully qualified name (`friction_node` means `/friction_node`;
//! `/**` matches any sequence of tokens, `*` one token; nested namespace
//! mappings are joined with `/`), and every matching entry applies, in file
//! order. Parameter names may be nested mappings or dotted keys.

use super::ConfigError;
use serde_norway::{Mapping, Value};
use std::path::{Path, PathBuf};

/// The parsed `--ros-args` of a command line.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RosArgs {
    /// `-r __node:=NAME`.
    pub node_name: Option<String>,
    /// `-r __ns:=/NS`.
    pub namespace: Option<String>,
    /// Topic remappings `FROM:=TO`, in order.
    pub remaps: Vec<(String, String)>,
    /// `-p KEY:=VALUE` (value as YAML text), in order.
    pub params: Vec<(String, String)>,
    /// `--params-file`, in order.
    pub params_files: Vec<PathBuf>,
    /// `--log-level`.
    pub log_level: Option<String>,
    /// `--disable-rosout-logs` given last.
    pub rosout_disabled: bool,
    /// `--disable-stdout-logs` given last.
    pub stdout_disabled: bool,
}

fn err(arg: &str, message: impl Into<String>) -> ConfigError {
    ConfigError::RosArgs {
        arg: arg.to_string(),
        message: message.into(),
    }
}

/// Split `argv` (without the program name) into the arguments for the
/// command line parser and the tokens of every `--ros-args` section (each
/// runs until a `--` or the end; several sections are concatenated, as rcl
/// does).
pub fn split(argv: &[String]) -> (Vec<String>, Option<Vec<String>>) {
    let mut rest = Vec::new();
    let mut ros: Option<Vec<String>> = None;
    let mut inside = false;
    for a in argv {
        if inside {
            if a == "--" {
                inside = false;
            } else if a == "--ros-args" {
                // A new section: nothing to do.
            } else {
                ros.get_or_insert_with(Vec::new).push(a.clone());
            }
        } else if a == "--ros-args" {
            inside = true;
            ros.get_or_insert_with(Vec::new);
        } else {
            rest.push(a.clone());
        }
    }
    (rest, ros)
}

/// `[node:]FROM:=TO` → (node, FROM, TO).
fn rule<'a>(flag: &str, s: &'a str) -> Result<(Option<&'a str>, &'a str, &'a str), ConfigError> {
    let Some((lhs, to)) = s.split_once(":=") else {
        return Err(err(
            &format!("{flag} {s}"),
            "expected FROM:=TO (or KEY:=VALUE for -p)",
        ));
    };
    // A node prefix is a plain token before a single `:` (`talker:__ns:=/x`).
    let (node, from) = match lhs.split_once(':') {
        Some((n, f)) if !n.is_empty() && !n.contains('/') && !f.starts_with(':') => (Some(n), f),
        _ => (None, lhs),
    };
    if from.is_empty() {
        return Err(err(&format!("{flag} {s}"), "the left side is empty"));
    }
    Ok((node, from, to))
}

/// The level of `--log-level LEVEL` or `--log-level LOGGER:=LEVEL`,
/// lower case.
fn log_level(flag: &str, v: &str) -> Result<String, ConfigError> {
    let level = v.rsplit_once(":=").map_or(v, |(_, l)| l);
    let l = level.to_ascii_lowercase();
    if !matches!(
        l.as_str(),
        "debug" | "info" | "warn" | "warning" | "error" | "fatal" | "unset"
    ) {
        return Err(err(
            &format!("{flag} {v}"),
            "the level is one of debug, info, warn, error, fatal",
        ));
    }
    Ok(l)
}

impl RosArgs {
    /// Parse the tokens of the `--ros-args` sections; `node_name` is the
    /// name a node-prefixed rule must carry to apply (it is resolved from
    /// `__node` when given before).
    pub fn parse(tokens: &[String], default_node_name: &str) -> Result<Self, ConfigError> {
        let mut a = RosArgs::default();
        let mut i = 0;
        let value = |i: usize, flag: &str| -> Result<&String, ConfigError> {
            tokens
                .get(i + 1)
                .ok_or_else(|| err(flag, "needs a value after it"))
        };
        while i < tokens.len() {
            let flag = tokens[i].as_str();
            match flag {
                "-r" | "--remap" => {
                    let v = value(i, flag)?;
                    a.remap(flag, v, default_node_name)?;
                    i += 2;
                }
                "-p" | "--param" => {
                    let v = value(i, flag)?;
                    let (node, key, val) = rule(flag, v)?;
                    let me = a.node_name.as_deref().unwrap_or(default_node_name);
                    if node.is_none_or(|n| n == me) {
                        a.params.push((key.to_string(), val.to_string()));
                    }
                    i += 2;
                }
                "--params-file" => {
                    a.params_files.push(PathBuf::from(value(i, flag)?));
                    i += 2;
                }
                "--log-level" => {
                    a.log_level = Some(log_level(flag, value(i, flag)?)?);
                    i += 2;
                }
                "--enable-rosout-logs" => {
                    a.rosout_disabled = false;
                    i += 1;
                }
                "--disable-rosout-logs" => {
                    a.rosout_disabled = true;
                    i += 1;
                }
                "--enable-stdout-logs" => {
                    a.stdout_disabled = false;
                    i += 1;
                }
                "--disable-stdout-logs" => {
                    a.stdout_disabled = true;
                    i += 1;
                }
                "--enable-external-lib-logs" | "--disable-external-lib-logs" => i += 1,
                "--log-config-file" | "-e" | "--enclave" => {
                    return Err(err(
                        flag,
                        "is not supported by this node (logging goes to the terminal and /rosout; no DDS security)",
                    ));
                }
                other => {
                    return Err(err(
                        other,
                        "is not a --ros-args flag (-r/--remap, -p/--param, --params-file, --log-level, --enable-/--disable-rosout-logs, --enable-/--disable-stdout-logs)",
                    ));
                }
            }
        }
        Ok(a)
    }

    /// Apply one `-r FROM:=TO` rule (when it is for this node): a node
    /// name, a namespace or a topic remapping.
    fn remap(&mut self, flag: &str, v: &str, default_node_name: &str) -> Result<(), ConfigError> {
        let (node, from, to) = rule(flag, v)?;
        let me = self.node_name.as_deref().unwrap_or(default_node_name);
        if node.is_some_and(|n| n != me) {
            return Ok(());
        }
        let here = || format!("{flag} {v}");
        match from {
            "__node" | "__name" => {
                super::check_node_name(to).map_err(|m| err(&here(), m))?;
                self.node_name = Some(to.to_string());
            }
            "__ns" => {
                super::check_namespace(to).map_err(|m| err(&here(), m))?;
                self.namespace = Some(to.to_string());
            }
            f if f.starts_with("__") => {
                return Err(err(
                    &here(),
                    format!("`{f}` is not a remapping this node knows (__node, __ns)"),
                ));
            }
            _ => {
                for (what, name) in [("from", from), ("to", to)] {
                    super::check_topic(name).map_err(|m| err(&here(), format!("{what}: {m}")))?;
                }
                self.remaps.push((from.to_string(), to.to_string()));
            }
        }
        Ok(())
    }

    /// The fully qualified node name these arguments give, falling back to
    /// the configuration's name and namespace.
    pub fn fully_qualified(&self, name: &str, namespace: &str) -> String {
        let name = self.node_name.as_deref().unwrap_or(name);
        let ns = self.namespace.as_deref().unwrap_or(namespace);
        if ns == "/" {
            format!("/{name}")
        } else {
            format!("{ns}/{name}")
        }
    }
}

/// Whether a parameter-file node key matches the fully qualified name
/// `fqn` (`/**` any tokens, `*` one token; a key without a leading `/` is
/// in the root namespace).
pub fn node_key_matches(key: &str, fqn: &str) -> bool {
    let key = if key.starts_with('/') {
        key.to_string()
    } else {
        format!("/{key}")
    };
    let k: Vec<&str> = key[1..].split('/').collect();
    let f: Vec<&str> = fqn[1..].split('/').collect();
    fn m(k: &[&str], f: &[&str]) -> bool {
        match (k.first(), f.first()) {
            (None, None) => true,
            (Some(&"**"), _) => m(&k[1..], f) || (!f.is_empty() && m(k, &f[1..])),
            (Some(&"*"), Some(_)) => m(&k[1..], &f[1..]),
            (Some(a), Some(b)) if a == b => m(&k[1..], &f[1..]),
            _ => false,
        }
    }
    m(&k, &f)
}

/// A mapping whose dotted keys are expanded into nested mappings.
fn expand_dotted(v: Value) -> Value {
    let Value::Mapping(map) = v else {
        return v;
    };
    let mut out = Value::Mapping(Mapping::new());
    for (k, v) in map {
        let v = expand_dotted(v);
        let key = k.as_str().map(str::to_string);
        match key {
            Some(key) if key.contains('.') => {
                let parts: Vec<&str> = key.split('.').collect();
                insert_path(&mut out, &parts, v);
            }
            _ => merge(&mut out, Value::Mapping(Mapping::from_iter([(k, v)]))),
        }
    }
    out
}

fn insert_path(root: &mut Value, parts: &[&str], v: Value) {
    let mut nested = v;
    for p in parts.iter().rev() {
        nested = Value::Mapping(Mapping::from_iter([(Value::String((*p).into()), nested)]));
    }
    merge(root, nested);
}

/// Deep-merge `over` into `base` (mappings merge, anything else replaces).
pub fn merge(base: &mut Value, over: Value) {
    match (base, over) {
        (Value::Mapping(b), Value::Mapping(o)) => {
            for (k, v) in o {
                match b.get_mut(&k) {
                    Some(slot) => merge(slot, v),
                    None => {
                        b.insert(k, v);
                    }
                }
            }
        }
        (slot, v) => *slot = v,
    }
}

/// The `ros__parameters` of every entry of a parameter file that matches
/// `fqn`, in file order (nested namespace mappings are joined).
pub fn matching_parameters(path: &Path, fqn: &str) -> Result<Vec<Value>, ConfigError> {
    let text = std::fs::read_to_string(path).map_err(|cause| ConfigError::Io {
        path: path.to_path_buf(),
        cause,
    })?;
    let doc: Value = serde_norway::from_str(&text).map_err(|e| ConfigError::Syntax {
        origin: path.display().to_string(),
        message: e.to_string(),
    })?;
    let layout = |message: String| ConfigError::Layout {
        origin: path.display().to_string(),
        message,
    };
    let Value::Mapping(top) = doc else {
        return Err(layout(
            "a parameter file is a mapping of node names to `ros__parameters:`".into(),
        ));
    };
    let mut out = Vec::new();
    fn walk(
        prefix: &str,
        map: Mapping,
        fqn: &str,
        out: &mut Vec<Value>,
        layout: &dyn Fn(String) -> ConfigError,
    ) -> Result<(), ConfigError> {
        for (k, v) in map {
            let Some(k) = k.as_str() else {
                return Err(layout("a node name must be a string".into()));
            };
            let name = if prefix.is_empty() {
                k.to_string()
            } else {
                format!("{prefix}/{}", k.trim_start_matches('/'))
            };
            let Value::Mapping(body) = v else {
                return Err(layout(format!("`{name}` must be a mapping")));
            };
            if body.contains_key("ros__parameters") {
                if node_key_matches(&name, fqn) {
                    let params = body.get("ros__parameters").cloned().unwrap_or(Value::Null);
                    match params {
                        Value::Null => {}
                        p @ Value::Mapping(_) => out.push(expand_dotted(p)),
                        _ => {
                            return Err(layout(format!(
                                "`{name}.ros__parameters` must be a mapping"
                            )))
                        }
                    }
                }
            } else {
                walk(&name, body, fqn, out, layout)?;
            }
        }
        Ok(())
    }
    walk("", top, fqn, &mut out, &layout)?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn toks(s: &str) -> Vec<String> {
        s.split_whitespace().map(String::from).collect()
    }

    #[test]
    fn ros_args_sections_are_split_from_the_command_line() {
        let argv = toks("run --quiet --ros-args -r __node:=x -- --duration 3 --ros-args -p a.b:=1");
        let (rest, ros) = split(&argv);
        assert_eq!(rest, toks("run --quiet --duration 3"));
        assert_eq!(ros.unwrap(), toks("-r __node:=x -p a.b:=1"));
        assert_eq!(split(&toks("run")).1, None);
    }

    #[test]
    fn every_rcl_form_is_parsed() {
        let a = RosArgs::parse(
            &toks(
                "-r __node:=axis_x --remap __ns:=/robot -r ~/friction:=/ff/friction \
                 -r other:__ns:=/nope -r axis_x:cmd:=/c -p contact.load_n:=5762.0 \
                 --param other:contact.load_n:=1.0 --params-file a.yaml --params-file b.yaml \
                 --log-level friction_node:=WARN --disable-rosout-logs --enable-stdout-logs",
            ),
            "friction_node",
        )
        .unwrap();
        assert_eq!(a.node_name.as_deref(), Some("axis_x"));
        assert_eq!(a.namespace.as_deref(), Some("/robot"));
        assert_eq!(
            a.remaps,
            vec![
                ("~/friction".into(), "/ff/friction".into()),
                ("cmd".into(), "/c".into())
            ]
        );
        assert_eq!(a.params, vec![("contact.load_n".into(), "5762.0".into())]);
        assert_eq!(
            a.params_files,
            vec![PathBuf::from("a.yaml"), PathBuf::from("b.yaml")]
        );
        assert_eq!(a.log_level.as_deref(), Some("warn"));
        assert!(a.rosout_disabled && !a.stdout_disabled);
        assert_eq!(a.fully_qualified("friction_node", "/"), "/robot/axis_x");
    }

    #[test]
    fn malformed_ros_args_name_the_flag() {
        for (args, needle) in [
            ("--frobnicate", "--frobnicate"),
            ("-r", "needs a value"),
            ("-r a=b", "FROM:=TO"),
            ("-r __node:=a/b", "one token"),
            ("-r __ns:=relative", "absolute"),
            ("-r a:=b//c", "`//`"),
            ("-r __foo:=x", "__foo"),
            ("--log-level loud", "debug, info"),
            ("-e /enclave", "not supported"),
            ("-p :=1", "empty"),
        ] {
            let e = RosArgs::parse(&toks(args), "friction_node")
                .unwrap_err()
                .to_string();
            assert!(e.contains(needle), "{args}: {e}");
        }
    }

    #[test]
    fn parameter_file_node_keys_match_as_rcl_matches_them() {
        for (key, fqn, want) in [
            ("friction_node", "/friction_node", true),
            ("friction_node", "/robot/friction_node", false),
            ("/robot/friction_node", "/robot/friction_node", true),
            ("/**", "/robot/arm/friction_node", true),
            ("/**/friction_node", "/robot/friction_node", true),
            ("/**/friction_node", "/friction_node", true),
            ("/**/friction_node", "/robot/other", false),
            ("/*/friction_node", "/robot/friction_node", true),
            ("/*/friction_node", "/a/b/friction_node", false),
            ("/robot/*", "/robot/friction_node", true),
            ("talker", "/friction_node", false),
        ] {
            assert_eq!(node_key_matches(key, fqn), want, "{key} vs {fqn}");
        }
    }

    #[test]
    fn a_parameter_file_with_several_nodes_gives_the_matching_entries_in_order() {
        let d = std::env::temp_dir().join(format!("fn-rosargs-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        let p = d.join("params.yaml");
        std::fs::write(
            &p,
            "/**:\n  ros__parameters:\n    contact.load_n: 1.0\n\
             talker:\n  ros__parameters:\n    contact:\n      load_n: 2.0\n\
             robot:\n  friction_node:\n    ros__parameters:\n      contact:\n        load_n: 3.0\n\
             /**/friction_node:\n  ros__parameters:\n    lubricant.viscosity_pa_s: 0.1\n",
        )
        .unwrap();
        let got = matching_parameters(&p, "/robot/friction_node").unwrap();
        assert_eq!(got.len(), 3, "{got:?}");
        let load = |v: &Value| v["contact"]["load_n"].as_f64();
        assert_eq!(load(&got[0]), Some(1.0), "dotted keys are expanded");
        assert_eq!(load(&got[1]), Some(3.0), "nested namespaces are joined");
        assert_eq!(got[2]["lubricant"]["viscosity_pa_s"].as_f64(), Some(0.1));
        let _ = std::fs::remove_dir_all(&d);
    }
}
