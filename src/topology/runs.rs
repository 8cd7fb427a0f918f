//! Springs grouped into runs: consecutive springs `(i, i + offset)`, `(i + 1, i + 1 + offset)`,
//! ... of one family. A run's end points are contiguous in memory, so the spring pass loads
//! them as plain slices (no index loads, no gathers) and the compiler vectorises it.
//!
//! [`order_into_runs`] sorts a spring list by (family, offset, first vertex); a grid then falls
//! into long runs (a whole vertical family is one run) and any mesh whose vertices are
//! numbered in rows (most are) into fairly long ones. A spring that fits no run is a run of
//! one: the layout is never wrong, only less fast.

use super::Spring;

/// `len` springs starting at spring index `first_spring`; spring `first_spring + t` joins
/// vertex `first_vertex + t` to vertex `first_vertex + t + offset`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SpringRun {
    pub first_spring: u32,
    pub first_vertex: u32,
    pub offset: u32,
    pub len: u32,
}

/// Sorts `springs` (each with i < j) by (kind, j - i, i) and returns the runs.
pub fn order_into_runs(springs: &mut [Spring]) -> Vec<SpringRun> {
    springs.sort_by_key(|s| (s.kind as u8, s.j - s.i, s.i));
    let mut runs: Vec<SpringRun> = Vec::new();
    for (k, s) in springs.iter().enumerate() {
        let offset = s.j - s.i;
        if let Some(r) = runs.last_mut() {
            let prev = &springs[k - 1];
            if prev.kind == s.kind && r.offset == offset && r.first_vertex + r.len == s.i {
                r.len += 1;
                continue;
            }
        }
        runs.push(SpringRun {
            first_spring: k as u32,
            first_vertex: s.i,
            offset,
            len: 1,
        });
    }
    runs
}

#[cfg(test)]
mod tests {
    use crate::topology::GridSpec;

    #[test]
    fn runs_describe_every_spring_exactly() {
        let t = GridSpec {
            width: 7,
            height: 5,
            spacing: 0.1,
            total_mass: 1.0,
        }
        .build()
        .unwrap();
        let mut covered = 0;
        for r in &t.spring_runs {
            for k in 0..r.len {
                let s = &t.springs[(r.first_spring + k) as usize];
                assert_eq!(s.i, r.first_vertex + k);
                assert_eq!(s.j, s.i + r.offset);
                assert_eq!(s.kind, t.springs[r.first_spring as usize].kind);
            }
            assert_eq!(r.first_spring as usize, covered);
            covered += r.len as usize;
        }
        assert_eq!(covered, t.springs.len());
        // The vertical stretch family is one run over all rows but the last.
        assert!(t.spring_runs.iter().any(|r| r.offset == 7 && r.len == 7 * 4));
    }
}
