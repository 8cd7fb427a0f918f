//! How the per-particle passes are split among threads.
//!
//! Every pass writes each output element from inputs that no other element of the same pass
//! writes (gather, never scatter), and the work is cut into chunks of a fixed size that does
//! not depend on the number of threads. So the result is bitwise identical for any thread
//! count: threads only change which core computes a chunk, never what is computed.
//!
//! Small cloths stay on the calling thread: below [`min_parallel`] particles a step takes a
//! few tens of microseconds and handing chunks to other threads costs more than it saves.
//! Where that crossover lies depends on the CPU: it is chosen by the CPU's maker, from
//! measurements on each (docs/benchmarks.md), and [`MIN_PARALLEL_VARIABLE`] overrides it
//! for measuring it on another machine.
//! Threads come from rayon's current pool: the global pool (`RAYON_NUM_THREADS`), or a pool
//! the host installs around the call, unless a cloth says otherwise ([`Threads`]).

use std::cell::Cell;
use std::sync::Arc;

use rayon::prelude::*;

/// Elements per task. Fixed, so the split never depends on the thread count.
pub const CHUNK: usize = 4096;

/// Particles per tile: the unit the step's passes work in (their arrays for a tile fit in L1
/// cache). A chunk is whole tiles.
pub const TILE: usize = 256;
const _: () = assert!(CHUNK % TILE == 0);

/// Fewest particles for which a step uses more than one thread on a CPU not made by AMD (an
/// Intel Xeon): the threshold chosen with `cargo run --release --example
/// throughput` (docs/benchmarks.md), not yet measured lower on an Intel Xeon. The largest of
/// the thresholds, so a cloth of this many particles uses the pool on every CPU unless
/// [`MIN_PARALLEL_VARIABLE`] says otherwise.
pub const MIN_PARALLEL: usize = 16_000;

/// Fewest particles for which a step uses more than one thread on an AMD CPU: on the AMD EPYC
/// measured (Zen 4, `step_cycles`, docs/benchmarks.md) two threads gain 1.22-1.27x at
/// 6 400 particles (80 x 80) and break even at about 5 000.
pub const MIN_PARALLEL_AMD: usize = 6_400;

/// Environment variable that sets the fewest particles for which a step uses the pool (a
/// whole number, read once), for measuring the crossover on a machine; the choice by CPU
/// when unset or not a number.
pub const MIN_PARALLEL_VARIABLE: &str = "FRACCLOTH_MIN_PARALLEL";

/// Fewest particles for which a step uses more than one thread here: [`MIN_PARALLEL_AMD`] on
/// an AMD CPU, [`MIN_PARALLEL`] on others, or [`MIN_PARALLEL_VARIABLE`] when it is set.
/// The bits of a step never depend on it (only where its chunks run).
pub fn min_parallel() -> usize {
    static CHOSEN: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *CHOSEN.get_or_init(|| {
        let set = std::env::var(MIN_PARALLEL_VARIABLE).ok();
        set.and_then(|s| s.trim().parse().ok())
            .unwrap_or(if made_by_amd() {
                MIN_PARALLEL_AMD
            } else {
                MIN_PARALLEL
            })
    })
}

/// Whether this CPU's vendor string (CPUID leaf 0) is AMD's.
fn made_by_amd() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        // CPUID is on every x86-64 CPU; leaf 0 gives the vendor in ebx, edx, ecx.
        #[allow(unused_unsafe)]
        // SAFETY: the instruction exists on every x86-64 CPU and has no side effects.
        let r = unsafe { std::arch::x86_64::__cpuid(0) };
        let mut vendor = [0u8; 12];
        vendor[..4].copy_from_slice(&r.ebx.to_le_bytes());
        vendor[4..8].copy_from_slice(&r.edx.to_le_bytes());
        vendor[8..].copy_from_slice(&r.ecx.to_le_bytes());
        &vendor == b"AuthenticAMD"
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Whether a cloth of `n` particles should spread its passes over the pool.
pub fn worth_it(n: usize) -> bool {
    n >= min_parallel() && !ON_CALLER.with(Cell::get) && rayon::current_num_threads() > 1
}

thread_local! {
    /// Set while a step of a [`Threads::Caller`] cloth runs on this thread.
    static ON_CALLER: Cell<bool> = const { Cell::new(false) };
}

