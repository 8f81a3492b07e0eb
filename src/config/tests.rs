use super::*;

fn load(text: &str, sets: &[&str]) -> Result<Config, ConfigError> {
    let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
    Config::from_yaml(text, &Origin::Embedded, &sets)
}

#[test]
fn shipped_default_file_equals_the_built_in_defaults() {
    let c = Config::load(None, &[]).unwrap();
    assert_eq!(c, Config::default());
    assert_eq!(c.model(), ModelParams::default());
    assert_eq!(c.solver_settings(), SolverSettings::default());
    assert_eq!(c.contact.load_n, 20_762.0);
}

#[test]
fn every_shipped_parameter_file_loads() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("launch-config");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "yaml") {
            let c = Config::load(Some(&path), &[])
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            // Shipped configs keep ROS 2 discovery on this host.
            assert_eq!(
                c.ros.discovery_range,
                DiscoveryRange::Localhost,
                "{}",
                path.display()
            );
            n += 1;
        }
    }
    assert!(n >= 2);
}

#[test]
fn unknown_key_is_named_with_its_full_path() {
    let e = load(
        "friction_node:\n  ros__parameters:\n    contact:\n      lenght_m: 0.1\n",
        &[],
    )
    .unwrap_err();
    assert!(
        matches!(e, ConfigError::UnknownKey { ref key, .. } if key == "contact.lenght_m"),
        "{e}"
    );
    assert!(
        e.to_string().contains("did you mean `length_m`?"),
        "suggests the nearest valid key: {e}"
    );
    // A name near none of them gets the list alone.
    let e = load(
        "friction_node:\n  ros__parameters:\n    contact:\n      colour: 1\n",
        &[],
    )
    .unwrap_err();
    let m = e.to_string();
    assert!(!m.contains("did you mean") && m.contains("length_m"), "{m}");
}

#[test]
fn out_of_range_value_names_key_value_and_range() {
    let e = load(
        "friction_node:\n  ros__parameters:\n    lubricant:\n      viscosity_pa_s: -1.0\n",
        &[],
    )
    .unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("lubricant.viscosity_pa_s")
            && msg.contains("-1")
            && msg.contains("(1e-5, 100]"),
        "{msg}"
    );
}

#[test]
fn overrides_apply_and_are_validated_like_file_keys() {
    let c = load(
        DEFAULT_YAML,
        &[
            "contact.load_n=5762",
            "solver.method=reference",
            "roughness.flow_factors=true",
        ],
    )
    .unwrap();
    assert_eq!(c.contact.load_n, 5762.0);
    assert_eq!(c.solver.method, MethodKind::Reference);
    assert!(c.roughness.flow_factors);
    let e = load(DEFAULT_YAML, &["contact.lode_n=5"]).unwrap_err();
    assert!(matches!(e, ConfigError::UnknownKey { ref key, .. } if key == "contact.lode_n"));
    let e = load(DEFAULT_YAML, &["solver.cells=3"]).unwrap_err();
    assert!(e.to_string().contains("solver.cells"), "{e}");
    let e = load(DEFAULT_YAML, &["solver.method=magic"]).unwrap_err();
    assert!(e.to_string().contains("newton"), "{e}");
    assert!(matches!(
        load(DEFAULT_YAML, &["nokey"]).unwrap_err(),
        ConfigError::BadOverride { .. }
    ));
}

#[test]
fn node_ros_and_recording_values_outside_their_ranges_are_named() {
    for (set, key) in [
        ("node.command_timeout_s=-1", "node.command_timeout_s"),
        ("node.max_abs_velocity_m_s=0", "node.max_abs_velocity_m_s"),
        ("node.initial_velocity_m_s=20", "node.initial_velocity_m_s"),
        ("node.max_load_n=0.5", "node.max_load_n"),
        ("node.queue_capacity=2", "node.queue_capacity"),
        ("node.realtime.priority=0", "node.realtime.priority"),
        ("ros.domain_id=300", "ros.domain_id"),
        ("ros.qos.estimates.depth=0", "ros.qos.estimates.depth"),
        (
            "recording.chunk_size_bytes=10",
            "recording.chunk_size_bytes",
        ),
    ] {
        let e = load(DEFAULT_YAML, &[set]).unwrap_err();
        assert!(
            matches!(e, ConfigError::OutOfRange { key: ref k, .. } if k == key),
            "{set}: {e}"
        );
    }
    let c = load(
        DEFAULT_YAML,
        &["ros.qos.estimates.durability=transient_local"],
    )
    .unwrap();
    assert_eq!(c.ros.qos.estimates.durability, Durability::TransientLocal);
}

