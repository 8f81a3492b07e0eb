//! One definition of the estimate: `msg/msg/FrictionEstimate.msg` (the wire
//! layout's source of truth) names every field and says what it is, once.
//! Every other shape is held to it, field by field and doc by doc:
//!
//! - the loop's record (`EstimateRecord`), the ROS 2 wire struct and the
//!   iceoryx2 payload carry exactly the message's fields (the header as its
//!   stamp, `stamp_ns`), each documented with the message's comment;
//! - the offline shapes, the C API's `FnEstimate` and Python's `Estimate`,
//!   document the physical fields they share with it (velocity, load,
//!   forces, COF, film) with the message's comment; their own fields
//!   (model time, residual, sub-steps) and their code lists (`FN_STATUS_*`,
//!   strings in Python) are theirs.

use std::collections::BTreeMap;
use std::path::Path;

fn read(path: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(path)).unwrap()
}

/// The message's fields in order, each with its trailing comment.
fn message() -> Vec<(String, String)> {
    read("msg/msg/FrictionEstimate.msg")
        .lines()
        .filter_map(|l| {
            let (decl, comment) = l.split_once('#')?;
            let mut words = decl.split_whitespace();
            let (_, name) = (words.next()?, words.next()?);
            (!name.contains('=')).then(|| (name.to_string(), comment.trim().to_string()))
        })
        .collect()
}

/// The fields of `pub struct NAME` in `path`, in order, each with its doc
/// comment (the `///` lines above it, attributes skipped, joined by spaces).
fn shape(path: &str, name: &str) -> Vec<(String, String)> {
    let text = read(path);
    let lines: Vec<&str> = text.lines().collect();
    let start = lines
        .iter()
        .position(|l| {
            l.strip_prefix("pub struct ").is_some_and(|r| {
                r.starts_with(name)
                    && !r[name.len()..].starts_with(|c: char| c.is_alphanumeric() || c == '_')
            })
        })
        .unwrap_or_else(|| panic!("{path}: no struct {name}"));
    let mut out = Vec::new();
    for (i, l) in lines.iter().enumerate().skip(start + 1) {
        if *l == "}" {
            break;
        }
        let Some(field) = l.strip_prefix("    pub ").and_then(|r| r.split_once(':')) else {
            continue;
        };
        let mut j = i;
        while lines[j - 1].trim_start().starts_with("#[") {
            j -= 1;
        }
        let mut doc = Vec::new();
        while let Some(d) = lines[j - 1].trim_start().strip_prefix("///") {
            doc.insert(0, d.trim().to_string());
            j -= 1;
        }
        out.push((field.0.to_string(), doc.join(" ")));
    }
    out
}

#[test]
fn the_record_the_wire_struct_and_the_payload_carry_exactly_the_messages_fields_with_its_docs() {
    let msg = message();
    assert!(msg.len() >= 19, "{msg:?}");
    let expected: BTreeMap<String, String> = msg
        .iter()
        .map(|(n, d)| {
            if n == "header" {
                ("stamp_ns".to_string(), String::new())
            } else {
                (n.clone(), d.clone())
            }
        })
        .collect();
    for (path, name) in [
        ("src/msgs/records.rs", "EstimateRecord"),
        ("src/msgs/wire.rs", "FrictionEstimate"),
        ("src/transport/iceoryx/payloads.rs", "EstimatePayload"),
    ] {
        let fields = shape(path, name);
        let names: Vec<&str> = fields
            .iter()
            .map(|(n, _)| {
                if n == "header" {
                    "stamp_ns"
                } else {
                    n.as_str()
                }
            })
            .collect();
        let mut sorted = names.clone();
        sorted.sort_unstable();
        assert_eq!(
            sorted,
            expected.keys().map(String::as_str).collect::<Vec<_>>(),
            "{path}: {name}'s fields are not the message's"
        );
        for (field, doc) in &fields {
            if field == "header" || field == "stamp_ns" {
                continue;
            }
            assert_eq!(
                doc, &expected[field],
                "{path}: {name}.{field}'s doc is not the message's comment"
            );
        }
    }
}

#[test]
fn the_c_api_and_python_document_the_physical_fields_they_share_with_the_message_as_it_does() {
    let msg: BTreeMap<String, String> = message().into_iter().collect();
    let physical = [
        "velocity_m_s",
        "load_n",
        "friction_force_n",
        "contact_friction_force_n",
        "cof",
        "h0_m",
        "h_min_m",
        "hydrodynamic_force_n",
        "asperity_force_n",
        "asperity_load_share",
    ];
    for (path, name) in [
        ("capi/src/codes.rs", "FnEstimate"),
        ("python/src/model.rs", "Estimate"),
    ] {
        let fields: BTreeMap<String, String> = shape(path, name).into_iter().collect();
        for f in physical {
            let doc = fields
                .get(f)
                .unwrap_or_else(|| panic!("{path}: {name} lacks {f}"));
            assert_eq!(
                doc, &msg[f],
                "{path}: {name}.{f}'s doc is not the message's comment"
            );
        }
    }
    // The C header is generated from capi/src (tests/header.rs there): it
    // carries the same words.
    let header = read("capi/include/friction_node.h");
    for f in physical {
        assert!(
            header.contains(&format!("// {}\n", msg[f])),
            "friction_node.h: {f}'s comment is not the message's"
        );
    }
}

