//! Command samples taken off DDS as raw CDR bytes: decoded here and
//! recorded unchanged.
//!
//! ros2-client's subscriptions hand out deserialized messages only; a
//! RustDDS reader with this adapter hands out the serialized payload and its
//! representation identifier, from which the 4-byte encapsulation header is
//! rebuilt (its two option bytes are zero, as rmw writes them).

use ros2_client::dds::rustdds::no_key::{Decode, DefaultDecoder, DeserializerAdapter};
use ros2_client::dds::rustdds::RepresentationIdentifier;

/// A serialized sample: encapsulation header plus CDR payload.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RawCdr(pub Vec<u8>);

/// The adapter of a raw reader.
pub struct RawAdapter;

/// Decoding never fails: the bytes are kept as they are.
#[derive(Debug, Clone, Copy)]
pub struct RawDecoder;

/// Never constructed (raw decoding cannot fail).
#[derive(Debug)]
pub struct NoError;

impl std::fmt::Display for NoError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("no error")
    }
}

impl std::error::Error for NoError {}

impl<'de> Decode<'de, RawCdr> for RawDecoder {
    type Error = NoError;

    fn decode_bytes(
        self,
        input_bytes: &'de [u8],
        encoding: RepresentationIdentifier,
    ) -> Result<RawCdr, NoError> {
        let mut bytes = Vec::with_capacity(input_bytes.len() + 4);
        bytes.extend_from_slice(&encoding.to_bytes());
        bytes.extend_from_slice(&[0, 0]);
        bytes.extend_from_slice(input_bytes);
        Ok(RawCdr(bytes))
    }
}

impl DeserializerAdapter<RawCdr> for RawAdapter {
    type Error = NoError;
    type Decoded = RawCdr;

    fn supported_encodings() -> &'static [RepresentationIdentifier] {
        &[
            RepresentationIdentifier::CDR_LE,
            RepresentationIdentifier::CDR_BE,
        ]
    }

    fn transform_decoded(decoded: RawCdr) -> RawCdr {
        decoded
    }
}

impl DefaultDecoder<RawCdr> for RawAdapter {
    type Decoder = RawDecoder;
    const DECODER: RawDecoder = RawDecoder;
}
