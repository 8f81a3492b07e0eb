//! A structural check of an MCAP file before the `mcap` reader sees it.
//!
//! The reader trusts declared lengths: a damaged or hostile record length,
//! string length or chunk size can make it overflow an offset, reserve an
//! absurd buffer (seen: 3.9 GB for one metadata string) or abort. This walk
//! checks every top-level record and every record inside every chunk
//! (decompressed here, bounded by [`MAX_CHUNK_BYTES`]): each record fits in
//! its container, each string, byte array and map fits in its record. It
//! returns the readable prefix: everything before the first record that
//! does not pass.

/// The largest uncompressed chunk accepted, bytes (recorders use 256 kB to
/// a few MB; a chunk is decompressed into memory at once).
pub const MAX_CHUNK_BYTES: u64 = 1 << 30;

const OP_HEADER: u8 = 0x01;
const OP_FOOTER: u8 = 0x02;
const OP_SCHEMA: u8 = 0x03;
const OP_CHANNEL: u8 = 0x04;
const OP_MESSAGE: u8 = 0x05;
const OP_CHUNK: u8 = 0x06;
const OP_MESSAGE_INDEX: u8 = 0x07;
const OP_CHUNK_INDEX: u8 = 0x08;
const OP_ATTACHMENT: u8 = 0x09;
const OP_ATTACHMENT_INDEX: u8 = 0x0A;
const OP_STATISTICS: u8 = 0x0B;
const OP_METADATA: u8 = 0x0C;
const OP_METADATA_INDEX: u8 = 0x0D;

/// A bounds-checked little-endian cursor over one record's body.
struct Cursor<'a> {
    b: &'a [u8],
    at: usize,
}

type Check = Result<(), String>;

impl<'a> Cursor<'a> {
    fn new(b: &'a [u8]) -> Self {
        Self { b, at: 0 }
    }

    fn take(&mut self, n: u64, what: &str) -> Result<&'a [u8], String> {
        let left = (self.b.len() - self.at) as u64;
        if n > left {
            return Err(format!("{what} declares {n} bytes, {left} are left"));
        }
        let s = &self.b[self.at..self.at + n as usize];
        self.at += n as usize;
        Ok(s)
    }

    fn skip(&mut self, n: u64, what: &str) -> Check {
        self.take(n, what).map(|_| ())
    }

    fn u32(&mut self, what: &str) -> Result<u32, String> {
        let s = self.take(4, what)?;
        Ok(u32::from_le_bytes(s.try_into().expect("4 bytes")))
    }

    fn u64(&mut self, what: &str) -> Result<u64, String> {
        let s = self.take(8, what)?;
        Ok(u64::from_le_bytes(s.try_into().expect("8 bytes")))
    }

    /// A string or byte array with a u32 length prefix.
    fn prefixed32(&mut self, what: &str) -> Result<&'a [u8], String> {
        let n = self.u32(what)?;
        self.take(u64::from(n), what)
    }

    /// A map: u32 byte length, then its entries, which must fill it.
    fn map(&mut self, what: &str, entry: impl Fn(&mut Cursor<'a>) -> Check) -> Check {
        let body = self.prefixed32(what)?;
        let mut c = Cursor::new(body);
        while c.at < body.len() {
            entry(&mut c)?;
        }
        Ok(())
    }

    fn string_map(&mut self, what: &str) -> Check {
        self.map(what, |c| {
            c.prefixed32("a map key")?;
            c.prefixed32("a map value").map(|_| ())
        })
    }
}

