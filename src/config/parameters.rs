//! The live-parameter catalogue: every configuration key is a declared
//! ROS 2 parameter (dotted name, type, description, range, read-only or
//! not), and a set is validated here ([`apply_set`]). Preparing a valid set
//! for the loop and handing it over is `link.rs`; the loop applies it
//! between two steps (`node/parameters.rs`); the ROS 2 services and
//! `/parameter_events` are `transport/ros2/params.rs`.
//!
//! Keys that can change while running ([`is_runtime`]): the load, the
//! contact's mass and film floor, every friction term's key that its term
//! declares live (`physics::terms`), every lubricant, roughness and
//! drivetrain key, and the node's command limits,
//! timeout rule and publication rates. Everything else (geometry, grid,
//! solver, transports, names, recording) is read-only: changing it needs a
//! restart. With several contacts the same keys of each contact,
//! `contacts.NAME.contact.load_n`, `contacts.NAME.lubricant.…`, … change
//! that contact alone (its joint, gain and grid are read-only), and the
//! top-level `contact.`, `lubricant.` and `roughness.` keys, which only gave
//! the contacts their defaults when the configuration was read, are
//! read-only.

use super::IntervalText;
use super::{key_ranges, Config, ConfigError, KeyRange};
use crate::msgs::ros_interfaces::{parameter_type as ty, ParameterValue};
use crate::physics::terms::{configured_catalogue as catalogue, Interval};
use serde_norway::Value;

/// Whether `key` may change while the node runs.
pub fn is_runtime(key: &str) -> bool {
    // The friction terms' keys say themselves (physics::terms::catalogue).
    const EXACT: [&str; 12] = [
        "contact.load_n",
        "contact.mass_kg",
        "contact.min_film_m",
        "node.command_timeout_s",
        "node.timeout_behaviour",
        "node.outside_envelope",
        "node.timeout_deceleration_m_s2",
        "node.max_abs_velocity_m_s",
        "node.min_load_n",
        "node.max_load_n",
        "node.profile_rate_hz",
        "node.statistics_rate_hz",
    ];
    EXACT.contains(&key)
        || crate::physics::terms::term_key(key).is_some_and(|k| k.live)
        || key == "node.max_catch_up_s"
        || ["lubricant.", "roughness.", "drivetrain."]
            .iter()
            .any(|p| key.starts_with(p))
}

/// Whether `key` may change while a node with `config` runs: [`is_runtime`]
/// of the key a per-contact key mirrors; with several contacts the
/// top-level keys the contacts took their defaults from are read-only.
pub fn is_runtime_in(config: &Config, key: &str) -> bool {
    let per_contact = key.starts_with("contacts.");
    let defaults_only = !config.contacts.0.is_empty()
        && !per_contact
        && ["contact.", "lubricant.", "roughness."]
            .iter()
            .any(|p| key.starts_with(p));
    !defaults_only && is_runtime(top_level_key(key))
}

/// One declared parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Declared {
    /// The dotted key.
    pub name: String,
    /// `rcl_interfaces/msg/ParameterType`.
    pub r#type: u8,
    /// Its current value.
    pub value: ParameterValue,
    /// The key's documentation in `launch-config/default.yaml`.
    pub description: String,
    /// Its physical range, when it has one.
    pub range: Option<KeyRange>,
    /// Whether it cannot change while the node runs.
    pub read_only: bool,
}

/// The comment of every key in the shipped `default.yaml` (dotted name →
/// text after `#`, its range column included).
fn documented() -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut path: Vec<(usize, String)> = Vec::new();
    for line in crate::config::DEFAULT_YAML.lines() {
        let body = line.split('#').next().unwrap_or("");
        let Some((key, _)) = body.split_once(':') else {
            continue;
        };
        let indent = key.len() - key.trim_start().len();
        let key = key.trim();
        if key.is_empty() || key.starts_with('-') {
            continue;
        }
        while path.last().is_some_and(|(i, _)| *i >= indent) {
            path.pop();
        }
        path.push((indent, key.to_string()));
        // Under `friction_node: ros__parameters:`.
        if path.len() > 2 {
            let name: Vec<&str> = path[2..].iter().map(|(_, k)| k.as_str()).collect();
            let comment = line.split_once('#').map_or("", |(_, c)| c.trim());
            out.push((name.join("."), comment.to_string()));
        }
    }
    out
}

/// Every leaf of the configuration as (dotted name, YAML value).
pub fn flatten(config: &Config) -> Vec<(String, Value)> {
    fn walk(prefix: &str, v: &Value, out: &mut Vec<(String, Value)>) {
        match v {
            Value::Mapping(m) => {
                for (k, v) in m {
                    let k = k.as_str().unwrap_or_default();
                    let name = if prefix.is_empty() {
                        k.to_string()
                    } else {
                        format!("{prefix}.{k}")
                    };
                    walk(&name, v, out);
                }
            }
            other => out.push((prefix.to_string(), other.clone())),
        }
    }
    let mut out = Vec::new();
    walk(
        "",
        &serde_norway::to_value(config).expect("config serializes"),
        &mut out,
    );
    out
}