/// Largest thread count a cloth's own pool may have.
pub const MAX_THREADS: u32 = 256;

/// Which threads a cloth's step runs on. The result is the same bits for every choice (the
/// chunks never depend on the thread count); only where the work runs changes.
#[derive(Clone, Debug, Default)]
pub enum Threads {
    /// rayon's current pool: the global one (`RAYON_NUM_THREADS`) or one the caller installed.
    /// Cloths under [`min_parallel`] particles stay on the calling thread. The default.
    #[default]
    Shared,
    /// Every pass on the calling thread, whatever the cloth's size: for a host that runs
    /// cloths on its own threads (its job system) and wants no other thread touched.
    Caller,
    /// The cloth's own pool of this many threads; the calling thread waits for the step.
    Own(Arc<rayon::ThreadPool>),
}

impl Threads {
    /// `0` = [`Threads::Shared`], `1` = [`Threads::Caller`], `n >= 2` = a new pool of `n`
    /// threads (started now; an error if the system cannot start them).
    pub fn with_count(count: u32) -> Result<Self, String> {
        match count {
            0 => Ok(Self::Shared),
            1 => Ok(Self::Caller),
            n if n > MAX_THREADS => Err(format!("thread count must be at most {MAX_THREADS}, got {n}")),
            n => rayon::ThreadPoolBuilder::new()
                .num_threads(n as usize)
                .thread_name(|i| format!("fraccloth-{i}"))
                .build()
                .map(|p| Self::Own(Arc::new(p)))
                .map_err(|e| format!("cannot start {n} threads: {e}")),
        }
    }

    /// The count [`Threads::with_count`] was given.
    pub fn count(&self) -> u32 {
        match self {
            Self::Shared => 0,
            Self::Caller => 1,
            Self::Own(p) => p.current_num_threads() as u32,
        }
    }

    /// Runs `f` (a step) on these threads.
    pub fn run<T: Send>(&self, f: impl FnOnce() -> T + Send) -> T {
        match self {
            Self::Shared => f(),
            Self::Caller => {
                struct Restore(bool);
                impl Drop for Restore {
                    fn drop(&mut self) {
                        ON_CALLER.with(|c| c.set(self.0));
                    }
                }
                let _restore = Restore(ON_CALLER.with(|c| c.replace(true)));
                f()
            }
            Self::Own(pool) => pool.install(f),
        }
    }
}

/// Calls `f(first_index, chunk)` on consecutive chunks of `a` of `chunk` elements, in
/// parallel when `parallel`.
pub fn chunks<A, F>(parallel: bool, a: &mut [A], chunk: usize, f: F)
where
    A: Send,
    F: Fn(usize, &mut [A]) + Sync + Send,
{
    if parallel {
        a.par_chunks_mut(chunk)
            .enumerate()
            .for_each(|(k, c)| f(k * chunk, c));
    } else {
        a.chunks_mut(chunk).enumerate().for_each(|(k, c)| f(k * chunk, c));
    }
}

/// As [`chunks`], over two slices cut at the same element boundaries: chunk k of `a` has
/// `chunk * stride_a` elements and chunk k of `b` has `chunk * stride_b`. `f` gets the index
/// of the first element (in units of `chunk`'s elements).
pub fn chunks2<A, B, F>(
    parallel: bool,
    (a, stride_a): (&mut [A], usize),
    (b, stride_b): (&mut [B], usize),
    chunk: usize,
    f: F,
) where
    A: Send,
    B: Send,
    F: Fn(usize, &mut [A], &mut [B]) + Sync + Send,
{
    if parallel {
        a.par_chunks_mut(chunk * stride_a)
            .zip(b.par_chunks_mut(chunk * stride_b))
            .enumerate()
            .for_each(|(k, (ca, cb))| f(k * chunk, ca, cb));
    } else {
        a.chunks_mut(chunk * stride_a)
            .zip(b.chunks_mut(chunk * stride_b))
            .enumerate()
            .for_each(|(k, (ca, cb))| f(k * chunk, ca, cb));
    }
}

