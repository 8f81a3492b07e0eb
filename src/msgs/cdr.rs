//! CDR encoding with the 4-byte encapsulation header.

use serde::Serialize;

/// What went wrong coding a message to or from CDR.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum CdrError {
    /// Fewer bytes than the encapsulation header.
    #[error("{len} bytes is too short for a CDR message")]
    TooShort {
        /// The message's length, bytes.
        len: usize,
    },
    /// An encapsulation other than plain CDR, little or big endian.
    #[error("unsupported CDR encapsulation 0x{:02x}{:02x}", .header[0], .header[1])]
    Encapsulation {
        /// The header's first two bytes.
        header: [u8; 2],
    },
    /// The body does not decode as the type asked for.
    #[error("{message}")]
    Body {
        /// The decoder's message.
        message: String,
    },
    /// The value does not encode (a sequence too long for CDR, …).
    #[error("cannot encode: {message}")]
    Encode {
        /// The encoder's message.
        message: String,
    },
    /// A joint's velocity asked for without the joint's name (it is read
    /// by name from a JointState of several joints).
    #[error("a joint's velocity is read by its joint's name from a JointState")]
    JointByName,
}

/// Encode a message as CDR with the 4-byte encapsulation header (little endian).
pub fn to_cdr<T: Serialize>(m: &T) -> Result<Vec<u8>, CdrError> {
    let mut out = vec![0x00, 0x01, 0x00, 0x00];
    let body =
        cdr_encoding::to_vec::<T, byteorder_le::LittleEndian>(m).map_err(|e| CdrError::Encode {
            message: e.to_string(),
        })?;
    out.extend_from_slice(&body);
    Ok(out)
}

/// Decode a CDR message (with its encapsulation header).
pub fn from_cdr<T: serde::de::DeserializeOwned>(bytes: &[u8]) -> Result<T, CdrError> {
    if bytes.len() < 4 {
        return Err(CdrError::TooShort { len: bytes.len() });
    }
    let body = &bytes[4..];
    let body_error = |e: cdr_encoding::Error| CdrError::Body {
        message: e.to_string(),
    };
    match bytes[1] {
        0x01 => cdr_encoding::from_bytes::<T, byteorder_le::LittleEndian>(body)
            .map(|(v, _)| v)
            .map_err(body_error),
        0x00 => cdr_encoding::from_bytes::<T, byteorder_le::BigEndian>(body)
            .map(|(v, _)| v)
            .map_err(body_error),
        _ => Err(CdrError::Encapsulation {
            header: [bytes[0], bytes[1]],
        }),
    }
}

mod byteorder_le {
    pub(super) use byteorder::{BigEndian, LittleEndian};
}
