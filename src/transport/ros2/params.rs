//! The node's ROS 2 services, on a thread of their own: the parameter
//! services `ros2 param` uses (`list_parameters`, `describe_parameters`,
//! `get_parameters`, `get_parameter_types`, `set_parameters`,
//! `set_parameters_atomically`) and `~/snapshot` (`std_srvs/srv/Trigger`),
//! each in both DDS layouts ([`super::service`]); `/parameter_events`.
//!
//! A set is validated ([`crate::config::parameters`]) and prepared ([`crate::link`]) here and
//! handed to the loop, which applies it between two steps and hands it
//! back stamped with the first step that used it; this thread then
//! publishes the `ParameterEvent` (stamped so) and gives it to the
//! recorder. A refused set changes nothing and says why, naming the key.

use super::service::{DualServer, Request};
use super::{err, TransportError};
use crate::config::parameters::{apply_set, declare, Declared, SetRefusal};
use crate::config::Config;
use crate::link::{ParameterChannel, ParameterIo, ParameterUpdate};
use crate::msgs::ros_interfaces::{
    parameter_type as ty, DescribeParametersResponse, FloatingPointRange,
    GetParameterTypesResponse, GetParametersResponse, IntegerRange, ListParametersRequest,
    ListParametersResponse, ListParametersResult, NamesRequest, ParameterDescriptor,
    ParameterEvent, ParameterValue, SetParametersAtomicallyResponse, SetParametersRequest,
    SetParametersResponse, SetParametersResult, TriggerRequest, TriggerResponse,
};
use crate::transport::Operation;
use crate::transport::RecordQueue;
use ros2_client::dds::rustdds::mio1::{Events, Interest, Poll, Token};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

const SERVICES: [(&str, &str, &str); 6] = [
    ("list_parameters", "rcl_interfaces", "ListParameters"),
    (
        "describe_parameters",
        "rcl_interfaces",
        "DescribeParameters",
    ),
    ("get_parameters", "rcl_interfaces", "GetParameters"),
    ("get_parameter_types", "rcl_interfaces", "GetParameterTypes"),
    ("set_parameters", "rcl_interfaces", "SetParameters"),
    (
        "set_parameters_atomically",
        "rcl_interfaces",
        "SetParametersAtomically",
    ),
];

/// `ListParameters` as rclcpp answers it: the names under any of the
/// prefixes (all when none), at most `depth` levels below (0 = any), and
/// the prefixes of the names returned.
pub fn list(declared: &[Declared], req: &ListParametersRequest) -> ListParametersResult {
    let dots = |s: &str| s.matches('.').count() as u64;
    let mut out = ListParametersResult::default();
    for d in declared {
        let n = &d.name;
        let all = req.prefixes.is_empty() && (req.depth == 0 || dots(n) < req.depth);
        let under = req.prefixes.iter().any(|p| {
            n == p
                || (n.starts_with(p.as_str())
                    && n[p.len()..].starts_with('.')
                    && (req.depth == 0 || dots(&n[p.len() + 1..]) < req.depth))
        });
        if all || under {
            out.names.push(n.clone());
            if let Some((prefix, _)) = n.rsplit_once('.') {
                if !out.prefixes.iter().any(|p| p == prefix) {
                    out.prefixes.push(prefix.to_string());
                }
            }
        }
    }
    out
}

/// The descriptor of a declared parameter.
pub fn describe(d: &Declared) -> ParameterDescriptor {
    let mut constraints = Vec::new();
    let mut p = ParameterDescriptor {
        name: d.name.clone(),
        r#type: d.r#type,
        description: d.description.clone(),
        read_only: d.read_only,
        ..Default::default()
    };
    if let Some(r) = &d.range {
        constraints.push(format!("allowed {r}"));
        match d.r#type {
            ty::DOUBLE => p.floating_point_range.push(FloatingPointRange {
                from_value: r.range.lo.value(),
                to_value: r.range.hi.value(),
                step: 0.0,
            }),
            ty::INTEGER => p.integer_range.push(IntegerRange {
                from_value: r.range.lo.value() as i64,
                to_value: r.range.hi.value() as i64,
                step: 0,
            }),
            _ => {}
        }
    }
    constraints.push(if d.read_only {
        "read-only while running (restart to change)".into()
    } else {
        "applied between two steps while running".into()
    });
    p.additional_constraints = constraints.join("; ");
    p
}