/// As [`chunks`], over three equally long `f64` slices cut at the same boundaries (the
/// component arrays of a [`crate::soa::Soa3`]).
pub fn chunks3<F>(parallel: bool, [a, b, c]: [&mut [f64]; 3], chunk: usize, f: F)
where
    F: Fn(usize, [&mut [f64]; 3]) + Sync + Send,
{
    if parallel {
        a.par_chunks_mut(chunk)
            .zip(b.par_chunks_mut(chunk))
            .zip(c.par_chunks_mut(chunk))
            .enumerate()
            .for_each(|(k, ((x, y), z))| f(k * chunk, [x, y, z]));
    } else {
        a.chunks_mut(chunk)
            .zip(b.chunks_mut(chunk))
            .zip(c.chunks_mut(chunk))
            .enumerate()
            .for_each(|(k, ((x, y), z))| f(k * chunk, [x, y, z]));
    }
}

/// Calls `f(first, len)` for consecutive chunks `first .. first + len` of `0 .. n`, `chunk`
/// long (the last may be shorter), in parallel when `parallel`. For passes that write several
/// arrays at once through [`Disjoint`].
pub fn for_chunks<F>(parallel: bool, n: usize, chunk: usize, f: F)
where
    F: Fn(usize, usize) + Sync + Send,
{
    let count = n.div_ceil(chunk);
    let run = |k: usize| {
        let first = k * chunk;
        f(first, chunk.min(n - first))
    };
    if parallel {
        (0..count).into_par_iter().for_each(run);
    } else {
        (0..count).for_each(run);
    }
}

/// A mutable slice that the tasks of one [`for_chunks`] call write in disjoint ranges (what
/// `split_at_mut` does for two parts, for as many parts as there are chunks, without allocating).
pub struct Disjoint<'a, T> {
    ptr: *mut T,
    len: usize,
    _borrow: std::marker::PhantomData<&'a mut [T]>,
}

// SAFETY: a `Disjoint` is a `&mut [T]` whose parts are handed out by `range`, whose contract
// forbids overlapping parts; sending parts of it to other threads is then like sending the
// halves of `split_at_mut`.
unsafe impl<T: Send> Send for Disjoint<'_, T> {}
// SAFETY: as above; `range` is the only access and its contract forbids overlapping borrows.
unsafe impl<T: Send> Sync for Disjoint<'_, T> {}

impl<'a, T> Disjoint<'a, T> {
    pub fn new(s: &'a mut [T]) -> Self {
        Self {
            ptr: s.as_mut_ptr(),
            len: s.len(),
            _borrow: std::marker::PhantomData,
        }
    }

    /// Whether the slice is empty.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The elements `r`. Panics when `r` is out of bounds.
    ///
    /// # Safety
    /// No two ranges borrowed from the same `Disjoint` at the same time may overlap (e.g. each
    /// task of a [`for_chunks`] call takes only its own chunk).
    #[allow(clippy::mut_from_ref)]
    pub unsafe fn range(&self, r: std::ops::Range<usize>) -> &'a mut [T] {
        assert!(r.start <= r.end && r.end <= self.len, "range out of bounds");
        // SAFETY: in bounds (checked above) of a live `&'a mut [T]`; not aliased by any other
        // borrow (the caller's contract).
        unsafe { std::slice::from_raw_parts_mut(self.ptr.add(r.start), r.end - r.start) }
    }
}

