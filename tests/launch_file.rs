//! The shipped ROS 2 launch file and package manifest. ROS 2 is not on this
//! machine, so the launch file is read with Python's `ast`
//! (`tests/python/launch_command.py` builds the command line launch_ros
//! would run) and the node checks that command with `run --check`: the
//! executable, parameter files and remappings it passes must be accepted.

use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// What launch_ros would run, as (package, executable, argv after the
/// executable), with `overrides` as `name:=value` launch arguments.
fn launch_command(tmp: &Path, overrides: &[&str]) -> (String, String, Vec<String>) {
    let out = Command::new("python3")
        .arg(root().join("tests/python/launch_command.py"))
        .arg(root().join("launch-config/friction_node.launch.py"))
        .arg(root())
        .arg(tmp)
        .args(overrides)
        .output()
        .expect("python3 runs");
    assert!(
        out.status.success(),
        "launch_command.py failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let cmd: Vec<String> = v["command"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s.as_str().unwrap().to_string())
        .collect();
    (
        v["package"].as_str().unwrap().to_string(),
        v["executable"].as_str().unwrap().to_string(),
        cmd[1..].to_vec(),
    )
}

/// `friction-node <argv>` with `--check` added after the launch file's own
/// arguments (before the first `--ros-args`): (exit ok, stdout, stderr).
fn check(argv: &[String]) -> (bool, String, String) {
    let at = argv
        .iter()
        .position(|a| a == "--ros-args")
        .unwrap_or(argv.len());
    let mut args: Vec<String> = argv[..at].to_vec();
    args.push("--check".into());
    args.extend_from_slice(&argv[at..]);
    let out = Command::new(env!("CARGO_BIN_EXE_friction-node"))
        .args(&args)
        .output()
        .expect("the binary runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn tmpdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("friction-launch-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The `<name>` and build type of a package.xml (plain text search: the
/// manifest is ours and simple).
fn xml_tag<'a>(xml: &'a str, tag: &str) -> Vec<&'a str> {
    let open = format!("<{tag}>");
    let close = format!("</{tag}>");
    xml.match_indices(&open)
        .map(|(i, _)| {
            let rest = &xml[i + open.len()..];
            &rest[..rest.find(&close).expect("closed tag")]
        })
        .collect()
}

#[test]
fn the_launch_file_starts_this_packages_executable_and_the_node_accepts_its_defaults() {
    let tmp = tmpdir("defaults");
    let (package, executable, argv) = launch_command(&tmp, &[]);
    let manifest = std::fs::read_to_string(root().join("package.xml")).unwrap();
    assert_eq!(xml_tag(&manifest, "name"), [package.as_str()]);
    assert_eq!(xml_tag(&manifest, "build_type"), ["ament_cargo"]);
    assert!(xml_tag(&manifest, "exec_depend").contains(&"friction_msgs"));
    assert_eq!(
        package,
        env!("CARGO_PKG_NAME"),
        "cargo-ament-build installs under the Cargo name"
    );
    assert_eq!(
        executable,
        Path::new(env!("CARGO_BIN_EXE_friction-node"))
            .file_name()
            .unwrap()
            .to_str()
            .unwrap()
    );
    // The parameter file comes from share/<package>/launch-config, which
    // Cargo.toml asks cargo-ament-build to install.
    let cargo = std::fs::read_to_string(root().join("Cargo.toml")).unwrap();
    assert!(cargo.contains("[package.metadata.ros]\ninstall_to_share = [\"launch-config\"]"));
    let params = argv
        .iter()
        .zip(argv.iter().skip(1))
        .filter(|(a, _)| *a == "--params-file")
        .map(|(_, p)| PathBuf::from(p))
        .collect::<Vec<_>>();
    assert_eq!(
        params.len(),
        2,
        "the file and the use_sim_time dict: {argv:?}"
    );
    assert_eq!(params[0], root().join("launch-config/default.yaml"));

    let (ok, out, err) = check(&argv);
    assert!(
        ok,
        "the node refused the launch file's command {argv:?}: {err}"
    );
    assert!(out.contains("node: /friction_node\n"), "{out}");
    assert!(
        out.contains("  cmd_velocity: /slider/cmd_velocity\n"),
        "{out}"
    );
    assert!(
        out.contains("  friction: /friction_node/friction\n"),
        "{out}"
    );
    assert!(
        out.contains("  loop_statistics: /friction_node/loop_statistics\n"),
        "{out}"
    );
    std::fs::remove_dir_all(&tmp).ok();
}

#[test]
fn launch_arguments_rename_remap_and_reach_the_nodes_parameters() {
    let tmp = tmpdir("overrides");
    let (_, _, argv) = launch_command(
        &tmp,
        &[
            "node_name:=axis_x",
            "namespace:=robot",
            "cmd_velocity_topic:=/axis_x/velocity_command",
            "friction_topic:=/ff/friction",
            "use_sim_time:=true",
            "log_level:=warn",
        ],
    );
    let (ok, out, err) = check(&argv);
    assert!(ok, "{argv:?}: {err}");
    assert!(out.contains("node: /robot/axis_x\n"), "{out}");
    assert!(
        out.contains("  cmd_velocity: /axis_x/velocity_command\n"),
        "{out}"
    );
    assert!(out.contains("  friction: /ff/friction\n"), "{out}");
    assert!(
        out.contains("  normal_load: /robot/axis_x/normal_load\n"),
        "{out}"
    );
    assert!(out.contains("  use_sim_time: true\n"), "{out}");
    std::fs::remove_dir_all(&tmp).ok();
}

#[test]
fn a_bad_launch_argument_is_refused_with_its_value_named() {
    let tmp = tmpdir("bad");
    let (_, _, argv) = launch_command(&tmp, &["log_level:=verbose"]);
    let (ok, _, err) = check(&argv);
    assert!(!ok);
    assert!(err.contains("verbose"), "{err}");

    let bad_params = tmp.join("machine.yaml");
    std::fs::write(
        &bad_params,
        "/**:\n  ros__parameters:\n    contact:\n      load_n: -5.0\n",
    )
    .unwrap();
    let (_, _, argv) = launch_command(&tmp, &[&format!("params_file:={}", bad_params.display())]);
    let (ok, _, err) = check(&argv);
    assert!(!ok);
    assert!(
        err.contains("contact.load_n") && err.contains("-5"),
        "{err}"
    );

    std::fs::write(
        &bad_params,
        "/**:\n  ros__parameters:\n    contact:\n      load_n: heavy\n",
    )
    .unwrap();
    let (ok, _, err) =
        check(&launch_command(&tmp, &[&format!("params_file:={}", bad_params.display())]).2);
    assert!(!ok);
    assert!(err.contains("load_n") && err.contains("heavy"), "{err}");
    std::fs::remove_dir_all(&tmp).ok();
}