/// The service state: the configuration as changed so far.
pub struct ParamState {
    /// The configuration with every change applied so far.
    pub config: Config,
    /// The declared parameters.
    pub declared: Vec<Declared>,
    /// Where validated changes go to the loop.
    pub channel: Arc<ParameterChannel>,
}

impl ParamState {
    /// The state of a node that serves parameters.
    pub fn new(io: ParameterIo) -> Self {
        Self {
            declared: declare(&io.config),
            config: io.config,
            channel: io.channel,
        }
    }

    fn value(&self, name: &str) -> ParameterValue {
        self.declared
            .iter()
            .find(|d| d.name == name)
            .map_or_else(ParameterValue::default, |d| d.value.clone())
    }

    /// Validate, prepare and submit `changes` as one update.
    fn submit(&mut self, changes: &[(String, ParameterValue)]) -> Result<(), SetRefusal> {
        let new = apply_set(&self.config, &self.declared, changes)?;
        let u = ParameterUpdate::prepare(&self.config, new.clone(), changes.to_vec())
            .map_err(|e| SetRefusal::Invalid(e.to_string()))?;
        self.channel.submit(u)?;
        self.config = new;
        self.declared = declare(&self.config);
        Ok(())
    }

    /// `SetParameters`: each parameter on its own, in order (as rclcpp).
    pub fn set_each(&mut self, req: &SetParametersRequest) -> SetParametersResponse {
        let mut results = Vec::with_capacity(req.parameters.len());
        for p in &req.parameters {
            let r = self.submit(&[(p.name.clone(), p.value.clone())]);
            results.push(result(r));
        }
        SetParametersResponse { results }
    }

    /// `SetParametersAtomically`: all or nothing.
    pub fn set_all(&mut self, req: &SetParametersRequest) -> SetParametersAtomicallyResponse {
        let changes: Vec<(String, ParameterValue)> = req
            .parameters
            .iter()
            .map(|p| (p.name.clone(), p.value.clone()))
            .collect();
        SetParametersAtomicallyResponse {
            result: result(self.submit(&changes)),
        }
    }
}

fn result(r: Result<(), SetRefusal>) -> SetParametersResult {
    match r {
        Ok(()) => SetParametersResult {
            successful: true,
            reason: String::new(),
        },
        Err(e) => {
            tracing::warn!("parameter set refused: {e}");
            SetParametersResult {
                successful: false,
                reason: e.to_string(),
            }
        }
    }
}

/// Everything the thread serves and publishes.
struct Entities {
    servers: Vec<DualServer>,
    snapshot: Option<DualServer>,
    events: ros2_client::dds::rustdds::no_key::DataWriter<
        ParameterEvent,
        ros2_client::dds::rustdds::CDRSerializerAdapter<ParameterEvent>,
    >,
    poll: Poll,
}

/// The node's services thread: runs until `stop`.
pub(super) fn run(
    ctx: ros2_client::Context,
    node_fqn: String,
    io: ParameterIo,
    record: RecordQueue,
    snapshot: Option<Arc<AtomicBool>>,
    stop: Arc<AtomicBool>,
    ready: std::sync::mpsc::Sender<Result<(), TransportError>>,
) {
    let mut e = match setup(&ctx, &node_fqn, snapshot.is_some()) {
        Ok(e) => e,
        Err(x) => {
            let _ = ready.send(Err(x));
            return;
        }
    };
    let _ = ready.send(Ok(()));
    let mut state = ParamState::new(io);
    let mut events = Events::with_capacity(16);
    while !stop.load(Ordering::Acquire) {
        let _ = e.poll.poll(&mut events, Some(Duration::from_millis(5)));
        serve(&mut e, &mut state, snapshot.as_deref());
        while let Some(u) = state.channel.take_applied() {
            if let Err(x) = e.events.write(event(&node_fqn, &u), None) {
                tracing::warn!("/parameter_events: {x:?}");
            }
            if let Some(q) = &record {
                if let Err(x) = record_applied(q, &node_fqn, &u, crate::clock::system_wall_ns()) {
                    tracing::warn!("recording a parameter event: {x}");
                }
            }
            tracing::info!(
                "parameters applied from the step stamped {} ns: {}",
                u.applied_stamp_ns,
                u.changed
                    .iter()
                    .map(|(n, v)| format!("{n}={}", v.to_yaml().unwrap_or_default()))
                    .collect::<Vec<_>>()
                    .join(", ")
            );
            // The update (and the old model it holds) is freed here, off
            // the loop.
            drop(u);
        }
    }
}

