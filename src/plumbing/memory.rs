//! Memory a caller's request will need, checked before it is allocated.
//!
//! Rust aborts the process when an allocation fails, and a plugin must never take its host
//! down. Every allocation whose size a caller sets (a cloth's particles, its history, a
//! snapshot, a cache frame) is therefore either made with `try_reserve` or preceded by
//! [`ensure_available`]: a fallible reservation of the whole amount the request will use
//! at its peak (measured, with a margin), released at once. Under an address-space limit
//! (`ulimit -v`, a container's limit) the probe fails exactly when the request would, and
//! the caller gets [`crate::ErrorKind::OutOfMemory`] instead of an abort.

use crate::error::Error;

/// Peak bytes per particle of building a grid or mesh topology (positions, springs, runs,
/// adjacency, triangles, with their temporaries), with margin; measured peak about 700.
pub const TOPOLOGY_BYTES_PER_PARTICLE: u64 = 1_100;
/// Bytes per particle of a cloth's state, scratch and rollback copies beside its topology
/// and history, with margin; measured about 500-800 over the topology.
pub const STATE_BYTES_PER_PARTICLE: u64 = 1_300;

/// Bytes per particle self-collision adds (its neighbour lists, near pairs and guard, the
/// triangles' trees and the first look), with margin: measured about 1 100 at 0.4 spacings on
/// grids of 251 001 and 1 002 001 particles (peak resident size with and without). Its pair
/// lists past that grow fallibly.
pub const SELF_COLLISION_BYTES_PER_PARTICLE: u64 = 1_500;

/// Fails with an out-of-memory error naming `what` unless `bytes` could be allocated now.
pub fn ensure_available(bytes: u64, what: &str) -> Result<(), Error> {
    let fail = || {
        Error::out_of_memory(format!(
            "{what} needs about {:.1} MB, which cannot be allocated",
            bytes as f64 / 1e6
        ))
    };
    let size = usize::try_from(bytes).map_err(|_| fail())?;
    let mut probe: Vec<u8> = Vec::new();
    probe.try_reserve_exact(size).map_err(|_| fail())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_impossible_amount_is_an_error_not_an_abort() {
        let e = ensure_available(u64::MAX / 2, "a test").unwrap_err();
        assert_eq!(e.kind, crate::ErrorKind::OutOfMemory);
        assert!(e.message.contains("a test"), "{}", e.message);
        assert!(ensure_available(1 << 20, "a megabyte").is_ok());
    }
}
