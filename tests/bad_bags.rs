//! Damaged and hostile bags through `replay`: truncation at many offsets,
//! bit flips, absurd record lengths, bad chunk CRCs, corrupt compression,
//! CDR sequences declaring 2^31 elements, lying schemas, 100 000 channels,
//! time going backwards, things that are not bags. A damaged bag replays
//! what precedes the damage (exit 0, saying so) or is refused with a message
//! naming it (exit 2); never a panic, never a half-written output.
#![cfg(feature = "mcap")]

mod common;
use common::cli::fresh_dir;

use friction_node::msgs;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::Command;

const NODE_BAG: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/bags/node_lockstep.mcap");

struct Outcome {
    code: i32,
    stdout: String,
    stderr: String,
}

fn replay(bag: &Path, out: &Path, extra: &[&str]) -> Outcome {
    let o = Command::new(env!("CARGO_BIN_EXE_friction-node"))
        .arg("replay")
        .arg(bag)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    Outcome {
        code: o.status.code().unwrap_or(-1),
        stdout: String::from_utf8_lossy(&o.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&o.stderr).into_owned(),
    }
}

/// The outcome is one of the two allowed, and the output directory holds a
/// complete output (exit 0) or nothing (exit 2), never a temporary file.
#[track_caller]
fn sane(o: &Outcome, out: &Path, what: &str) {
    assert!(
        o.code == 0 || o.code == 2,
        "{what}: exit {} (a panic is 101)\n{}",
        o.code,
        o.stderr
    );
    let dir = out.parent().unwrap();
    let names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(
        names.iter().all(|n| !n.contains(".tmp-")),
        "{what}: temporary left: {names:?}"
    );
    if o.code == 0 {
        let text = std::fs::read_to_string(out).unwrap();
        assert!(text.lines().count() >= 2, "{what}: an empty output");
        let cols = text.lines().next().unwrap().split(',').count();
        assert!(
            text.lines().all(|l| l.split(',').count() == cols),
            "{what}: a half-written row"
        );
    } else {
        assert!(!out.exists(), "{what}: an output after a refusal");
        assert!(
            o.stderr.lines().any(|l| l.starts_with("error: ")),
            "{what}: {}",
            o.stderr
        );
    }
}

#[test]
fn a_bag_truncated_at_any_of_60_offsets_replays_its_prefix_or_is_refused() {
    let bytes = std::fs::read(NODE_BAG).unwrap();
    let d = fresh_dir("badbag", "trunc");
    let (mut replayed, mut refused) = (0, 0);
    let offsets: Vec<usize> = [0, 1, 7, 8, 9, 17, 30, 100, 500]
        .into_iter()
        .chain((1..=50).map(|k| k * bytes.len() / 51))
        .chain([bytes.len() - 1])
        .collect();
    for &cut in &offsets {
        let bag = d.join("t.mcap");
        std::fs::write(&bag, &bytes[..cut]).unwrap();
        let out = d.join("o.csv");
        let _ = std::fs::remove_file(&out);
        let o = replay(&bag, &out, &[]);
        sane(&o, &out, &format!("truncated at {cut}"));
        if o.code == 0 {
            replayed += 1;
            // Either the loss is reported, or nothing was lost (a cut in
            // the footer's end magic loses no message).
            assert!(
                o.stdout.contains("damaged") || o.stdout.contains("steps            2000 "),
                "cut {cut}: a loss not reported\n{}",
                o.stdout
            );
        } else {
            refused += 1;
            assert!(o.stderr.contains("t.mcap"), "cut {cut}: {}", o.stderr);
        }
    }
    assert!(
        replayed > 30 && refused > 3,
        "{replayed} replayed, {refused} refused"
    );
}

#[test]
fn single_bit_flips_anywhere_never_panic_or_leave_half_an_output() {
    let bytes = std::fs::read(NODE_BAG).unwrap();
    let d = fresh_dir("badbag", "flip");
    for k in 0..60 {
        let pos = 3 + k * (bytes.len() - 4) / 60;
        let mut b = bytes.clone();
        b[pos] ^= 1 << (k % 8);
        let bag = d.join("f.mcap");
        std::fs::write(&bag, &b).unwrap();
        let out = d.join("o.csv");
        let _ = std::fs::remove_file(&out);
        let o = replay(&bag, &out, &[]);
        sane(&o, &out, &format!("bit {} of byte {pos}", k % 8));
    }
}

/// (offset, opcode, length) of every top-level record after the magic.
fn records(b: &[u8]) -> Vec<(usize, u8, u64)> {
    let mut out = Vec::new();
    let mut at = 8;
    while at + 9 <= b.len() {
        let op = b[at];
        let len = u64::from_le_bytes(b[at + 1..at + 9].try_into().unwrap());
        out.push((at, op, len));
        if op == 0x02 {
            break; // footer
        }
        at += 9 + len as usize;
    }
    out
}

