//! CDR encoding with the 4-byte encapsulation header.

use serde::Serialize;

/// Encode a message as CDR with the 4-byte encapsulation header (little endian).
pub fn to_cdr<T: Serialize>(m: &T) -> Result<Vec<u8>, String> {
    let mut out = vec![0x00, 0x01, 0x00, 0x00];
    let body =
        cdr_encoding::to_vec::<T, byteorder_le::LittleEndian>(m).map_err(|e| e.to_string())?;
    out.extend_from_slice(&body);
    Ok(out)
}

/// Decode a CDR message (with its encapsulation header).
pub fn from_cdr<T: serde::de::DeserializeOwned>(bytes: &[u8]) -> Result<T, String> {
    if bytes.len() < 4 {
        return Err(format!(
            "{} bytes is too short for a CDR message",
            bytes.len()
        ));
    }
    let body = &bytes[4..];
    match bytes[1] {
        0x01 => cdr_encoding::from_bytes::<T, byteorder_le::LittleEndian>(body)
            .map(|(v, _)| v)
            .map_err(|e| e.to_string()),
        0x00 => cdr_encoding::from_bytes::<T, byteorder_le::BigEndian>(body)
            .map(|(v, _)| v)
            .map_err(|e| e.to_string()),
        other => Err(format!(
            "unsupported CDR encapsulation 0x{:02x}{other:02x}",
            bytes[0]
        )),
    }
}

mod byteorder_le {
    pub use byteorder::{BigEndian, LittleEndian};
}
