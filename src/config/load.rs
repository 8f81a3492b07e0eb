//! Reading a configuration: parameter-file text (the ROS 2 shapes), then
//! `dotted.key=value` overrides applied to the YAML tree before it is read,
//! so they are checked exactly like file keys.

use super::{Config, ConfigError, Origin, DEFAULT_NODE_NAME, DEFAULT_YAML};
use serde_norway::Value;
use std::path::Path;

impl Config {
    /// Read a parameter file (or the embedded default when `path` is None),
    /// apply `dotted.key=value` overrides, deserialize and validate.
    pub fn load(path: Option<&Path>, overrides: &[String]) -> Result<Config, ConfigError> {
        let (text, origin) = match path {
            Some(p) => (
                std::fs::read_to_string(p).map_err(|cause| ConfigError::Io {
                    path: p.to_path_buf(),
                    cause,
                })?,
                Origin::File(p.to_path_buf()),
            ),
            None => (DEFAULT_YAML.to_string(), Origin::Embedded),
        };
        Self::from_yaml(&text, &origin, overrides)
    }

    /// As [`Config::load`], with `--ros-args` applied as rcl applies them:
    /// the file (or built-in defaults) < `--params-file` entries matching
    /// the node, in order < `-p`, in order; then `--set` overrides, the
    /// node's name and namespace (`-r __node:=`, `-r __ns:=`) and the topic
    /// remappings (appended to `ros.remappings`).
    pub fn load_with_ros_args(
        path: Option<&Path>,
        overrides: &[String],
        ros: &super::RosArgs,
    ) -> Result<Config, ConfigError> {
        let (text, origin) = match path {
            Some(p) => (
                std::fs::read_to_string(p).map_err(|cause| ConfigError::Io {
                    path: p.to_path_buf(),
                    cause,
                })?,
                Origin::File(p.to_path_buf()),
            ),
            None => (DEFAULT_YAML.to_string(), Origin::Embedded),
        };
        let doc: Value = serde_norway::from_str(&text).map_err(|e| ConfigError::Syntax {
            origin: origin.to_string(),
            message: e.to_string(),
        })?;
        let mut params = ros_parameters(doc, &origin)?;
        let text_of = |v: &Value, key: &str, default: &str| -> String {
            v.get("ros")
                .and_then(|r| r.get(key))
                .and_then(Value::as_str)
                .unwrap_or(default)
                .to_string()
        };
        let fqn = ros.fully_qualified(
            &text_of(&params, "node_name", DEFAULT_NODE_NAME),
            &text_of(&params, "namespace", "/"),
        );
        for file in &ros.params_files {
            for entry in super::ros_args::matching_parameters(file, &fqn)? {
                super::ros_args::merge(&mut params, entry);
            }
        }
        for (key, value) in &ros.params {
            apply_override(&mut params, &format!("{key}={value}")).map_err(|e| match e {
                ConfigError::BadOverride { message, .. } => ConfigError::RosArgs {
                    arg: format!("-p {key}:={value}"),
                    message,
                },
                other => other,
            })?;
        }
        for o in overrides {
            apply_override(&mut params, o)?;
        }
        fn set(params: &mut Value, key: &str, v: Value) {
            if let Value::Mapping(top) = params {
                let ros = top
                    .entry(Value::String("ros".into()))
                    .or_insert_with(|| Value::Mapping(Default::default()));
                if let Value::Mapping(r) = ros {
                    r.insert(Value::String(key.into()), v);
                }
            }
        }
        if let Some(n) = &ros.node_name {
            set(&mut params, "node_name", Value::String(n.clone()));
        }
        if let Some(n) = &ros.namespace {
            set(&mut params, "namespace", Value::String(n.clone()));
        }
        if !ros.remaps.is_empty() {
            let mut rules: Vec<Value> = params
                .get("ros")
                .and_then(|r| r.get("remappings"))
                .and_then(Value::as_sequence)
                .cloned()
                .unwrap_or_default();
            rules.extend(
                ros.remaps
                    .iter()
                    .map(|(f, t)| Value::String(format!("{f}:={t}"))),
            );
            set(&mut params, "remappings", Value::Sequence(rules));
        }
        Self::from_params(params)
    }

    /// Parse parameter-file text (see [`Config::load`]).
    pub fn from_yaml(
        text: &str,
        origin: &Origin,
        overrides: &[String],
    ) -> Result<Config, ConfigError> {
        let mut params = parse_params(text, origin)?;
        for o in overrides {
            apply_override(&mut params, o)?;
        }
        Self::from_params(params)
    }

