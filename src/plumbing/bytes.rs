//! Little-endian byte writer and bounds-checked reader for the snapshot format.

use crate::error::Error;
use crate::math::Vec3;

/// Appends little-endian values to a byte vector, or only counts them (to size a snapshot
/// without building it).
#[derive(Default)]
pub struct ByteWriter {
    pub buf: Vec<u8>,
    counting: bool,
    count: usize,
}

impl ByteWriter {
    /// A writer that only counts the bytes it is given.
    pub fn counter() -> Self {
        Self {
            counting: true,
            ..Self::default()
        }
    }
    /// A writer whose buffer already holds room for `bytes` (fallibly).
    pub fn with_room(bytes: usize) -> Result<Self, Error> {
        let mut buf = Vec::new();
        buf.try_reserve_exact(bytes)
            .map_err(|_| Error::out_of_memory(format!("a snapshot of {bytes} bytes cannot be allocated")))?;
        Ok(Self {
            buf,
            ..Self::default()
        })
    }
    /// True for a writer that only counts.
    pub fn is_counting(&self) -> bool {
        self.counting
    }
    /// Bytes written (or counted) so far.
    pub fn len(&self) -> usize {
        if self.counting {
            self.count
        } else {
            self.buf.len()
        }
    }
    pub fn put(&mut self, bytes: &[u8]) {
        if self.counting {
            self.count += bytes.len();
        } else {
            self.buf.extend_from_slice(bytes);
        }
    }
    pub fn u8(&mut self, v: u8) {
        self.put(&[v]);
    }
    pub fn u32(&mut self, v: u32) {
        self.put(&v.to_le_bytes());
    }
    pub fn u64(&mut self, v: u64) {
        self.put(&v.to_le_bytes());
    }
    pub fn f64(&mut self, v: f64) {
        self.put(&v.to_le_bytes());
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
        out.try_reserve(n)
            .map_err(|_| Error::out_of_memory(format!("no memory to read {n} vectors")))?;
        for _ in 0..n {
            out.push(self.vec3()?);
        }
        Ok(())
    }
    pub fn f64s_into(&mut self, expected: Option<usize>, out: &mut Vec<f64>) -> Result<(), Error> {
        let n = self.len(expected, 8)?;
        out.clear();
        out.try_reserve(n)
            .map_err(|_| Error::out_of_memory(format!("no memory to read {n} numbers")))?;
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
