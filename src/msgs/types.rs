//! Message types and their `ros2msg` schemas (what MCAP bags carry).

/// A ROS 2 message type: package, name, `.msg` text and the types it uses.
#[derive(Debug)]
pub struct MsgType {
    /// The package (`std_msgs`).
    pub package: &'static str,
    /// The type's name (`Float64`).
    pub name: &'static str,
    /// The `.msg` text.
    pub definition: &'static str,
    /// The types the definition uses.
    pub dependencies: &'static [&'static MsgType],
}

impl MsgType {
    /// `pkg/msg/Name` (the MCAP schema name and ROS 2 type string).
    pub fn full_name(&self) -> String {
        format!("{}/msg/{}", self.package, self.name)
    }

    /// The `ros2msg` schema: the definition, then every (transitive)
    /// dependency after a line of 80 `=` and `MSG: pkg/Name`.
    pub fn ros2msg_schema(&self) -> String {
        let mut out = self.definition.trim_end().to_string();
        out.push('\n');
        let mut seen: Vec<&str> = Vec::new();
        fn walk(t: &MsgType, out: &mut String, seen: &mut Vec<&'static str>) {
            for d in t.dependencies {
                let key = d.name;
                if seen.contains(&key) {
                    continue;
                }
                seen.push(key);
                out.push_str(&"=".repeat(80));
                out.push_str(&format!("\nMSG: {}/{}\n", d.package, d.name));
                out.push_str(d.definition.trim_end());
                out.push('\n');
                walk(d, out, seen);
            }
        }
        walk(self, &mut out, &mut seen);
        out
    }
}

/// The `time` message type (definition and dependencies).
pub static TIME: MsgType = MsgType {
    package: "builtin_interfaces",
    name: "Time",
    definition: "int32 sec\nuint32 nanosec\n",
    dependencies: &[],
};

/// The `header` message type (definition and dependencies).
pub static HEADER: MsgType = MsgType {
    package: "std_msgs",
    name: "Header",
    definition: "builtin_interfaces/Time stamp\nstring frame_id\n",
    dependencies: &[&TIME],
};

/// The `float64` message type (definition and dependencies).
pub static FLOAT64: MsgType = MsgType {
    package: "std_msgs",
    name: "Float64",
    definition: "float64 data\n",
    dependencies: &[],
};

/// The `vector3` message type (definition and dependencies).
pub static VECTOR3: MsgType = MsgType {
    package: "geometry_msgs",
    name: "Vector3",
    definition: "float64 x\nfloat64 y\nfloat64 z\n",
    dependencies: &[],
};

/// The `twist` message type (definition and dependencies).
pub static TWIST: MsgType = MsgType {
    package: "geometry_msgs",
    name: "Twist",
    definition: "Vector3 linear\nVector3 angular\n",
    dependencies: &[&VECTOR3],
};

/// The `twist_stamped` message type (definition and dependencies).
pub static TWIST_STAMPED: MsgType = MsgType {
    package: "geometry_msgs",
    name: "TwistStamped",
    definition: "std_msgs/Header header\nTwist twist\n",
    dependencies: &[&HEADER, &TWIST],
};

/// The `joint_state` message type (definition and dependencies).
pub static JOINT_STATE: MsgType = MsgType {
    package: "sensor_msgs",
    name: "JointState",
    definition: "std_msgs/Header header\nstring[] name\nfloat64[] position\nfloat64[] velocity\nfloat64[] effort\n",
    dependencies: &[&HEADER],
};

/// The `multi_array_dimension` message type (definition and dependencies).
pub static MULTI_ARRAY_DIMENSION: MsgType = MsgType {
    package: "std_msgs",
    name: "MultiArrayDimension",
    definition: "string label\nuint32 size\nuint32 stride\n",
    dependencies: &[],
};

/// The `multi_array_layout` message type (definition and dependencies).
pub static MULTI_ARRAY_LAYOUT: MsgType = MsgType {
    package: "std_msgs",
    name: "MultiArrayLayout",
    definition: "MultiArrayDimension[] dim\nuint32 data_offset\n",
    dependencies: &[&MULTI_ARRAY_DIMENSION],
};

/// The `float64_multi_array` message type (definition and dependencies).
pub static FLOAT64_MULTI_ARRAY: MsgType = MsgType {
    package: "std_msgs",
    name: "Float64MultiArray",
    definition: "MultiArrayLayout layout\nfloat64[] data\n",
    dependencies: &[&MULTI_ARRAY_LAYOUT],
};

/// The `empty` message type (definition and dependencies).
pub static EMPTY: MsgType = MsgType {
    package: "std_msgs",
    name: "Empty",
    definition: "",
    dependencies: &[],
};

/// The `temperature` message type (definition and dependencies).
pub static TEMPERATURE: MsgType = MsgType {
    package: "sensor_msgs",
    name: "Temperature",
    definition: "std_msgs/Header header\nfloat64 temperature\nfloat64 variance\n",
    dependencies: &[&HEADER],
};

/// The `friction_estimate` message type (definition and dependencies).
pub static FRICTION_ESTIMATE: MsgType = MsgType {
    package: "friction_msgs",
    name: "FrictionEstimate",
    definition: include_str!("../../msg/msg/FrictionEstimate.msg"),
    dependencies: &[&HEADER],
};

/// The `film_profile` message type (definition and dependencies).
pub static FILM_PROFILE: MsgType = MsgType {
    package: "friction_msgs",
    name: "FilmProfile",
    definition: include_str!("../../msg/msg/FilmProfile.msg"),
    dependencies: &[&HEADER],
};

/// The `loop_statistics` message type (definition and dependencies).
pub static LOOP_STATISTICS: MsgType = MsgType {
    package: "friction_msgs",
    name: "LoopStatistics",
    definition: include_str!("../../msg/msg/LoopStatistics.msg"),
    dependencies: &[&HEADER],
};

/// `FrictionEstimate` before `command_status` (bags recorded until then).
pub static FRICTION_ESTIMATE_V1: MsgType = MsgType {
    package: "friction_msgs",
    name: "FrictionEstimate",
    definition: include_str!("legacy/FrictionEstimateV1.msg"),
    dependencies: &[&HEADER],
};

/// `FrictionEstimate` before `calibrated_range` (bags recorded until then).
pub static FRICTION_ESTIMATE_V2: MsgType = MsgType {
    package: "friction_msgs",
    name: "FrictionEstimate",
    definition: include_str!("legacy/FrictionEstimateV2.msg"),
    dependencies: &[&HEADER],
};

/// Fields of a `.msg` text, in order: (type, name). Comments, blank lines
/// and constants are skipped.
pub fn msg_fields(definition: &str) -> Vec<(String, String)> {
    definition
        .lines()
        .map(|l| l.split('#').next().unwrap_or("").trim())
        .filter(|l| !l.is_empty())
        .filter_map(|l| {
            let mut it = l.split_whitespace();
            let ty = it.next()?;
            let rest = it.next()?;
            if rest.contains('=') || l.contains('=') {
                return None; // constant
            }
            Some((ty.to_string(), rest.to_string()))
        })
        .collect()
}