/// The smallest index in `0..n` for which `bad` holds, searched in parallel chunks when
/// `parallel`; the answer does not depend on the split. `clean(range)` is a fast test that
/// must be true only when `bad` holds for no index of `range` (e.g. a branch-free pass that
/// vectorises); chunks it passes are not searched.
pub fn first_failing<F, C>(parallel: bool, n: usize, clean: C, bad: F) -> Option<usize>
where
    F: Fn(usize) -> bool + Sync + Send,
    C: Fn(std::ops::Range<usize>) -> bool + Sync + Send,
{
    let scan = |k: usize| {
        let range = k * CHUNK..((k + 1) * CHUNK).min(n);
        if clean(range.clone()) {
            None
        } else {
            range.into_iter().find(|&i| bad(i))
        }
    };
    let chunks = n.div_ceil(CHUNK);
    if parallel {
        (0..chunks).into_par_iter().filter_map(scan).min()
    } else {
        (0..chunks).find_map(scan)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn threads_choose_where_work_runs() {
        assert!(
            !Threads::Caller.run(|| worth_it(10 * MIN_PARALLEL)),
            "a Caller step never spreads"
        );
        assert!(!ON_CALLER.with(Cell::get), "the flag is restored after the step");
        let own = Threads::with_count(3).expect("pool");
        assert_eq!(own.count(), 3);
        assert_eq!(own.run(rayon::current_num_threads), 3);
        assert!(own.run(|| worth_it(MIN_PARALLEL)));
        assert!(min_parallel() <= MIN_PARALLEL || std::env::var(MIN_PARALLEL_VARIABLE).is_ok());
        assert!(Threads::with_count(MAX_THREADS + 1).is_err());
        assert_eq!(Threads::with_count(0).map(|t| t.count()), Ok(0));
    }

    /// The vendor read from CPUID is the one the kernel reports (Linux), and the threshold
    /// follows it.
    #[test]
    fn the_threshold_follows_the_cpus_maker() {
        let Ok(info) = std::fs::read_to_string("/proc/cpuinfo") else {
            return;
        };
        let vendor = info
            .lines()
            .find_map(|l| l.strip_prefix("vendor_id"))
            .map(|l| l.trim_start_matches([' ', '\t', ':']).trim());
        let Some(vendor) = vendor else { return };
        assert_eq!(
            made_by_amd(),
            vendor == "AuthenticAMD",
            "CPUID against /proc/cpuinfo: {vendor}"
        );
        if std::env::var(MIN_PARALLEL_VARIABLE).is_err() {
            let expected = if vendor == "AuthenticAMD" {
                MIN_PARALLEL_AMD
            } else {
                MIN_PARALLEL
            };
            assert_eq!(min_parallel(), expected);
        }
    }

    #[test]
    fn chunks_cover_every_element_once_with_its_index() {
        for parallel in [false, true] {
            let mut a = vec![0usize; 3 * CHUNK + 5];
            chunks(parallel, &mut a, CHUNK, |first, c| {
                for (k, x) in c.iter_mut().enumerate() {
                    *x += first + k + 1;
                }
            });
            assert!(a.iter().enumerate().all(|(i, &x)| x == i + 1));
            let mut b = vec![0usize; 2 * a.len()];
            chunks2(parallel, (&mut a, 1), (&mut b, 2), 100, |first, ca, cb| {
                assert_eq!(2 * ca.len(), cb.len());
                for k in 0..ca.len() {
                    cb[2 * k] = first + k;
                }
            });
            assert!((0..a.len()).all(|i| b[2 * i] == i));
        }
    }

    #[test]
    fn for_chunks_with_disjoint_writes_every_element_once() {
        for parallel in [false, true] {
            let n = 3 * CHUNK + 5;
            let (mut a, mut b) = (vec![0usize; n], vec![0usize; 2 * n]);
            let (da, db) = (Disjoint::new(&mut a), Disjoint::new(&mut b));
            for_chunks(parallel, n, CHUNK, |first, len| {
                // SAFETY: each chunk borrows only its own range.
                let (ca, cb) = unsafe {
                    (
                        da.range(first..first + len),
                        db.range(2 * first..2 * (first + len)),
                    )
                };
                for k in 0..len {
                    ca[k] += first + k + 1;
                    cb[2 * k + 1] += first + k;
                }
            });
            assert!(a.iter().enumerate().all(|(i, &x)| x == i + 1));
            assert!((0..n).all(|i| b[2 * i + 1] == i && b[2 * i] == 0));
        }
    }

    #[test]
    fn first_failing_finds_the_smallest_index() {
        let n = 5 * CHUNK + 17;
        for parallel in [false, true] {
            let none = |_| false;
            assert_eq!(
                first_failing(parallel, n, none, |i| i % 3000 == 2999 && i > 9000),
                Some(11999)
            );
            assert_eq!(first_failing(parallel, n, none, |_| false), None);
            assert_eq!(first_failing(parallel, n, none, |i| i == n - 1), Some(n - 1));
            // Chunks the clean test passes are not searched: 2999 and 5999 are skipped.
            let clean = |r: std::ops::Range<usize>| r.end <= 2 * CHUNK;
            assert_eq!(
                first_failing(parallel, n, clean, |i| i % 3000 == 2999),
                Some(8999)
            );
        }
    }
}
