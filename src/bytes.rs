//! Little-endian byte writer and bounds-checked reader for the snapshot format.

use crate::error::Error;
use crate::Vec3;

/// Appends little-endian values to a byte vector.
#[derive(Default)]
pub struct ByteWriter {
    pub buf: Vec<u8>,
}

impl ByteWriter {
    pub fn u8(&mut self, v: u8) {
        self.buf.push(v);
    }
    pub fn u32(&mut self, v: u32) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn u64(&mut self, v: u64) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn f64(&mut self, v: f64) {
        self.buf.extend_from_slice(&v.to_le_bytes());
    }
    pub fn vec3(&mut self, v: &Vec3) {
        for c in v.iter() {
            self.f64(*c);
        }
    }
    /// A length, then the vectors.
    pub fn vec3s(&mut self, v: &[Vec3]) {
        self.u64(v.len() as u64);
        for p in v {
            self.vec3(p);
        }
    }
    /// A length, then the numbers.
    pub fn f64s(&mut self, v: &[f64]) {
        self.u64(v.len() as u64);
        for x in v {
            self.f64(*x);
        }
    }
}

/// Reads what [`ByteWriter`] wrote; every read is bounds-checked.
pub struct ByteReader<'a> {
    data: &'a [u8],
    pos: usize,
}

fn short() -> Error {
    Error::invalid("snapshot is truncated")
}

impl<'a> ByteReader<'a> {
    pub fn new(data: &'a [u8]) -> Self {
        Self { data, pos: 0 }
    }
    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }
    pub fn bytes(&mut self, n: usize) -> Result<&'a [u8], Error> {
        let end = self.pos.checked_add(n).ok_or_else(short)?;
        let s = self.data.get(self.pos..end).ok_or_else(short)?;
        self.pos = end;
        Ok(s)
    }
    fn array<const N: usize>(&mut self) -> Result<[u8; N], Error> {
        let mut a = [0u8; N];
        a.copy_from_slice(self.bytes(N)?);
        Ok(a)
    }
    pub fn u8(&mut self) -> Result<u8, Error> {
        Ok(self.array::<1>()?[0])
    }
    pub fn u32(&mut self) -> Result<u32, Error> {
        Ok(u32::from_le_bytes(self.array()?))
    }
    pub fn u64(&mut self) -> Result<u64, Error> {
        Ok(u64::from_le_bytes(self.array()?))
    }
    pub fn f64(&mut self) -> Result<f64, Error> {
        Ok(f64::from_le_bytes(self.array()?))
    }
    pub fn vec3(&mut self) -> Result<Vec3, Error> {
        Ok(Vec3::new(self.f64()?, self.f64()?, self.f64()?))
    }
    /// A length (which must equal `expected` when given, and fit in what is left), then
    /// the vectors, into `out` (resized).
    pub fn vec3s_into(&mut self, expected: Option<usize>, out: &mut Vec<Vec3>) -> Result<(), Error> {
        let n = self.len(expected, 24)?;
        out.clear();
        out.reserve(n);
        for _ in 0..n {
            out.push(self.vec3()?);
        }
        Ok(())
    }
    pub fn f64s_into(&mut self, expected: Option<usize>, out: &mut Vec<f64>) -> Result<(), Error> {
        let n = self.len(expected, 8)?;
        out.clear();
        out.reserve(n);
        for _ in 0..n {
            out.push(self.f64()?);
        }
        Ok(())
    }
    /// A length prefix, checked against `expected` and against the bytes left (so a corrupt
    /// length cannot make us allocate).
    pub fn len(&mut self, expected: Option<usize>, item_bytes: usize) -> Result<usize, Error> {
        let n = self.u64()?;
        if let Some(e) = expected {
            if n != e as u64 {
                return Err(Error::invalid(format!(
                    "snapshot holds {n} items where this cloth needs {e}"
                )));
            }
        }
        if n.saturating_mul(item_bytes as u64) > self.remaining() as u64 {
            return Err(short());
        }
        Ok(n as usize)
    }
}
