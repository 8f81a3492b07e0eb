//! Logging for the binary: `tracing` events to the terminal (stderr), at
//! the level `RUST_LOG` or `--ros-args --log-level` gives (default: the
//! node's own lines from info up, other crates' from warn; RustDDS's
//! teardown chatter is silenced), in colour only on a terminal without
//! `NO_COLOR`. The ROS 2 transport also sends
//! them to `/rosout` (see `friction_node::transport::ros2::rosout`).

use friction_node::config::RosArgs;
use tracing_subscriber::layer::SubscriberExt;
use tracing_subscriber::util::SubscriberInitExt;
use tracing_subscriber::EnvFilter;

/// rcl's level names to `tracing` filter directives.
fn directive(level: &str) -> &'static str {
    match level {
        "debug" => "debug",
        "info" => "info",
        "warn" | "warning" => "warn",
        "error" | "fatal" => "error",
        _ => "warn",
    }
}

pub fn init(ros: Option<&RosArgs>) {
    let quiet = ",rustdds=off,ros2_client=error";
    let filter = match ros.and_then(|r| r.log_level.as_deref()) {
        Some(level) => EnvFilter::new(format!("{}{quiet}", directive(level))),
        None => EnvFilter::try_from_default_env()
            // The node's own lines from info up (a few: start, splits,
            // parameter changes); RustDDS logs harmless chatter at
            // participant teardown (RUST_LOG=rustdds=warn shows it).
            .unwrap_or_else(|_| EnvFilter::new(format!("warn,friction_node=info{quiet}"))),
    };
    let stdout = !ros.is_some_and(|r| r.stdout_disabled);
    // Colour only on a terminal, and never with NO_COLOR set (no-color.org):
    // a redirected log holds plain text.
    let colour = std::io::IsTerminal::is_terminal(&std::io::stderr())
        && std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty());
    let terminal = stdout.then(|| {
        tracing_subscriber::fmt::layer()
            .with_writer(std::io::stderr)
            .with_ansi(colour)
    });
    let rosout_enabled = !ros.is_some_and(|r| r.rosout_disabled);
    #[cfg(feature = "ros2")]
    let rosout = friction_node::transport::ros2::rosout::layer(rosout_enabled);
    #[cfg(not(feature = "ros2"))]
    let rosout = {
        let _ = rosout_enabled; // no ROS 2 transport: nothing publishes /rosout
        tracing_subscriber::layer::Identity::new()
    };
    tracing_subscriber::registry()
        .with(filter)
        .with(terminal)
        .with(rosout)
        .init();
}
