//! How a point cache encodes one frame.

/// One frame as f32 triples, little- or big-endian (the caches' only difference in encoding).
/// A position beyond the float range is an error (it would be written as infinite).
pub(crate) fn encode_frame(positions: &[crate::math::Vec3], big_endian: bool) -> std::io::Result<Vec<u8>> {
    let mut buf = Vec::new();
    buf.try_reserve_exact(12 * positions.len())
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::OutOfMemory, e.to_string()))?;
    for p in positions {
        for c in p.iter() {
            let v = *c as f32;
            if !v.is_finite() {
                return Err(std::io::Error::new(
                    std::io::ErrorKind::InvalidInput,
                    format!("position {p:?} is beyond the float range of a cache"),
                ));
            }
            buf.extend_from_slice(&if big_endian {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            });
        }
    }
    Ok(buf)
}
