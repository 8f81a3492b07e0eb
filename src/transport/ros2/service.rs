//! A ROS 2 service served in both DDS layouts that ROS 2 uses.
//!
//! | layout | used by | request payload | reply payload |
//! |---|---|---|---|
//! | enhanced | rmw_fastrtps (the default RMW), ros2-client's default | the request | the reply, its request's identity in the `related_sample_identity` inline QoS |
//! | cyclone | rmw_cyclonedds | a 16-byte header (the lower half of the client's GUID, the sequence number) then the request | the same header echoed, then the reply |
//!
//! Both kinds of client send on the same DDS request topic, so one reader
//! sees every request; it tells the layout of each from the bytes: a
//! request is decoded both ways and a decoding counts only if it uses the
//! whole payload. When exactly one does, that is the layout; when both do,
//! a Cyclone header that names a sequence number (high word 0, low word
//! non-zero, or equal to the inline `related_sample_identity` a
//! ros2-client Cyclone client also sends) makes it Cyclone. A request that
//! decodes neither way gets no reply (it is counted). Every request gets
//! exactly one reply, in its own layout.
//!
//! A reply written before this side has matched the client's reply reader
//! would be lost (the writer is volatile, and discovery is not symmetric in
//! time): as rmw_fastrtps does, a reply waits (in this thread, not the
//! loop) until a reader of the client's participant is matched, at most
//! [`MATCH_WAIT`].

use super::raw::{RawAdapter, RawCdr};
use super::{err, TransportError};
use crate::transport::Operation;
use ros2_client::dds::rustdds::{
    self,
    bytes::Bytes,
    no_key::{DataWriter, SimpleDataReader},
    DomainParticipant, Publisher, QosPolicies, RepresentationIdentifier, SampleIdentity,
    SequenceNumber, Subscriber, TopicKind, WriteOptionsBuilder, GUID,
};
use serde::de::DeserializeOwned;
use serde::Serialize;
use std::time::{Duration, Instant};

/// How long a reply waits for the client's reply reader to be matched.
pub const MATCH_WAIT: Duration = Duration::from_secs(3);

/// A reply payload (CDR without the encapsulation header, which RustDDS
/// writes).
#[derive(Debug, Clone)]
pub struct RawPayload(pub Vec<u8>);

/// Writes [`RawPayload`]s as little-endian CDR.
pub struct RawPayloadAdapter;

impl rustdds::no_key::SerializerAdapter<RawPayload> for RawPayloadAdapter {
    type Error = std::io::Error;
    fn output_encoding() -> RepresentationIdentifier {
        RepresentationIdentifier::CDR_LE
    }
    fn to_bytes(value: &RawPayload) -> Result<Bytes, std::io::Error> {
        Ok(Bytes::copy_from_slice(&value.0))
    }
}

/// The DDS layout of one request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// The enhanced RPC layout (Fast DDS, ros2-client).
    Enhanced,
    /// Cyclone DDS's: a 16-byte header before the body.
    Cyclone,
}

/// A decoded request and what its reply needs.
#[derive(Debug, Clone)]
pub struct Request<T> {
    /// How the request was laid out.
    pub layout: Layout,
    /// The decoded request.
    pub body: T,
    /// The identity the reply's inline QoS carries.
    identity: SampleIdentity,
    /// Cyclone: the header to echo.
    header: [u8; 16],
    /// The requesting participant (its GUID prefix).
    sender: [u8; 12],
}

/// Decode `payload` (CDR, little endian unless `big`) as `T`, only if the
/// decoding uses all of it (up to 7 bytes of alignment padding).
fn decode_all<T: DeserializeOwned>(payload: &[u8], big: bool) -> Option<T> {
    let r = if big {
        cdr_encoding::from_bytes::<T, byteorder::BigEndian>(payload)
    } else {
        cdr_encoding::from_bytes::<T, byteorder::LittleEndian>(payload)
    };
    match r {
        Ok((v, used)) if payload.len().saturating_sub(used) < 8 => Some(v),
        _ => None,
    }
}