#[test]
fn wrong_file_layout_is_explained() {
    let e = load("contact:\n  load_n: 1\n", &[]).unwrap_err();
    assert!(e.to_string().contains("`contact` is not this node"), "{e}");
    let e = load("friction_node:\n  params: {}\n", &[]).unwrap_err();
    assert!(e.to_string().contains("ros__parameters"), "{e}");
    let e = load("friction_node: [", &[]).unwrap_err();
    assert!(matches!(e, ConfigError::Syntax { .. }));
    assert!(load(
        "/**:\n  ros__parameters:\n    contact: {load_n: 100.0}\n",
        &[]
    )
    .is_ok());
    assert!(load("/robot/friction_node:\n  ros__parameters: {}\n", &[]).is_ok());
}

#[test]
fn texture_arrays_must_have_equal_lengths_and_fit_the_slider() {
    let base = "friction_node:\n  ros__parameters:\n    texture:\n";
    let e = load(&format!("{base}      pocket_start_m: [0.01]\n      pocket_width_m: []\n      pocket_depth_m: [1e-6]\n"), &[]).unwrap_err();
    assert!(e.to_string().contains("texture.pocket_width_m"), "{e}");
    let e = load(&format!("{base}      pocket_start_m: [0.07]\n      pocket_width_m: [0.01]\n      pocket_depth_m: [1e-6]\n"), &[]).unwrap_err();
    assert!(e.to_string().contains("texture.pocket_width_m[0]"), "{e}");
    let c = load(&format!("{base}      pocket_start_m: [0.01]\n      pocket_width_m: [0.005]\n      pocket_depth_m: [5e-6]\n"), &[]).unwrap();
    assert_eq!(c.model().geometry.pockets.len(), 1);
}

#[test]
fn resolved_config_round_trips_through_yaml() {
    let c = load(
        DEFAULT_YAML,
        &[
            "contact.load_n=1234.5",
            "texture.pocket_start_m=[0.01]",
            "texture.pocket_width_m=[0.002]",
            "texture.pocket_depth_m=[3e-6]",
        ],
    )
    .unwrap();
    let again = Config::from_yaml(&c.to_yaml(), &Origin::Embedded, &[]).unwrap();
    assert_eq!(again, c);
}

#[test]
fn topic_node_and_namespace_names_are_checked_with_the_key_and_rule() {
    for (set, key, rule) in [
        (
            "ros.topics.friction=bad topic",
            "ros.topics.friction",
            "only letters",
        ),
        (
            "ros.topics.cmd_velocity=/a//b",
            "ros.topics.cmd_velocity",
            "`//`",
        ),
        (
            "ros.topics.loop_statistics=/x/",
            "ros.topics.loop_statistics",
            "end with",
        ),
        ("ros.node_name=my node", "ros.node_name", "only letters"),
        ("ros.namespace=robot", "ros.namespace", "absolute"),
        (
            "iceoryx2.friction_service=''",
            "iceoryx2.friction_service",
            "1 to 255",
        ),
    ] {
        let e = load(DEFAULT_YAML, &[set]).unwrap_err();
        let msg = e.to_string();
        assert!(
            matches!(e, ConfigError::InvalidValue { key: ref k, .. } if k == key)
                && msg.contains(rule),
            "{set}: {msg}"
        );
    }
}

#[test]
fn a_step_that_is_not_a_whole_number_of_nanoseconds_is_refused() {
    let e = load(DEFAULT_YAML, &["solver.dt_s=1.0000005e-3"]).unwrap_err();
    assert!(e.to_string().contains("whole number of nanoseconds"), "{e}");
    assert!(load(DEFAULT_YAML, &["solver.dt_s=2.5e-4"]).is_ok());
}

/// A file with no keys: every default.
const EMPTY: &str = "friction_node:\n  ros__parameters: {}\n";