fn setup(
    ctx: &ros2_client::Context,
    node_fqn: &str,
    snapshots: bool,
) -> Result<Entities, TransportError> {
    let dp = ctx.domain_participant();
    let qos = super::service::service_qos();
    let publisher = dp
        .create_publisher(&qos)
        .map_err(|e| err(Operation::Open, "create the services' DDS publisher", e))?;
    let subscriber = dp
        .create_subscriber(&qos)
        .map_err(|e| err(Operation::Open, "create the services' DDS subscriber", e))?;
    let poll = Poll::new().map_err(|e| err(Operation::Open, "create a poll", e))?;
    let mut servers = Vec::new();
    for (k, (name, pkg, ty)) in SERVICES.iter().enumerate() {
        let mut s = DualServer::new(
            &dp,
            &publisher,
            &subscriber,
            &format!("{node_fqn}/{name}"),
            pkg,
            ty,
        )?;
        poll.registry()
            .register(s.reader_mut(), Token(k), Interest::READABLE)
            .map_err(|e| err(Operation::Open, format!("register {name}"), e))?;
        servers.push(s);
    }
    let snapshot = if snapshots {
        let mut s = DualServer::new(
            &dp,
            &publisher,
            &subscriber,
            &format!("{node_fqn}/snapshot"),
            "std_srvs",
            "Trigger",
        )?;
        poll.registry()
            .register(s.reader_mut(), Token(100), Interest::READABLE)
            .map_err(|e| err(Operation::Open, "register ~/snapshot", e))?;
        Some(s)
    } else {
        None
    };
    // /parameter_events: reliable, volatile, keep last 1000 (rcl's
    // parameter events QoS).
    let events_qos = {
        use ros2_client::dds::rustdds::policy::{Durability, History, Reliability};
        ros2_client::dds::rustdds::QosPolicyBuilder::new()
            .reliability(Reliability::Reliable {
                max_blocking_time: ros2_client::dds::rustdds::Duration::from_millis(10),
            })
            .durability(Durability::Volatile)
            .history(History::KeepLast { depth: 1000 })
            .build()
    };
    let topic = dp
        .create_topic(
            "rt/parameter_events".into(),
            "rcl_interfaces::msg::dds_::ParameterEvent_".into(),
            &events_qos,
            ros2_client::dds::rustdds::TopicKind::NoKey,
        )
        .map_err(|e| err(Operation::Open, "create /parameter_events", e))?;
    let events = publisher
        .create_datawriter_no_key_cdr::<ParameterEvent>(&topic, Some(events_qos))
        .map_err(|e| err(Operation::Open, "advertise /parameter_events", e))?;
    Ok(Entities {
        servers,
        snapshot,
        events,
        poll,
    })
}

fn reply<T, R: serde::Serialize>(s: &mut DualServer, req: &Request<T>, r: &R) {
    if let Err(e) = s.reply(req, r) {
        tracing::warn!("{}: the reply could not be sent: {e}", s.name);
    }
}

