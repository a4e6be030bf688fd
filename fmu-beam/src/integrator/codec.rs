//! The byte codec of serialized states (fmi2SerializeFMUstate): little-endian numbers and
//! length-prefixed vectors, read back with bounds checks.

use crate::error::EngineError;

/// Appends a vector: its length (u64), then its values (f64), little-endian.
pub(crate) fn write_vec(w: &mut Vec<u8>, v: &[f64]) {
    w.extend_from_slice(&(v.len() as u64).to_le_bytes());
    for x in v {
        w.extend_from_slice(&x.to_le_bytes());
    }
}

/// Bounds-checked reader of serialized states.
pub(crate) struct Reader<'a> {
    b: &'a [u8],
    pos: usize,
}

impl<'a> Reader<'a> {
    pub(crate) fn new(b: &'a [u8]) -> Reader<'a> {
        Reader { b, pos: 0 }
    }
    /// Bytes read so far.
    pub(crate) fn pos(&self) -> usize {
        self.pos
    }
    pub(crate) fn take(&mut self, n: usize) -> Result<&'a [u8], EngineError> {
        if self.b.len() - self.pos < n {
            return Err(EngineError::BadState {
                message: format!("truncated: {} bytes, more expected", self.b.len()),
            });
        }
        let s = &self.b[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }
    pub(crate) fn u8(&mut self) -> Result<u8, EngineError> {
        Ok(self.take(1)?[0])
    }
    pub(crate) fn u32(&mut self) -> Result<u32, EngineError> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().unwrap_or_default(),
        ))
    }
    pub(crate) fn u64(&mut self) -> Result<u64, EngineError> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().unwrap_or_default(),
        ))
    }
    pub(crate) fn f64(&mut self) -> Result<f64, EngineError> {
        Ok(f64::from_bits(self.u64()?))
    }
    pub(crate) fn vec(&mut self) -> Result<Vec<f64>, EngineError> {
        let n = self.u64()? as usize;
        if n > (self.b.len() - self.pos) / 8 {
            return Err(EngineError::BadState {
                message: format!("a vector of {n} values does not fit in the bytes left"),
            });
        }
        (0..n).map(|_| self.f64()).collect()
    }
}