#[test]
fn an_unknown_flux_names_the_key_and_the_allowed_values() {
    let e = load(EMPTY, &["solver.flux=muscl"]).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("solver.flux"), "{msg}");
    for allowed in FluxKind::NAMES.split(", ") {
        assert!(msg.contains(allowed), "{allowed} missing from: {msg}");
    }
    let e = load(
        "friction_node:\n  ros__parameters:\n    solver:\n      flux: vanleer\n",
        &[],
    )
    .unwrap_err();
    assert!(e.to_string().contains("solver.flux"), "{e}");
}

#[test]
fn a_muscl_flux_with_the_reference_solver_is_refused_naming_both_keys() {
    let e = load(
        EMPTY,
        &["solver.flux=muscl_van_leer", "solver.method=reference"],
    )
    .unwrap_err();
    assert!(
        matches!(e, ConfigError::InvalidValue { ref key, .. } if key == "solver.flux"),
        "{e}"
    );
    assert!(e.to_string().contains("solver.method: reference"), "{e}");
    // The same refusal from the solver's own settings check.
    let st = SolverSettings {
        method: crate::physics::Method::Reference,
        flux: crate::physics::CouetteFlux::Muscl(crate::physics::Limiter::VanLeer),
        ..Default::default()
    };
    let err = st.check().unwrap_err().to_string();
    assert!(err.contains("solver.flux"), "{err}");
    // Each flux value reaches the solver.
    let c = load(EMPTY, &["solver.flux=muscl_van_albada"]).unwrap();
    assert_eq!(
        c.solver_settings().flux,
        crate::physics::CouetteFlux::Muscl(crate::physics::Limiter::VanAlbada)
    );
}

#[test]
fn an_unset_flux_is_the_best_one_the_method_supports() {
    let c = load(DEFAULT_YAML, &[]).unwrap();
    assert_eq!(c.solver.flux, FluxKind::MusclVanLeer);
    let c = load(DEFAULT_YAML, &["solver.method=reference"]).unwrap();
    assert_eq!(c.solver.flux, FluxKind::Upwind);
    // Set by hand, it is kept (and checked against the method).
    let c = load(DEFAULT_YAML, &["solver.flux=upwind"]).unwrap();
    assert_eq!(c.solver.flux, FluxKind::Upwind);
}

#[test]
fn a_recorded_configuration_without_a_flux_replays_with_the_upwind_flux_it_was_recorded_with() {
    let mut old = Config::default().to_yaml();
    old = old
        .lines()
        .filter(|l| !l.trim_start().starts_with("flux:"))
        .collect::<Vec<_>>()
        .join("\n");
    let origin = Origin::Text("recorded in the bag");
    let c = Config::from_recorded_yaml(&old, &origin, &[]).unwrap();
    assert_eq!(c.solver.flux, FluxKind::Upwind);
    // A recording that names its flux keeps it; overrides still apply.
    let new = Config::default().to_yaml();
    let c = Config::from_recorded_yaml(&new, &origin, &[]).unwrap();
    assert_eq!(c.solver.flux, FluxKind::MusclVanLeer);
    let c =
        Config::from_recorded_yaml(&old, &origin, &["solver.flux=muscl_minmod".into()]).unwrap();
    assert_eq!(c.solver.flux, FluxKind::MusclMinmod);
}

#[test]
fn a_flux_given_as_a_number_a_boolean_or_nothing_lists_the_allowed_values() {
    for v in ["1", "true", ""] {
        let e = Config::load(None, &[format!("solver.flux={v}")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("solver.flux"), "{v}: {e}");
        assert!(
            e.contains("upwind") && e.contains("muscl_van_leer"),
            "{v}: {e}"
        );
        assert!(!e.contains("Tagged"), "{v}: {e}");
    }
}

#[test]
fn nan_and_inf_overrides_are_not_finite_numbers_not_strings() {
    for v in ["nan", "NaN", "inf", "-inf"] {
        let e = Config::load(None, &[format!("contact.load_n={v}")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("contact.load_n"), "{v}: {e}");
        assert!(!e.contains("invalid type"), "{v}: {e}");
        let yaml = Config::load(None, &["contact.load_n=.nan".to_string()])
            .unwrap_err()
            .to_string();
        if v == "nan" {
            assert_eq!(e, yaml, "as YAML's .nan");
        }
    }
}