/// How a request's bytes were read.
#[derive(Debug, Clone, PartialEq)]
pub enum Classified<T> {
    /// The enhanced layout's body.
    Enhanced(T),
    /// Cyclone's layout.
    Cyclone {
        /// The header to echo in the reply.
        header: [u8; 16],
        /// The body.
        body: T,
    },
    /// Neither layout decodes.
    Undecodable,
}

/// Tell the layout of a request from its CDR bytes (encapsulation header
/// included) and the inline `related_sample_identity` sequence number, if
/// any.
pub fn classify<T: DeserializeOwned>(cdr: &[u8], related_seq: Option<i64>) -> Classified<T> {
    if cdr.len() < 4 {
        return Classified::Undecodable;
    }
    let big = cdr[1] == 0x00;
    let payload = &cdr[4..];
    let enhanced = decode_all::<T>(payload, big);
    let cyclone = (payload.len() >= 16)
        .then(|| decode_all::<T>(&payload[16..], big))
        .flatten()
        .map(|body| {
            let mut header = [0u8; 16];
            header.copy_from_slice(&payload[..16]);
            (header, body)
        });
    let word = |b: &[u8]| -> u32 {
        let a = [b[0], b[1], b[2], b[3]];
        if big {
            u32::from_be_bytes(a)
        } else {
            u32::from_le_bytes(a)
        }
    };
    match (enhanced, cyclone) {
        (Some(body), None) => Classified::Enhanced(body),
        (None, Some((header, body))) => Classified::Cyclone { header, body },
        (Some(e), Some((header, body))) => {
            let (high, low) = (word(&header[8..12]), word(&header[12..16]));
            let seq = (i64::from(high as i32) << 32) | i64::from(low);
            let names_a_sequence =
                related_seq == Some(seq) || (related_seq.is_none() && high == 0 && low != 0);
            if names_a_sequence {
                Classified::Cyclone { header, body }
            } else {
                Classified::Enhanced(e)
            }
        }
        (None, None) => Classified::Undecodable,
    }
}

/// One service: its request reader and reply writer.
pub struct DualServer {
    /// The service's name.
    pub name: String,
    reader: SimpleDataReader<RawCdr, RawAdapter>,
    writer: DataWriter<RawPayload, RawPayloadAdapter>,
    /// Requests that decoded neither way.
    pub undecodable: u64,
    /// Reply readers matched by the reply writer.
    matched: Vec<GUID>,
    /// Replies waiting for their client's reader: (requesting participant,
    /// identity, payload, give up at).
    waiting: Vec<([u8; 12], SampleIdentity, Vec<u8>, Instant)>,
}

/// The QoS rcl gives services: reliable, volatile, keep last 10.
pub fn service_qos() -> QosPolicies {
    use rustdds::policy::{Durability, History, Reliability};
    rustdds::QosPolicyBuilder::new()
        .reliability(Reliability::Reliable {
            max_blocking_time: rustdds::Duration::from_millis(100),
        })
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 10 })
        .build()
}

/// A request in Cyclone DDS's layout: the client's GUID has its upper half
/// from the writer and its lower half from the header (as rmw_cyclonedds
/// splits it), the sequence number the header's last 8 bytes in the
/// message's byte order; the header is echoed little-endian (the reply's
/// encoding).
fn cyclone_request<T>(
    body: T,
    header: [u8; 16],
    big: bool,
    writer_guid: GUID,
    sender: [u8; 12],
) -> Request<T> {
    let mut g = writer_guid.to_bytes();
    g[8..16].copy_from_slice(&header[..8]);
    let word = |b: &[u8]| {
        let a = [b[0], b[1], b[2], b[3]];
        if big {
            u32::from_be_bytes(a)
        } else {
            u32::from_le_bytes(a)
        }
    };
    let (high, low) = (word(&header[8..12]), word(&header[12..16]));
    let seq = SequenceNumber::from_high_low(high as i32, low);
    let mut echoed = header;
    if big {
        echoed[8..12].copy_from_slice(&high.to_le_bytes());
        echoed[12..16].copy_from_slice(&low.to_le_bytes());
    }
    Request {
        layout: Layout::Cyclone,
        body,
        identity: SampleIdentity {
            writer_guid: GUID::from_bytes(g),
            sequence_number: seq,
        },
        header: echoed,
        sender,
    }
}