/// The parameter type of a key (empty arrays take the key's element type).
fn type_of(name: &str, v: &Value) -> u8 {
    match v {
        Value::Sequence(s) if s.is_empty() => {
            if is_texture(name) {
                ty::DOUBLE_ARRAY
            } else {
                ty::STRING_ARRAY
            }
        }
        Value::Sequence(_) => {
            let p = ParameterValue::from_yaml(v).r#type;
            // Pocket arrays are doubles even when written as integers.
            if is_texture(name) {
                ty::DOUBLE_ARRAY
            } else {
                p
            }
        }
        other => ParameterValue::from_yaml(other).r#type,
    }
}

fn is_texture(name: &str) -> bool {
    top_level_key(name).starts_with("texture.")
}

/// The top-level key a per-contact key `contacts.NAME.section.key` mirrors
/// (for its documentation and range); other keys are their own.
fn top_level_key(name: &str) -> &str {
    name.strip_prefix("contacts.")
        .and_then(|rest| rest.split_once('.'))
        .map_or(name, |(_, key)| key)
}

/// Every parameter of `config`, declared.
pub fn declare(config: &Config) -> Vec<Declared> {
    let docs = documented();
    let ranges = key_ranges();
    flatten(config)
        .into_iter()
        .map(|(name, v)| {
            let r#type = type_of(&name, &v);
            let mut value = ParameterValue::from_yaml(&v);
            if r#type == ty::DOUBLE && value.r#type == ty::INTEGER {
                value.double_value = value.integer_value as f64;
            }
            value.r#type = r#type;
            let doc_key = top_level_key(&name);
            let description = docs
                .iter()
                .find(|(k, _)| k == doc_key)
                .map_or(String::new(), |(_, c)| c.clone());
            let range = ranges.iter().find(|r| r.key == doc_key).map(|r| KeyRange {
                key: name.clone(),
                ..r.clone()
            });
            Declared {
                range,
                read_only: !is_runtime_in(config, &name),
                description,
                value,
                r#type,
                name,
            }
        })
        .collect()
}

/// Why a set was refused (the text goes to `SetParametersResult.reason`).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SetRefusal {
    /// The name is not a declared parameter.
    #[error("parameter `{0}` is not declared (ros2 param list shows the names)")]
    Undeclared(String),
    /// The parameter cannot change while the node runs.
    #[error("parameter `{0}` is read-only while the node runs (restart with the new value)")]
    ReadOnly(String),
    /// The value's type is not the parameter's.
    #[error("parameter `{name}` is of type {want}; got {got} ({value})")]
    WrongType {
        /// The parameter.
        name: String,
        /// Its type.
        want: &'static str,
        /// The type given.
        got: &'static str,
        /// The value given.
        value: String,
    },
    /// The new configuration does not validate (the message names the key).
    #[error("{0}")]
    Invalid(String),
    /// An earlier change is still being applied.
    #[error("the node is still applying earlier changes; try again")]
    Busy,
}

/// A parameter type's name.
pub fn type_name(t: u8) -> &'static str {
    match t {
        ty::BOOL => "bool",
        ty::INTEGER => "integer",
        ty::DOUBLE => "double",
        ty::STRING => "string",
        ty::BYTE_ARRAY => "byte array",
        ty::BOOL_ARRAY => "bool array",
        ty::INTEGER_ARRAY => "integer array",
        ty::DOUBLE_ARRAY => "double array",
        ty::STRING_ARRAY => "string array",
        _ => "not set",
    }
}

/// `config` with `key` set to `value`, given as YAML text (the C API's and
/// Python's `set_parameter`): [`apply_set`] of the parsed value.
pub fn set_from_text(
    config: &Config,
    declared: &[Declared],
    key: &str,
    value: &str,
) -> Result<Config, SetRefusal> {
    let yaml: Value = serde_norway::from_str(value).map_err(|e| {
        SetRefusal::Invalid(format!(
            "parameter `{key}`: value `{value}` is not YAML: {e}"
        ))
    })?;
    apply_set(
        config,
        declared,
        &[(key.to_string(), ParameterValue::from_yaml(&yaml))],
    )
}