/// Check one record's body against its opcode's layout.
fn check_record(op: u8, body: &[u8]) -> Check {
    let mut c = Cursor::new(body);
    match op {
        OP_HEADER => {
            c.prefixed32("the profile")?;
            c.prefixed32("the library")?;
        }
        OP_SCHEMA => {
            c.skip(2, "a schema id")?;
            c.prefixed32("a schema name")?;
            c.prefixed32("a schema encoding")?;
            c.prefixed32("schema data")?;
        }
        OP_CHANNEL => {
            c.skip(4, "channel ids")?;
            c.prefixed32("a topic")?;
            c.prefixed32("a message encoding")?;
            c.string_map("channel metadata")?;
        }
        OP_MESSAGE => c.skip(22, "a message header")?,
        OP_MESSAGE_INDEX => {
            c.skip(2, "a channel id")?;
            let n = c.u32("message index entries")?;
            if n % 16 != 0 {
                return Err(format!("message index entries of {n} bytes"));
            }
            c.skip(u64::from(n), "message index entries")?;
        }
        OP_CHUNK_INDEX => {
            c.skip(32, "a chunk index")?;
            c.map("message index offsets", |e| e.skip(10, "an offset entry"))?;
            c.skip(8, "a message index length")?;
            c.prefixed32("a compression name")?;
            c.skip(16, "chunk sizes")?;
        }
        OP_ATTACHMENT => {
            c.skip(16, "attachment times")?;
            c.prefixed32("an attachment name")?;
            c.prefixed32("a media type")?;
            let n = c.u64("attachment data")?;
            c.skip(n, "attachment data")?;
        }
        OP_ATTACHMENT_INDEX => {
            c.skip(40, "an attachment index")?;
            c.prefixed32("an attachment name")?;
            c.prefixed32("a media type")?;
        }
        OP_STATISTICS => {
            c.skip(8 + 2 + 4 * 4 + 16, "statistics")?;
            c.map("channel message counts", |e| e.skip(10, "a count entry"))?;
        }
        OP_METADATA => {
            c.prefixed32("a metadata name")?;
            c.string_map("metadata")?;
        }
        OP_METADATA_INDEX => {
            c.skip(16, "a metadata index")?;
            c.prefixed32("a metadata name")?;
        }
        _ => {}
    }
    Ok(())
}

/// Every record of a sequence (a chunk's records) fits and passes.
fn check_records(b: &[u8]) -> Check {
    let mut c = Cursor::new(b);
    while c.at < b.len() {
        let at = c.at;
        let op = c.take(1, "an opcode")?[0];
        let len = c.u64("a record length")?;
        let body = c.take(len, &format!("the record at byte {at} (opcode 0x{op:02x})"))?;
        if op == OP_CHUNK {
            return Err(format!("a chunk inside a chunk at byte {at}"));
        }
        check_record(op, body).map_err(|e| format!("the record at byte {at}: {e}"))?;
    }
    Ok(())
}

/// Decompress a chunk's records (bounded by its declared size).
fn decompress(name: &[u8], data: &[u8], size: u64) -> Result<Vec<u8>, String> {
    let out = match name {
        b"" => data.to_vec(),
        b"zstd" => zstd::bulk::decompress(data, size as usize).map_err(|e| format!("zstd: {e}"))?,
        b"lz4" => {
            use std::io::Read;
            let mut out = Vec::with_capacity(size as usize);
            lz4::Decoder::new(data)
                .map_err(|e| format!("lz4: {e}"))?
                .take(size + 1)
                .read_to_end(&mut out)
                .map_err(|e| format!("lz4: {e}"))?;
            out
        }
        other => {
            return Err(format!(
                "unknown compression `{}`",
                String::from_utf8_lossy(other)
            ))
        }
    };
    if out.len() as u64 != size {
        return Err(format!(
            "it declares {size} uncompressed bytes, it holds {}",
            out.len()
        ));
    }
    Ok(out)
}

/// A chunk record's body: consistent sizes, then its records.
fn check_chunk(body: &[u8]) -> Check {
    let mut c = Cursor::new(body);
    c.skip(16, "chunk times")?;
    let uncompressed = c.u64("an uncompressed size")?;
    c.skip(4, "a CRC")?;
    let name = c.prefixed32("a compression name")?;
    let records_len = c.u64("a records length")?;
    let data = c.take(records_len, "the chunk's records")?;
    if uncompressed > MAX_CHUNK_BYTES {
        return Err(format!(
            "it declares {uncompressed} uncompressed bytes (more than {MAX_CHUNK_BYTES})"
        ));
    }
    let records = decompress(name, data, uncompressed)?;
    check_records(&records)
}