impl DualServer {
    /// Serve `service` (fully qualified, e.g. `/friction_node/list_parameters`)
    /// of type `package/srv/Type`.
    pub fn new(
        participant: &DomainParticipant,
        publisher: &Publisher,
        subscriber: &Subscriber,
        service: &str,
        package: &str,
        type_name: &str,
    ) -> Result<Self, TransportError> {
        let qos = service_qos();
        let base = service.trim_start_matches('/');
        let rq = participant
            .create_topic(
                format!("rq/{base}Request"),
                format!("{package}::srv::dds_::{type_name}_Request_"),
                &qos,
                TopicKind::NoKey,
            )
            .map_err(|e| {
                err(
                    Operation::Open,
                    format!("create the request topic of {service}"),
                    e,
                )
            })?;
        let rr = participant
            .create_topic(
                format!("rr/{base}Reply"),
                format!("{package}::srv::dds_::{type_name}_Response_"),
                &qos,
                TopicKind::NoKey,
            )
            .map_err(|e| {
                err(
                    Operation::Open,
                    format!("create the reply topic of {service}"),
                    e,
                )
            })?;
        let reader = subscriber
            .create_simple_datareader_no_key::<RawCdr, RawAdapter>(&rq, Some(qos.clone()))
            .map_err(|e| err(Operation::Open, format!("serve {service}"), e))?;
        let writer = publisher
            .create_datawriter_no_key::<RawPayload, RawPayloadAdapter>(&rr, Some(qos))
            .map_err(|e| err(Operation::Open, format!("reply on {service}"), e))?;
        Ok(Self {
            name: service.to_string(),
            reader,
            writer,
            undecodable: 0,
            matched: Vec::new(),
            waiting: Vec::new(),
        })
    }

    /// The reader, to register with a poll.
    pub fn reader_mut(&mut self) -> &mut SimpleDataReader<RawCdr, RawAdapter> {
        &mut self.reader
    }

    /// The next request, decoded in its layout (undecodable ones are
    /// skipped and counted).
    pub fn take<T: DeserializeOwned>(&mut self) -> Option<Request<T>> {
        self.reader.drain_read_notifications();
        loop {
            let dcc = match self.reader.try_take_one() {
                Ok(Some(d)) => d,
                Ok(None) => return None,
                Err(e) => {
                    tracing::debug!("{}: taking a request failed: {e:?}", self.name);
                    return None;
                }
            };
            let related = dcc.write_options.related_sample_identity();
            let writer_guid = dcc.writer_guid;
            let mut sender = [0u8; 12];
            sender.copy_from_slice(&writer_guid.to_bytes()[..12]);
            let sample_seq = dcc.sequence_number;
            let RawCdr(cdr) = dcc.sample;
            match classify::<T>(&cdr, related.map(|r| i64::from(r.sequence_number))) {
                Classified::Enhanced(body) => {
                    // As rmw_fastrtps: the related identity when given (an
                    // unknown sequence number replaced by the sample's),
                    // else the sample's own identity.
                    let mut identity = related.unwrap_or(SampleIdentity {
                        writer_guid,
                        sequence_number: sample_seq,
                    });
                    if identity.sequence_number == SequenceNumber::UNKNOWN {
                        identity.sequence_number = sample_seq;
                    }
                    return Some(Request {
                        layout: Layout::Enhanced,
                        body,
                        identity,
                        header: [0; 16],
                        sender,
                    });
                }
                Classified::Cyclone { header, body } => {
                    let big = cdr.get(1) == Some(&0);
                    return Some(cyclone_request(body, header, big, writer_guid, sender));
                }
                Classified::Undecodable => {
                    self.undecodable += 1;
                    tracing::warn!(
                        "{}: a request decodes in neither DDS layout ({} bytes); no reply",
                        self.name,
                        cdr.len()
                    );
                }
            }
        }
    }