fn serve(e: &mut Entities, state: &mut ParamState, snapshot: Option<&AtomicBool>) {
    for s in e.servers.iter_mut().chain(e.snapshot.as_mut()) {
        s.flush();
    }
    let [list_s, describe_s, get_s, types_s, set_s, atomic_s] = &mut e.servers[..] else {
        return;
    };
    while let Some(r) = list_s.take::<ListParametersRequest>() {
        let resp = ListParametersResponse {
            result: list(&state.declared, &r.body),
        };
        reply(list_s, &r, &resp);
    }
    while let Some(r) = describe_s.take::<NamesRequest>() {
        let descriptors = r
            .body
            .names
            .iter()
            .map(|n| {
                state.declared.iter().find(|d| d.name == *n).map_or_else(
                    || ParameterDescriptor {
                        name: n.clone(),
                        ..Default::default()
                    },
                    describe,
                )
            })
            .collect();
        reply(describe_s, &r, &DescribeParametersResponse { descriptors });
    }
    while let Some(r) = get_s.take::<NamesRequest>() {
        let values = r.body.names.iter().map(|n| state.value(n)).collect();
        reply(get_s, &r, &GetParametersResponse { values });
    }
    while let Some(r) = types_s.take::<NamesRequest>() {
        let types = r.body.names.iter().map(|n| state.value(n).r#type).collect();
        reply(types_s, &r, &GetParameterTypesResponse { types });
    }
    while let Some(r) = set_s.take::<SetParametersRequest>() {
        let resp = state.set_each(&r.body);
        reply(set_s, &r, &resp);
    }
    while let Some(r) = atomic_s.take::<SetParametersRequest>() {
        let resp = state.set_all(&r.body);
        reply(atomic_s, &r, &resp);
    }
    if let (Some(s), Some(flag)) = (e.snapshot.as_mut(), snapshot) {
        while let Some(r) = s.take::<TriggerRequest>() {
            flag.store(true, Ordering::Release);
            tracing::info!("snapshot requested through ~/snapshot");
            reply(
                s,
                &r,
                &TriggerResponse {
                    success: true,
                    message: "snapshot requested: its file name and time span go to the log and the loop statistics".into(),
                },
            );
        }
    }
}

/// The `rcl_interfaces/msg/ParameterEvent` of an applied update, stamped
/// with the first step that used it.
pub fn event(node_fqn: &str, u: &ParameterUpdate) -> crate::msgs::ros_interfaces::ParameterEvent {
    use crate::msgs::ros_interfaces::{Parameter, ParameterEvent};
    ParameterEvent {
        stamp: crate::msgs::Time::from_ns(u.applied_stamp_ns),
        node: node_fqn.to_string(),
        changed_parameters: u
            .changed
            .iter()
            .map(|(name, value)| Parameter {
                name: name.clone(),
                value: value.clone(),
            })
            .collect(),
        ..Default::default()
    }
}

/// Hand an applied update's event to the recorder (replay re-applies it at
/// the same step); `logged_ns` is the wall time now.
pub fn record_applied(
    queue: &crossbeam_queue::ArrayQueue<crate::link::RecordItem>,
    node_fqn: &str,
    u: &ParameterUpdate,
    logged_ns: u64,
) -> Result<(), String> {
    let cdr = crate::msgs::to_cdr(&event(node_fqn, u)).map_err(|e| e.to_string())?;
    queue
        .push(crate::link::RecordItem::ParameterEvent {
            cdr,
            stamp_ns: u.applied_stamp_ns,
            logged_ns,
        })
        .map_err(|_| "the recorder queue is full".to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn list_parameters_answers_prefixes_and_depth_as_rclcpp() {
        let d = declare(&Config::default());
        let all = list(&d, &ListParametersRequest::default());
        assert_eq!(all.names.len(), d.len());
        assert!(all.prefixes.contains(&"contact".to_string()));
        assert!(all.prefixes.contains(&"solver.reference".to_string()));
        let contact = list(
            &d,
            &ListParametersRequest {
                prefixes: vec!["contact".into()],
                depth: 0,
            },
        );
        assert!(contact.names.iter().all(|n| n.starts_with("contact.")));
        assert!(contact.names.contains(&"contact.load_n".to_string()));
        let shallow = list(
            &d,
            &ListParametersRequest {
                prefixes: vec!["solver".into()],
                depth: 1,
            },
        );
        assert!(shallow.names.contains(&"solver.cells".to_string()));
        assert!(!shallow
            .names
            .iter()
            .any(|n| n.starts_with("solver.reference.")));
        let top = list(
            &d,
            &ListParametersRequest {
                prefixes: vec![],
                depth: 1,
            },
        );
        assert_eq!(top.names, vec!["use_sim_time".to_string()]);
    }

    #[test]
    fn descriptors_carry_the_range_and_whether_the_key_can_change_while_running() {
        let d = declare(&Config::default());
        let load = describe(d.iter().find(|p| p.name == "contact.load_n").unwrap());
        assert_eq!(load.floating_point_range.len(), 1);
        assert_eq!(load.floating_point_range[0].to_value, 1e9);
        assert!(!load.read_only);
        assert!(load.additional_constraints.contains("(0, 1e9]"));
        let cells = describe(d.iter().find(|p| p.name == "solver.cells").unwrap());
        assert!(cells.read_only);
        assert_eq!(cells.integer_range[0].from_value, 8);
    }
}