#[test]
fn absurd_record_lengths_bad_chunk_crcs_and_corrupt_compression_are_damage() {
    let bytes = std::fs::read(NODE_BAG).unwrap();
    let recs = records(&bytes);
    let chunks: Vec<&(usize, u8, u64)> = recs.iter().filter(|r| r.1 == 0x06).collect();
    assert!(chunks.len() >= 2, "the fixture has chunks");
    let d = fresh_dir("badbag", "records");
    let mut cases: Vec<(&str, Vec<u8>)> = Vec::new();
    // The header record claims 2^64 − 1 bytes.
    let mut b = bytes.clone();
    b[9..17].copy_from_slice(&u64::MAX.to_le_bytes());
    cases.push(("huge header length", b));
    // The second chunk claims more bytes than the file has.
    let mut b = bytes.clone();
    let (at, _, _) = *chunks[1];
    b[at + 1..at + 9].copy_from_slice(&(1u64 << 40).to_le_bytes());
    cases.push(("huge chunk length", b));
    // The second chunk's CRC of its uncompressed records is wrong.
    let mut b = bytes.clone();
    let crc_at = at + 9 + 24;
    b[crc_at] ^= 0xFF;
    cases.push(("bad chunk CRC", b));
    // The second chunk's compressed bytes are garbage.
    let mut b = bytes.clone();
    let body = at + 9;
    let comp_len = u32::from_le_bytes(b[body + 28..body + 32].try_into().unwrap()) as usize;
    let data = body + 32 + comp_len + 8;
    for x in &mut b[data + 4..data + 64] {
        *x = 0xA5;
    }
    cases.push(("corrupt compression", b));
    for (what, b) in cases {
        let bag = d.join("r.mcap");
        std::fs::write(&bag, &b).unwrap();
        let out = d.join("o.csv");
        let _ = std::fs::remove_file(&out);
        let o = replay(&bag, &out, &[]);
        sane(&o, &out, what);
        if o.code == 0 {
            assert!(o.stdout.contains("damaged"), "{what}: {}", o.stdout);
        }
    }
}

/// A bag with the given channels (topic, schema name, schema text) and
/// messages (channel index, log time ns, CDR bytes).
fn write_bag(path: &Path, channels: &[(String, &str, &str)], messages: &[(usize, u64, Vec<u8>)]) {
    let mut w = mcap::Writer::new(std::io::BufWriter::new(
        std::fs::File::create(path).unwrap(),
    ))
    .unwrap();
    let mut schemas = BTreeMap::new();
    let ids: Vec<u16> = channels
        .iter()
        .map(|(topic, name, text)| {
            let s = *schemas
                .entry((name.to_string(), text.to_string()))
                .or_insert_with(|| w.add_schema(name, "ros2msg", text.as_bytes()).unwrap());
            w.add_channel(s, topic, "cdr", &BTreeMap::new()).unwrap()
        })
        .collect();
    for (k, (c, t, data)) in messages.iter().enumerate() {
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: ids[*c],
                sequence: k as u32,
                log_time: *t,
                publish_time: *t,
            },
            data,
        )
        .unwrap();
    }
    w.finish().unwrap();
}

const F64: &str = "float64 data\n";
const JS: &str = "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n================================================================================\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n";

fn f64_cdr(v: f64) -> Vec<u8> {
    msgs::to_cdr(&msgs::Float64 { data: v }).unwrap()
}

#[test]
fn a_joint_state_declaring_2_pow_31_names_is_a_decode_error_not_an_allocation() {
    let d = fresh_dir("badbag", "cdr");
    // Header: stamp (8), frame_id "" (4 + 1 + pad 3), then name count 2^31.
    let mut bad = vec![0x00, 0x01, 0x00, 0x00];
    bad.extend_from_slice(&[0; 8]);
    bad.extend_from_slice(&1u32.to_le_bytes());
    bad.extend_from_slice(&[0, 0, 0, 0]);
    bad.extend_from_slice(&(1u32 << 31).to_le_bytes());
    let bag = d.join("seq.mcap");
    write_bag(
        &bag,
        &[("/joint_states".into(), "sensor_msgs/msg/JointState", JS)],
        &[(0, 1_000_000_000, bad)],
    );
    let out = d.join("o.csv");
    let o = replay(&bag, &out, &["--topic", "/joint_states", "--joint", "a"]);
    sane(&o, &out, "2^31 names");
    assert_eq!(o.code, 2);
    assert!(
        o.stderr.contains("/joint_states") && o.stderr.contains("message 1"),
        "{}",
        o.stderr
    );
}

#[test]
fn a_schema_that_lies_about_its_type_is_named() {
    let d = fresh_dir("badbag", "lie");
    let bag = d.join("lie.mcap");
    write_bag(
        &bag,
        &[("/joint_states".into(), "sensor_msgs/msg/JointState", F64)],
        &[(0, 1_000_000_000, f64_cdr(0.1))],
    );
    let out = d.join("o.csv");
    let o = replay(&bag, &out, &["--topic", "/joint_states", "--joint", "a"]);
    sane(&o, &out, "lying schema");
    assert_eq!(o.code, 2);
    assert!(o.stderr.contains("schema does not match"), "{}", o.stderr);
}