/// `config` with `changes` (name, value) applied and validated; refuses
/// undeclared or read-only names, wrong types (an integer for a double is
/// accepted, as a number) and values outside their range, naming the key
/// and the value.
pub fn apply_set(
    config: &Config,
    declared: &[Declared],
    changes: &[(String, ParameterValue)],
) -> Result<Config, SetRefusal> {
    let mut tree = serde_norway::to_value(config).expect("config serializes");
    for (name, value) in changes {
        let d = declared
            .iter()
            .find(|d| d.name == *name)
            .ok_or_else(|| SetRefusal::Undeclared(name.clone()))?;
        if d.read_only {
            return Err(SetRefusal::ReadOnly(name.clone()));
        }
        let compatible = value.r#type == d.r#type
            || (d.r#type == ty::DOUBLE && value.r#type == ty::INTEGER)
            || (d.r#type == ty::DOUBLE_ARRAY && value.r#type == ty::INTEGER_ARRAY);
        let text = value
            .to_yaml()
            .map_err(|m| SetRefusal::Invalid(format!("parameter `{name}`: {m}")))?;
        if !compatible {
            return Err(SetRefusal::WrongType {
                name: name.clone(),
                want: type_name(d.r#type),
                got: type_name(value.r#type),
                value: text,
            });
        }
        crate::config::apply_override(&mut tree, &format!("{name}={text}"))
            .map_err(|e| SetRefusal::Invalid(e.to_string()))?;
    }
    let new: Config = serde_path_to_error::deserialize(tree)
        .map_err(|e| SetRefusal::Invalid(format!("parameter `{}`: {}", e.path(), e.inner())))?;
    new.validate()
        .map_err(|e: ConfigError| SetRefusal::Invalid(e.to_string()))?;
    Ok(new)
}

/// The catalogue as a markdown table (key | symbol | unit | range | live |
/// meaning): the README's table of the friction terms' keys is this text.
pub fn term_keys_table() -> String {
    let mut s =
        String::from("| key | symbol | unit | valid range | meaning |\n|---|---|---|---|---|\n");
    for k in catalogue() {
        let range = IntervalText(Interval { lo: k.lo, hi: k.hi });
        s.push_str(&format!(
            "| `{}` | {} | {} | {range} | {} |\n",
            k.key, k.symbol, k.unit, k.meaning
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_readme_lists_the_terms_keys_as_the_catalogue_declares_them() {
        let readme = include_str!(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md"));
        let table = term_keys_table();
        assert!(
            readme.contains(&table),
            "README.md lacks the table:\n{table}"
        );
    }

    fn value(text: &str) -> ParameterValue {
        ParameterValue::from_yaml(&serde_norway::from_str(text).unwrap())
    }

    #[test]
    fn every_key_is_declared_with_its_type_description_range_and_writability() {
        let c = Config::default();
        let d = declare(&c);
        let get = |n: &str| {
            d.iter()
                .find(|p| p.name == n)
                .unwrap_or_else(|| panic!("{n}"))
        };
        let load = get("contact.load_n");
        assert_eq!(load.r#type, ty::DOUBLE);
        assert!(!load.read_only);
        assert!(
            load.description.contains("normal load"),
            "{}",
            load.description
        );
        assert_eq!(load.range.as_ref().unwrap().to_string(), "(0, 1e9]");
        assert_eq!(get("solver.cells").r#type, ty::INTEGER);
        assert!(get("solver.cells").read_only);
        assert_eq!(get("use_sim_time").r#type, ty::BOOL);
        assert_eq!(get("node.timeout_behaviour").r#type, ty::STRING);
        assert!(!get("node.timeout_behaviour").read_only);
        assert_eq!(get("texture.pocket_start_m").r#type, ty::DOUBLE_ARRAY);
        assert_eq!(get("ros.remappings").r#type, ty::STRING_ARRAY);
        assert!(get("contact.profile").read_only);
        assert_eq!(d.len(), flatten(&c).len());
    }

    #[test]
    fn a_set_is_validated_and_refusals_name_the_key_and_the_value() {
        let c = Config::default();
        let d = declare(&c);
        let ok = apply_set(&c, &d, &[("contact.load_n".into(), value("5762"))]).unwrap();
        assert_eq!(
            ok.contact.load_n, 5762.0,
            "an integer for a double is a number"
        );
        for (name, v, needle) in [
            ("contact.load_n", "-3.0", "contact.load_n"),
            ("contact.load_n", "heavy", "string"),
            ("solver.cells", "64", "read-only"),
            ("contact.nosuch", "1.0", "not declared"),
            (
                "node.timeout_behaviour",
                "explode",
                "node.timeout_behaviour",
            ),
        ] {
            let e = apply_set(&c, &d, &[(name.into(), value(v))])
                .unwrap_err()
                .to_string();
            assert!(e.contains(needle), "{name}={v}: {e}");
        }
        let e = apply_set(&c, &d, &[("contact.load_n".into(), value("-3.0"))])
            .unwrap_err()
            .to_string();
        assert!(e.contains("-3"), "the value is named: {e}");
    }
}