    /// Parse a configuration recorded in a bag (`config_yaml`). A key the
    /// recording predates takes the value that reproduces it (see
    /// `RECORDED_BEFORE`), so that old bags replay to the numbers they
    /// hold; then `overrides` apply.
    pub fn from_recorded_yaml(
        text: &str,
        origin: &Origin,
        overrides: &[String],
    ) -> Result<Config, ConfigError> {
        let mut params = parse_params(text, origin)?;
        for (key, value) in RECORDED_BEFORE {
            if lookup(&params, key).is_none() {
                apply_override(&mut params, &format!("{key}={value}"))?;
            }
        }
        for o in overrides {
            apply_override(&mut params, o)?;
        }
        Self::from_params(params)
    }

    /// Deserialize and validate a `ros__parameters` tree.
    fn from_params(mut params: Value) -> Result<Config, ConfigError> {
        default_flux_for_method(&mut params);
        super::contacts::inherit_top_level(&mut params);
        let cfg: Config = serde_path_to_error::deserialize(params.clone()).map_err(|e| {
            let key = e.path().to_string();
            let message = e.inner().to_string();
            let message = enum_choice_error(&params, &key, &message).unwrap_or(message);
            if message.starts_with("unknown field") {
                let message = nearest_first(&message);
                ConfigError::UnknownKey { key, message }
            } else {
                ConfigError::InvalidValue { key, message }
            }
        })?;
        cfg.validate()?;
        Ok(cfg)
    }
}

/// serde's "unknown field `x`, expected one of `a`, `b`…" led by the
/// expected name `x` most likely meant ([`super::nearest_key`]).
fn nearest_first(message: &str) -> String {
    let Some((field, tail)) = message
        .strip_prefix("unknown field `")
        .and_then(|r| r.split_once('`'))
    else {
        return message.to_string();
    };
    match super::nearest_key::nearest(field, tail.split('`').skip(1).step_by(2)) {
        Some(n) => format!("did you mean `{n}`? {message}"),
        None => message.to_string(),
    }
}

/// `nan`, `inf`, `-inf`, `infinity` (any case; what a shell user or
/// Python's `str(float("nan"))` writes) as the numbers they name, so that a
/// numeric key reports them as not finite, as YAML's `.nan` does, rather
/// than as a string of the wrong type.
fn non_finite_number(value: Value) -> Value {
    let Value::String(text) = &value else {
        return value;
    };
    let number = match text.trim().to_ascii_lowercase().as_str() {
        "nan" | "+nan" | "-nan" => f64::NAN,
        "inf" | "+inf" | "infinity" | "+infinity" => f64::INFINITY,
        "-inf" | "-infinity" => f64::NEG_INFINITY,
        _ => return value,
    };
    Value::Number(number.into())
}

/// A value of the wrong kind where a named choice (an enum) is expected
/// says "expected a Value::Tagged enum" and lists nothing: read as text, the
/// same value gets serde's message listing the allowed choices.
fn enum_choice_error(params: &Value, key: &str, message: &str) -> Option<String> {
    if !message.contains("Tagged enum") {
        return None;
    }
    let mut tree = params.clone();
    let mut node = &mut tree;
    for part in key.split('.') {
        node = node.get_mut(part)?;
    }
    let text = match node {
        Value::Null => String::new(),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => n.to_string(),
        _ => return None,
    };
    *node = Value::String(text);
    match serde_path_to_error::deserialize::<_, Config>(tree) {
        Err(e) if e.path().to_string() == key => Some(e.inner().to_string()),
        _ => None,
    }
}

/// The `ros__parameters` tree of parameter-file text.
fn parse_params(text: &str, origin: &Origin) -> Result<Value, ConfigError> {
    let doc: Value = serde_norway::from_str(text).map_err(|e| ConfigError::Syntax {
        origin: origin.to_string(),
        message: e.to_string(),
    })?;
    ros_parameters(doc, origin)
}

/// Keys added after the first recordings, with the value that reproduces a
/// recording made before each existed (a recorded configuration always
/// lists every key of its time: it is the resolved configuration).
///
/// | key | before it existed |
/// |---|---|
/// | `solver.flux` | `upwind`, the only flux then (the default since is `muscl_van_leer`) |
pub(super) const RECORDED_BEFORE: &[(&str, &str)] = &[("solver.flux", "upwind")];

/// The value at a dotted key of a `ros__parameters` tree.
fn lookup<'a>(params: &'a Value, key: &str) -> Option<&'a Value> {
    key.split('.').try_fold(params, |v, k| v.get(k))
}

/// `solver.flux` left unset takes the best flux the method supports:
/// `muscl_van_leer` with `newton` (the serde default), `upwind` with
/// `reference` (the paper's Picard solver has no other).
fn default_flux_for_method(params: &mut Value) {
    let reference = lookup(params, "solver.method").and_then(Value::as_str) == Some("reference");
    if reference && lookup(params, "solver.flux").is_none() {
        if let Some(Value::Mapping(solver)) = params.get_mut("solver") {
            solver.insert(Value::String("flux".into()), Value::String("upwind".into()));
        }
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
    let value = non_finite_number(value);
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
