//! OMG CDR as ROS 2 serialises messages (little-endian, the 4-byte encapsulation header, each primitive aligned to its size from the end of the header): a writer for the messages forkbench records and a bounded reader for those it reads back.

/// CDR_LE: the representation identifier, then two option bytes.
const ENCAPSULATION: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// One message being serialised.
#[derive(Debug, Default)]
pub struct CdrWriter {
    buf: Vec<u8>,
}

impl CdrWriter {
    pub fn new() -> Self {
        Self {
            buf: ENCAPSULATION.to_vec(),
        }
    }

    /// Pads so the next `n`-byte primitive starts at a multiple of `n` after the header.
    fn align(&mut self, n: usize) {
        while !(self.buf.len() - ENCAPSULATION.len()).is_multiple_of(n) {
            self.buf.push(0);
        }
    }

    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }

    pub fn u32(&mut self, v: u32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    pub fn i32(&mut self, v: i32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    pub fn f32(&mut self, v: f32) {
        self.align(4);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    pub fn f64(&mut self, v: f64) {
        self.align(8);
        self.buf.extend_from_slice(&v.to_le_bytes());
    }

    /// A string: its length with the terminating NUL, the bytes, the NUL.
    pub fn string(&mut self, s: &str) {
        self.u32(u32::try_from(s.len() + 1).unwrap_or(u32::MAX));
        self.buf.extend_from_slice(s.as_bytes());
        self.buf.push(0);
    }

    /// A sequence's element count (the elements follow).
    pub fn len(&mut self, n: usize) {
        self.u32(u32::try_from(n).unwrap_or(u32::MAX));
    }

    pub fn f32_seq(&mut self, v: &[f32]) {
        self.len(v.len());
        for x in v {
            self.f32(*x);
        }
    }

    /// A `uint8[]` or `int8[]` (no alignment after the count).
    pub fn bytes_seq(&mut self, v: &[u8]) {
        self.len(v.len());
        self.buf.extend_from_slice(v);
    }

    pub fn into_bytes(self) -> Vec<u8> {
        self.buf
    }
}

/// Why a message could not be read.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CdrError {
    #[error("not little-endian CDR (encapsulation {0:02x?})")]
    Encapsulation([u8; 2]),
    #[error("ends at byte {at} inside a field of {need} bytes")]
    Truncated { at: usize, need: usize },
    #[error("a sequence of {count} elements at byte {at} is longer than the message")]
    Sequence { count: u32, at: usize },
    #[error("a string at byte {at} is not UTF-8 or not NUL-terminated")]
    String { at: usize },
}

/// Reads one message; every length is checked against the bytes left, so a corrupt
/// message is an error, never a large allocation.
#[derive(Debug)]
pub struct CdrReader<'a> {
    data: &'a [u8],
    at: usize,
}

impl<'a> CdrReader<'a> {
    pub fn new(data: &'a [u8]) -> Result<Self, CdrError> {
        if data.len() < 4 {
            return Err(CdrError::Truncated { at: 0, need: 4 });
        }
        if data[0..2] != [0x00, 0x01] {
            return Err(CdrError::Encapsulation([data[0], data[1]]));
        }
        Ok(Self { data, at: 4 })
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], CdrError> {
        while !(self.at - 4).is_multiple_of(n) {
            self.at += 1;
        }
        let end = self.at.checked_add(n).filter(|e| *e <= self.data.len());
        let end = end.ok_or(CdrError::Truncated {
            at: self.at,
            need: n,
        })?;
        let s = &self.data[self.at..end];
        self.at = end;
        Ok(s)
    }

    pub fn u8(&mut self) -> Result<u8, CdrError> {
        let at = self.at;
        let b = *self
            .data
            .get(at)
            .ok_or(CdrError::Truncated { at, need: 1 })?;
        self.at += 1;
        Ok(b)
    }

    pub fn u32(&mut self) -> Result<u32, CdrError> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    pub fn i32(&mut self) -> Result<i32, CdrError> {
        Ok(self.u32()? as i32)
    }

    pub fn f32(&mut self) -> Result<f32, CdrError> {
        Ok(f32::from_bits(self.u32()?))
    }

    pub fn f64(&mut self) -> Result<f64, CdrError> {
        let b = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(b);
        Ok(f64::from_le_bytes(a))
    }

    pub fn string(&mut self) -> Result<String, CdrError> {
        let at = self.at;
        let n = self.u32()? as usize;
        if n > self.data.len().saturating_sub(self.at) {
            return Err(CdrError::Sequence {
                count: n as u32,
                at,
            });
        }
        let bytes = &self.data[self.at..self.at + n];
        self.at += n;
        let text = bytes.strip_suffix(&[0]).unwrap_or(bytes);
        String::from_utf8(text.to_vec()).map_err(|_| CdrError::String { at })
    }

    pub fn f32_seq(&mut self) -> Result<Vec<f32>, CdrError> {
        let at = self.at;
        let count = self.u32()?;
        if (count as usize).saturating_mul(4) > self.data.len().saturating_sub(self.at) {
            return Err(CdrError::Sequence { count, at });
        }
        (0..count).map(|_| self.f32()).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_with_alignment_and_refuses_corrupt_lengths() {
        let mut w = CdrWriter::new();
        w.i32(-7);
        w.string("map");
        w.f64(1.5);
        w.u8(3);
        w.f32_seq(&[1.0, f32::INFINITY]);
        let bytes = w.into_bytes();
        // "map\0" ends at offset 12 after the header: the f64 is padded to 16.
        assert_eq!(bytes.len(), 4 + 16 + 8 + 1 + 3 + 4 + 8);
        let mut r = CdrReader::new(&bytes).expect("header");
        assert_eq!(r.i32(), Ok(-7));
        assert_eq!(r.string().as_deref(), Ok("map"));
        assert_eq!(r.f64(), Ok(1.5));
        assert_eq!(r.u8(), Ok(3));
        assert_eq!(r.f32_seq(), Ok(vec![1.0, f32::INFINITY]));
        let mut huge = bytes[..4].to_vec();
        huge.extend_from_slice(&u32::MAX.to_le_bytes());
        let mut r = CdrReader::new(&huge).expect("header");
        assert!(matches!(r.f32_seq(), Err(CdrError::Sequence { .. })));
        assert!(
            CdrReader::new(&[0x01, 0x00, 0, 0]).is_err(),
            "big-endian refused"
        );
    }
}