/// The fields of a `.msg` file in order, each with its trailing comment
/// (empty when it has none).
fn message_of(path: &str) -> Vec<(String, String)> {
    read(path)
        .lines()
        .filter(|l| !l.trim_start().starts_with('#') && !l.trim().is_empty())
        .filter_map(|l| {
            let (decl, comment) = l.split_once('#').unwrap_or((l, ""));
            let mut words = decl.split_whitespace();
            let (_, name) = (words.next()?, words.next()?);
            (!name.contains('=')).then(|| (name.to_string(), comment.trim().to_string()))
        })
        .collect()
}

/// The loop's statistics on the wire mirror `LoopStatistics.msg`: its
/// fields in its order, each commented field documented with its comment.
/// (The record groups them and the iceoryx2 payload packs them in fixed
/// arrays: see the next test.)
#[test]
fn the_wire_statistics_carry_the_messages_fields_in_order_with_its_docs() {
    let msg = message_of("msg/msg/LoopStatistics.msg");
    assert!(msg.len() >= 30, "{msg:?}");
    let wire = shape("src/msgs/wire.rs", "LoopStatistics");
    assert_eq!(
        wire.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>(),
        msg.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>()
    );
    for ((field, doc), (_, comment)) in wire.iter().zip(&msg) {
        if !comment.is_empty() && field != "header" {
            assert_eq!(
                doc, comment,
                "LoopStatistics.{field}'s doc is not the message's comment"
            );
        }
    }
}

/// A message comment as a doc sentence starts: capitalised, no final stop.
fn sentence(comment: &str) -> String {
    let mut c = comment.chars();
    let first = c.next().map(|f| f.to_uppercase().collect::<String>());
    format!("{}{}", first.unwrap_or_default(), c.as_str())
        .trim_end_matches('.')
        .to_string()
}

/// The loop's record of its statistics and the iceoryx2 payload carry every
/// field of `LoopStatistics.msg`, by its name or in a group the test names
/// (the stamp, the recorder's counters, the p50/p99/max arrays, the latest
/// input outside the calibrated range), and each field named as the
/// message's is documented with the message's comment (what a shape adds,
/// a code list or a unit, follows it).
#[test]
fn the_statistics_record_and_payload_carry_the_messages_fields_with_its_docs() {
    let msg = message_of("msg/msg/LoopStatistics.msg");
    let record = shape("src/msgs/records.rs", "StatisticsRecord");
    let recording = shape("src/msgs/records.rs", "RecordingStatus");
    let payload = shape("src/transport/iceoryx/payloads.rs", "StatisticsPayload");
    // Where a message field lives in a shape that groups it.
    let grouped = |shape: &str, field: &str| -> Option<&'static str> {
        let arrays = [
            ("compute_time_p", "compute_time_ns"),
            ("compute_time_max_ns", "compute_time_ns"),
            ("period_jitter_", "period_jitter_ns"),
        ];
        if field == "header" {
            return Some("stamp_ns");
        }
        if let Some((_, a)) = arrays.iter().find(|(p, _)| field.starts_with(p)) {
            return Some(a);
        }
        match shape {
            "record" if field.starts_with("recording_") || field.contains("snapshot") => {
                Some("recording")
            }
            "record" if field.starts_with("outside_") => Some("last_outside"),
            _ => None,
        }
    };
    let comment = |f: &str| msg.iter().find(|(n, _)| n == f).map(|(_, c)| c.clone());
    let mut checked = 0;
    for (name, fields) in [("record", &record), ("payload", &payload)] {
        let names: Vec<&str> = fields.iter().map(|(n, _)| n.as_str()).collect();
        for (field, _) in &msg {
            let there = names.contains(&field.as_str())
                || grouped(name, field).is_some_and(|g| names.contains(&g));
            assert!(there, "the statistics {name} lacks LoopStatistics.{field}");
        }
        for (field, doc) in fields {
            let own = ["stamp_ns", "last_snapshot_len"].contains(&field.as_str())
                || msg
                    .iter()
                    .any(|(m, _)| grouped(name, m) == Some(field.as_str()));
            let Some(c) = comment(field) else {
                assert!(
                    own,
                    "the statistics {name}'s `{field}` is not in LoopStatistics.msg"
                );
                continue;
            };
            let c = if c.is_empty() && field == "outside_max" {
                comment("outside_min").unwrap()
            } else {
                c
            };
            assert!(
                doc.starts_with(&sentence(&c)),
                "the statistics {name}'s `{field}` doc `{doc}` is not the message's `{c}`"
            );
            checked += 1;
        }
    }
    // The recorder's counters, under the record's `recording`.
    for (field, doc) in &recording {
        let c = comment(&format!("recording_{field}"))
            .or_else(|| comment(field))
            .unwrap_or_else(|| panic!("RecordingStatus.{field} is not in LoopStatistics.msg"));
        assert!(
            doc.starts_with(&sentence(&c)),
            "RecordingStatus.{field}: `{doc}`, not `{c}`"
        );
        checked += 1;
    }
    assert!(checked > 50, "{checked} docs checked");
}