    /// Reply to `req` in its layout: now if the client's reply reader is
    /// matched, else when it is (see [`DualServer::flush`]).
    pub fn reply<T, R: Serialize>(&mut self, req: &Request<T>, reply: &R) -> Result<(), String> {
        let body =
            cdr_encoding::to_vec::<R, byteorder::LittleEndian>(reply).map_err(|e| e.to_string())?;
        let payload = match req.layout {
            Layout::Enhanced => body,
            Layout::Cyclone => {
                let mut p = req.header.to_vec();
                p.extend_from_slice(&body);
                p
            }
        };
        self.waiting.push((
            req.sender,
            req.identity,
            payload,
            Instant::now() + MATCH_WAIT,
        ));
        self.flush();
        Ok(())
    }

    /// Follow the reply writer's matches and send the replies whose client
    /// is matched (or that waited [`MATCH_WAIT`]).
    pub fn flush(&mut self) {
        use rustdds::{DataWriterStatus, StatusEvented};
        while let Some(st) = self.writer.try_recv_status() {
            if let DataWriterStatus::PublicationMatched {
                current, reader, ..
            } = st
            {
                if current.count_change() > 0 {
                    self.matched.push(reader);
                } else if current.count_change() < 0 {
                    self.matched.retain(|g| *g != reader);
                }
            }
        }
        if self.waiting.is_empty() {
            return;
        }
        let now = Instant::now();
        let matched = &self.matched;
        let ready = |sender: &[u8; 12]| matched.iter().any(|g| g.to_bytes()[..12] == sender[..]);
        let mut k = 0;
        while k < self.waiting.len() {
            let (sender, _, _, give_up) = &self.waiting[k];
            if ready(sender) || now >= *give_up {
                let (_, identity, payload, give_up) = self.waiting.remove(k);
                if now >= give_up {
                    tracing::warn!(
                        "{}: the client's reply reader is not matched after {MATCH_WAIT:?}; replying anyway",
                        self.name
                    );
                }
                let options = WriteOptionsBuilder::new()
                    .source_timestamp(rustdds::Timestamp::now())
                    .related_sample_identity(identity)
                    .build();
                if let Err(e) = self.writer.write_with_options(RawPayload(payload), options) {
                    tracing::warn!("{}: the reply could not be sent: {e:?}", self.name);
                }
            } else {
                k += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::msgs::ros_interfaces::{ListParametersRequest, NamesRequest};

    fn enc<T: Serialize>(header: Option<[u8; 16]>, v: &T) -> Vec<u8> {
        let mut out = vec![0x00, 0x01, 0x00, 0x00];
        if let Some(h) = header {
            out.extend_from_slice(&h);
        }
        out.extend(cdr_encoding::to_vec::<T, byteorder::LittleEndian>(v).unwrap());
        out
    }

    fn cyclone_header(seq: u32) -> [u8; 16] {
        let mut h = [0u8; 16];
        h[..8].copy_from_slice(&[0x11, 0x22, 0x33, 0x44, 0x00, 0x00, 0x12, 0x04]);
        h[12..16].copy_from_slice(&seq.to_le_bytes());
        h
    }

    #[test]
    fn each_layout_of_every_request_shape_is_told_apart() {
        let list = ListParametersRequest {
            prefixes: vec![],
            depth: 0,
        };
        let names = NamesRequest {
            names: vec!["contact.load_n".into(), "solver.cells".into()],
        };
        let empty = NamesRequest { names: vec![] };
        let one_empty = NamesRequest {
            names: vec![String::new()],
        };
        macro_rules! both {
            ($v:expr, $t:ty) => {{
                assert_eq!(
                    classify::<$t>(&enc(None, &$v), None),
                    Classified::Enhanced($v.clone()),
                    "enhanced {:?}",
                    $v
                );
                for related in [None, Some(7)] {
                    assert_eq!(
                        classify::<$t>(&enc(Some(cyclone_header(7)), &$v), related),
                        Classified::Cyclone {
                            header: cyclone_header(7),
                            body: $v.clone()
                        },
                        "cyclone {:?} (related {related:?})",
                        $v
                    );
                }
            }};
        }
        both!(list, ListParametersRequest);
        both!(names, NamesRequest);
        both!(empty, NamesRequest);
        both!(one_empty, NamesRequest);
        assert_eq!(
            classify::<NamesRequest>(&[0, 1, 0, 0, 0xff, 0xff, 0xff, 0x7f], None),
            Classified::Undecodable
        );
    }
}