#[test]
fn a_bag_of_60000_channels_is_listed_briefly() {
    let d = fresh_dir("badbag", "channels");
    let bag = d.join("many.mcap");
    // MCAP channel ids are 16 bits: one file holds at most 65 535.
    let channels: Vec<(String, &str, &str)> = (0..60_000)
        .map(|k| (format!("/c{k}"), "std_msgs/msg/Float64", F64))
        .collect();
    write_bag(&bag, &channels, &[(7, 1_000_000_000, f64_cdr(0.1))]);
    let out = d.join("o.csv");
    let o = replay(&bag, &out, &[]);
    sane(&o, &out, "60 000 channels");
    assert_eq!(o.code, 2);
    assert!(
        o.stderr.contains("--topic") && o.stderr.contains("more channels"),
        "{}",
        &o.stderr[..o.stderr.len().min(500)]
    );
    assert!(
        o.stderr.len() < 10_000,
        "{} bytes of message",
        o.stderr.len()
    );
    // Choosing one replays it.
    let o = replay(&bag, &out, &["--topic", "/c7"]);
    assert_eq!(o.code, 0, "{}", o.stderr);
}

#[test]
fn time_going_backwards_in_the_bag_is_sorted_onto_the_step_grid() {
    let d = fresh_dir("badbag", "backwards");
    let bag = d.join("back.mcap");
    let msgs: Vec<(usize, u64, Vec<u8>)> = (0..100u64)
        .map(|k| {
            (
                0,
                2_000_000_000 - k * 10_000_000,
                f64_cdr(0.5 - k as f64 * 0.001),
            )
        })
        .collect();
    write_bag(
        &bag,
        &[("/cmd_velocity".into(), "std_msgs/msg/Float64", F64)],
        &msgs,
    );
    let out = d.join("o.csv");
    let o = replay(&bag, &out, &[]);
    sane(&o, &out, "time going backwards");
    assert_eq!(o.code, 0, "{}", o.stderr);
    let text = std::fs::read_to_string(&out).unwrap();
    assert_eq!(text.lines().count() - 1, 991, "0.99 s on the 1 ms grid");
    // Sorted: the earliest stamp carried the last message's velocity.
    let first: Vec<&str> = text.lines().nth(1).unwrap().split(',').collect();
    assert_eq!(first[1], "0.401");
}

#[test]
fn things_that_are_not_bags_are_named() {
    let d = fresh_dir("badbag", "notbags");
    let out = d.join("o.csv");
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("empty.mcap", vec![], "MCAP magic"),
        ("text.mcap", b"hello, this is text\n".to_vec(), "MCAP magic"),
        ("db.mcap", b"SQLite format 3\0rest".to_vec(), "SQLite"),
        (
            "magic_only.mcap",
            b"\x89MCAP0\r\n".to_vec(),
            "magic_only.mcap",
        ),
    ];
    for (name, data, needle) in cases {
        let bag = d.join(name);
        std::fs::write(&bag, data).unwrap();
        let o = replay(&bag, &out, &[]);
        sane(&o, &out, name);
        assert_eq!(o.code, 2, "{name}");
        assert!(
            o.stderr.contains(name) && o.stderr.contains(needle),
            "{name}: {}",
            o.stderr
        );
    }
    // Directories: no metadata.yaml, metadata listing a file that is not there.
    let empty = d.join("emptydir");
    std::fs::create_dir_all(&empty).unwrap();
    let o = replay(&empty, &out, &[]);
    sane(&o, &out, "a directory without metadata.yaml");
    assert!(o.stderr.contains("metadata.yaml"), "{}", o.stderr);
    let listed = d.join("listed");
    std::fs::create_dir_all(&listed).unwrap();
    std::fs::write(
        listed.join("metadata.yaml"),
        "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n  relative_file_paths: [listed_0.mcap]\n",
    )
    .unwrap();
    let o = replay(&listed, &out, &[]);
    sane(&o, &out, "a missing split file");
    assert!(o.stderr.contains("listed_0.mcap"), "{}", o.stderr);
    let o = replay(Path::new("/nonexistent/bag.mcap"), &out, &[]);
    sane(&o, &out, "no such bag");
    assert!(o.stderr.contains("/nonexistent/bag.mcap"), "{}", o.stderr);
}

#[test]
fn a_stamp_years_away_is_refused_instead_of_a_grid_of_10_to_the_13_steps() {
    let d = fresh_dir("badbag", "years");
    let bag = d.join("years.mcap");
    let msgs = vec![
        (0, 1_000_000_000, f64_cdr(0.1)),
        (0, 1_001_000_000, f64_cdr(0.1)),
        (0, 400_000_000_000_000_000, f64_cdr(0.1)),
    ];
    write_bag(
        &bag,
        &[("/cmd_velocity".into(), "std_msgs/msg/Float64", F64)],
        &msgs,
    );
    let out = d.join("o.csv");
    let o = replay(&bag, &out, &[]);
    sane(&o, &out, "a stamp years away");
    assert_eq!(o.code, 2);
    assert!(
        o.stderr.contains("/cmd_velocity") && o.stderr.contains("a stamp is probably wrong"),
        "{}",
        o.stderr
    );
}
