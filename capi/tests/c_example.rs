//! `examples/c/friction_step.c`, compiled with the system C compiler against
//! the static library and run: its estimates are bit-identical to
//! `simulate` (the library's `offline::simulate`, which the CLI runs) on the
//! same velocity history.

use friction_node::config::Config;
use friction_node::signal::Signal;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

/// The static library cargo built for this test: in `target/<profile>/deps`
/// beside the test (a test build does not copy it up to `target/<profile>`).
fn static_library() -> PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap();
    [deps, deps.parent().unwrap()]
        .iter()
        .map(|d| d.join("libfriction_node_c.a"))
        .find(|p| p.exists())
        .unwrap_or_else(|| {
            panic!(
                "libfriction_node_c.a is not in {} or its parent",
                deps.display()
            )
        })
}

fn compile(tmp: &Path) -> PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lib = static_library();
    let exe = tmp.join("friction_step");
    let cc = std::env::var("CC").unwrap_or_else(|_| "cc".into());
    let out = Command::new(&cc)
        .arg(root.join("../examples/c/friction_step.c"))
        .arg("-std=c99")
        .arg("-Wall")
        .arg("-Werror")
        .arg("-I")
        .arg(root.join("include"))
        .arg(&lib)
        .args(["-lm", "-lpthread", "-ldl", "-o"])
        .arg(&exe)
        .output()
        .unwrap_or_else(|e| panic!("{cc}: {e}"));
    assert!(
        out.status.success(),
        "{cc} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    exe
}

#[test]
fn the_c_example_reproduces_simulate_bit_for_bit() {
    let tmp = std::env::temp_dir().join(format!("friction-capi-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let exe = compile(&tmp);

    let config = Config::load(None, &[]).unwrap();
    let dt = config.solver.dt_s;
    let duration = 2.0;
    let velocity = Signal::parse("sine:0,1,1", "--velocity").unwrap();
    let load = Signal::parse(&format!("const:{}", config.contact.load_n), "--load").unwrap();
    let mut expected = Vec::new();
    friction_node::offline::simulate(&config, &velocity, &load, duration, |e, _| {
        expected.push((e.time, e.friction_force, e.h_min, e.status.as_str()));
        Ok(())
    })
    .unwrap();
    assert_eq!(config.contact.load_n, 20762.0, "the example's load");

    let mut child = Command::new(&exe)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    {
        let mut stdin = child.stdin.take().unwrap();
        let steps = expected.len();
        let mut text = String::new();
        for k in 1..=steps {
            text.push_str(&format!("{:?}\n", velocity.at(k as f64 * dt)));
        }
        stdin.write_all(text.as_bytes()).unwrap();
    }
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines: Vec<String> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(str::to_string)
        .collect();
    assert_eq!(lines.len(), expected.len());
    for (k, (line, (t, f, h, status))) in lines.iter().zip(&expected).enumerate() {
        let c: Vec<&str> = line.split(',').collect();
        let num = |i: usize| c[i].parse::<f64>().unwrap();
        assert_eq!(
            (num(0).to_bits(), num(1).to_bits(), num(2).to_bits(), c[3]),
            (t.to_bits(), f.to_bits(), h.to_bits(), *status),
            "step {}: C {line} vs simulate {t},{f},{h},{status}",
            k + 1
        );
    }
    std::fs::remove_dir_all(&tmp).ok();
}

#[test]
fn the_c_example_names_a_bad_configuration() {
    let tmp = std::env::temp_dir().join(format!("friction-capi-bad-{}", std::process::id()));
    std::fs::create_dir_all(&tmp).unwrap();
    let exe = compile(&tmp);
    let cfg = tmp.join("bad.yaml");
    std::fs::write(
        &cfg,
        "/**:\n  ros__parameters:\n    roughness:\n      sigma_m: -1.0\n",
    )
    .unwrap();
    let out = Command::new(&exe).arg(&cfg).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("roughness.sigma_m") && err.contains("-1"),
        "{err}"
    );
    std::fs::remove_dir_all(&tmp).ok();
}
