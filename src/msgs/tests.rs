use super::*;
use serde::Serialize;
use serde_norway::Value;

/// Field names and kinds of a serialized struct, in order.
fn fields<T: Serialize>(v: &T) -> Vec<(String, Value)> {
    match serde_norway::to_value(v).unwrap() {
        Value::Mapping(m) => m
            .into_iter()
            .map(|(k, v)| (k.as_str().unwrap().to_string(), v))
            .collect(),
        other => panic!("not a struct: {other:?}"),
    }
}

fn kind_ok(msg_type: &str, v: &Value) -> bool {
    if msg_type.ends_with("[]") {
        return matches!(v, Value::Sequence(_));
    }
    match msg_type {
        "float64" | "float32" => matches!(v, Value::Number(n) if n.is_f64()),
        "uint8" | "uint32" | "uint64" | "int32" | "int64" => {
            matches!(v, Value::Number(n) if n.is_u64() || n.is_i64())
        }
        "string" => matches!(v, Value::String(_)),
        _ => matches!(v, Value::Mapping(_)),
    }
}

fn check<T: Serialize + Default>(t: &MsgType) {
    let msg = msg_fields(t.definition);
    let rust = fields(&T::default());
    let names: Vec<&str> = rust.iter().map(|(n, _)| n.as_str()).collect();
    let msg_names: Vec<&str> = msg.iter().map(|(_, n)| n.as_str()).collect();
    assert_eq!(
        names, msg_names,
        "{}: field names/order differ from the .msg",
        t.name
    );
    for ((ty, name), (_, v)) in msg.iter().zip(&rust) {
        assert!(
            kind_ok(ty, v),
            "{}.{name}: .msg type {ty}, Rust value {v:?}",
            t.name
        );
    }
}

#[test]
fn wire_structs_mirror_the_msg_files_field_by_field() {
    check::<FrictionEstimate>(&FRICTION_ESTIMATE);
    check::<FilmProfile>(&FILM_PROFILE);
    check::<LoopStatistics>(&LOOP_STATISTICS);
    check::<Header>(&HEADER);
    check::<Time>(&TIME);
    check::<TwistStamped>(&TWIST_STAMPED);
    check::<JointState>(&JOINT_STATE);
    check::<Float64MultiArray>(&FLOAT64_MULTI_ARRAY);
    check::<MultiArrayLayout>(&MULTI_ARRAY_LAYOUT);
    check::<MultiArrayDimension>(&MULTI_ARRAY_DIMENSION);
    check::<Float64>(&FLOAT64);
    check::<Temperature>(&TEMPERATURE);
    check::<FrictionEstimateV1>(&FRICTION_ESTIMATE_V1);
}

#[test]
fn time_saturates_at_the_int32_second_limit_instead_of_wrapping() {
    let t = Time::from_ns(u64::MAX);
    assert_eq!(t.sec, i32::MAX);
    assert_eq!(t.nanosec, 999_999_999);
    assert!(!Time::fits(u64::MAX));
    let ns = 1_763_900_000_123_456_789;
    assert!(Time::fits(ns));
    assert_eq!(Time::from_ns(ns).to_ns(), ns);
}

#[test]
fn a_bag_estimate_of_the_earlier_layout_maps_its_command_flags_to_command_status() {
    let old = FrictionEstimateV1 {
        status: estimate_constants::LEGACY_STATUS_COMMAND_TIMEOUT,
        velocity_m_s: 0.5,
        iterations: 2,
        ..Default::default()
    };
    let bytes = to_cdr(&old).unwrap();
    let schema = FRICTION_ESTIMATE_V1.ros2msg_schema();
    assert!(check_estimate_schema(&schema).is_ok());
    assert_eq!(EstimateLayout::of_schema(&schema), Ok(EstimateLayout::V1));
    assert_eq!(
        EstimateLayout::of_schema(&FRICTION_ESTIMATE.ros2msg_schema()),
        Ok(EstimateLayout::Current)
    );
    let r = decode_estimate(&bytes, EstimateLayout::V1).unwrap();
    assert_eq!(r.status, estimate_constants::STATUS_CONVERGED);
    assert_eq!(r.command_status, estimate_constants::COMMAND_TIMED_OUT);
    assert_eq!((r.velocity_m_s, r.iterations), (0.5, 2));
    assert!(check_estimate_schema("float64 x\n").is_err());
}