/// The readable prefix of `b` (which starts with the MCAP magic): its length
/// and, when it is not the whole file, why (with the byte offset).
pub fn readable_prefix(b: &[u8]) -> (usize, Option<String>) {
    let mut at = 8;
    loop {
        if at == b.len() {
            // Ends after a complete record: a recording never finalised.
            return (at, None);
        }
        if at + 9 > b.len() {
            return (at, Some(format!("a record header is cut off at byte {at}")));
        }
        let op = b[at];
        let len = u64::from_le_bytes(b[at + 1..at + 9].try_into().expect("8 bytes"));
        let left = (b.len() - at - 9) as u64;
        if len > left {
            return (
                at,
                Some(format!(
                    "the record at byte {at} (opcode 0x{op:02x}) declares {len} bytes, {left} are left"
                )),
            );
        }
        let body = &b[at + 9..at + 9 + len as usize];
        let checked = if op == OP_CHUNK {
            check_chunk(body)
        } else {
            check_record(op, body)
        };
        if let Err(e) = checked {
            return (
                at,
                Some(format!("the record at byte {at} (opcode 0x{op:02x}): {e}")),
            );
        }
        if op == OP_FOOTER {
            return (b.len(), None);
        }
        at += 9 + len as usize;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn record(op: u8, body: &[u8]) -> Vec<u8> {
        let mut v = vec![op];
        v.extend_from_slice(&(body.len() as u64).to_le_bytes());
        v.extend_from_slice(body);
        v
    }

    fn string(s: &[u8]) -> Vec<u8> {
        let mut v = (s.len() as u32).to_le_bytes().to_vec();
        v.extend_from_slice(s);
        v
    }

    fn chunk(uncompressed: u64, name: &str, records: &[u8]) -> Vec<u8> {
        let mut b = Vec::new();
        b.extend_from_slice(&[0; 16]);
        b.extend_from_slice(&uncompressed.to_le_bytes());
        b.extend_from_slice(&[0; 4]);
        b.extend(string(name.as_bytes()));
        b.extend_from_slice(&(records.len() as u64).to_le_bytes());
        b.extend_from_slice(records);
        record(OP_CHUNK, &b)
    }

    fn file() -> (Vec<u8>, usize) {
        let mut f = b"\x89MCAP0\r\n".to_vec();
        let mut h = string(b"ros2");
        h.extend(string(b"test"));
        f.extend(record(OP_HEADER, &h));
        let good = f.len();
        (f, good)
    }

    #[test]
    fn the_prefix_ends_at_the_first_record_that_does_not_fit() {
        let (mut f, good) = file();
        let msg = record(OP_MESSAGE, &[0; 22]);
        f.extend(chunk(msg.len() as u64, "", &msg));
        let after_chunk = f.len();
        assert_eq!(readable_prefix(&f), (after_chunk, None));
        // A chunk that claims a gigantic uncompressed size.
        let mut g = f[..good].to_vec();
        g.extend(chunk(1 << 40, "zstd", b"xyz"));
        let (n, why) = readable_prefix(&g);
        assert_eq!(n, good);
        assert!(why.unwrap().contains("uncompressed bytes"));
        // A record length beyond the end.
        let mut h = f.clone();
        h[good + 1..good + 9].copy_from_slice(&u64::MAX.to_le_bytes());
        let (n, why) = readable_prefix(&h);
        assert_eq!(n, good);
        assert!(why.unwrap().contains("declares"));
        // A cut-off record header.
        let (n, why) = readable_prefix(&f[..good + 4]);
        assert_eq!(n, good);
        assert!(why.unwrap().contains("cut off"));
    }

    #[test]
    fn a_string_longer_than_its_record_is_caught_before_the_reader_allocates_it() {
        // The fuzzer's find: a metadata name declaring ~4 GB.
        let (mut f, good) = file();
        let mut m = (0xEBE8_0000u32).to_le_bytes().to_vec();
        m.extend_from_slice(b"x");
        f.extend(record(OP_METADATA, &m));
        let (n, why) = readable_prefix(&f);
        assert_eq!(n, good);
        assert!(why.unwrap().contains("a metadata name declares"));
        // The same inside a zstd chunk.
        let (mut g, good) = file();
        let inner = record(OP_METADATA, &m);
        let z = zstd::bulk::compress(&inner, 3).unwrap();
        g.extend(chunk(inner.len() as u64, "zstd", &z));
        let (n, why) = readable_prefix(&g);
        assert_eq!(n, good);
        assert!(why.unwrap().contains("metadata name"));
    }
}