#[test]
fn a_bag_estimate_recorded_before_calibrated_range_reads_as_not_watched() {
    // The layout before `calibrated_range`: the same bytes, the new field
    // where padding was (here made non-zero to show it is not read).
    let mut bytes = to_cdr(
        &EstimateRecord {
            command_status: estimate_constants::COMMAND_HELD,
            iterations: 4,
            ..Default::default()
        }
        .to_wire("slider"),
    )
    .unwrap();
    let schema = FRICTION_ESTIMATE_V2.ros2msg_schema();
    assert_eq!(EstimateLayout::of_schema(&schema), Ok(EstimateLayout::V2));
    let at = bytes.len() - 8 - 8 - 4 - 1; // late, compute, iterations, then the pad byte
    bytes[at] = estimate_constants::RANGE_OUTSIDE;
    let r = decode_estimate(&bytes, EstimateLayout::V2).unwrap();
    assert_eq!(r.calibrated_range, estimate_constants::RANGE_NOT_WATCHED);
    assert_eq!(r.command_status, estimate_constants::COMMAND_HELD);
    assert_eq!(r.iterations, 4);
    let now = decode_estimate(&bytes, EstimateLayout::Current).unwrap();
    assert_eq!(now.calibrated_range, estimate_constants::RANGE_OUTSIDE);
}

#[test]
fn msg_constants_match_the_rust_constants() {
    use estimate_constants::*;
    let text = FRICTION_ESTIMATE.definition;
    for (name, value) in [
        ("REGIME_BOUNDARY", REGIME_BOUNDARY),
        ("REGIME_MIXED", REGIME_MIXED),
        ("REGIME_HYDRODYNAMIC", REGIME_HYDRODYNAMIC),
        ("STATUS_CONVERGED", STATUS_CONVERGED),
        ("STATUS_MAX_ITERATIONS", STATUS_MAX_ITERATIONS),
        ("STATUS_NON_FINITE", STATUS_NON_FINITE),
        ("STATUS_NON_FINITE_INPUT", STATUS_NON_FINITE_INPUT),
        ("STATUS_INPUT_OUT_OF_RANGE", STATUS_INPUT_OUT_OF_RANGE),
        ("COMMAND_FRESH", COMMAND_FRESH),
        ("COMMAND_HELD", COMMAND_HELD),
        ("COMMAND_TIMED_OUT", COMMAND_TIMED_OUT),
        ("RANGE_NOT_WATCHED", RANGE_NOT_WATCHED),
        ("RANGE_INSIDE", RANGE_INSIDE),
        ("RANGE_OUTSIDE", RANGE_OUTSIDE),
        ("COMMAND_REJECTED", COMMAND_REJECTED),
    ] {
        assert!(
            text.contains(&format!("uint8 {name}={value}")),
            "{name}={value} not in the .msg"
        );
    }
}

#[test]
fn ros2msg_schema_appends_each_dependency_once() {
    let s = FRICTION_ESTIMATE.ros2msg_schema();
    assert!(s.starts_with("# The friction estimate"));
    assert_eq!(s.matches(&"=".repeat(80)).count(), 2);
    assert!(s.contains("\nMSG: std_msgs/Header\nbuiltin_interfaces/Time stamp\nstring frame_id\n"));
    assert!(s.contains("\nMSG: builtin_interfaces/Time\nint32 sec\nuint32 nanosec\n"));
    let t = TWIST_STAMPED.ros2msg_schema();
    for dep in [
        "MSG: std_msgs/Header",
        "MSG: builtin_interfaces/Time",
        "MSG: geometry_msgs/Twist",
        "MSG: geometry_msgs/Vector3",
    ] {
        assert!(t.contains(dep), "{dep}");
    }
}

#[test]
fn cdr_round_trips_with_the_encapsulation_header() {
    let r = EstimateRecord {
        stamp_ns: 1_234_567_891_011,
        velocity_m_s: -0.25,
        friction_force_n: -123.5,
        iterations: 3,
        status: estimate_constants::STATUS_INPUT_OUT_OF_RANGE,
        command_status: estimate_constants::COMMAND_TIMED_OUT,
        calibrated_range: estimate_constants::RANGE_OUTSIDE,
        late_ns: 7,
        ..Default::default()
    };
    let bytes = to_cdr(&r.to_wire("slider")).unwrap();
    assert_eq!(&bytes[..4], &[0, 1, 0, 0]);
    let back: FrictionEstimate = from_cdr(&bytes).unwrap();
    assert_eq!(EstimateRecord::from_wire(&back), r);
    assert_eq!(back.header.frame_id, "slider");
    assert!(matches!(
        from_cdr::<FrictionEstimate>(&bytes[..10]),
        Err(CdrError::Body { .. })
    ));
    assert_eq!(
        from_cdr::<FrictionEstimate>(&bytes[..2]),
        Err(CdrError::TooShort { len: 2 })
    );
    let mut xcdr = bytes.clone();
    xcdr[1] = 0x07;
    assert_eq!(
        from_cdr::<FrictionEstimate>(&xcdr),
        Err(CdrError::Encapsulation { header: [0, 7] })
    );
}
