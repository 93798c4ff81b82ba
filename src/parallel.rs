//! The thread pool of one meshing run (`Params::threads`, CLI `--threads`) and the deterministic
//! parallel helpers its steps use.
//!
//! A run ([`with_threads`]) builds one rayon pool of the requested size and keeps the calling
//! thread as the run's thread: the serial steps (refinement, improvement, the callbacks that are
//! not `Sync`) stay on it, and each parallel step enters the pool through [`install`], so every
//! parallel step uses exactly the run's threads. Parallel steps only map over slices with
//! indexed iterators collected in order (or find the first index), and every value they compute
//! depends on its own element only, so the results are the same for every thread count.

use crate::run::spacing::Spacing;
use glam::DVec3;
use rayon::prelude::*;
use std::cell::RefCell;
use std::sync::Arc;

thread_local! {
    /// The pool of the run this thread is running, if any.
    static RUN_POOL: RefCell<Option<Arc<rayon::ThreadPool>>> = const { RefCell::new(None) };
}

/// The thread count `threads` asks for: 0 means all cores, at most
/// [`crate::delaunay::MAX_THREADS`].
pub fn resolve_threads(threads: usize) -> usize {
    crate::delaunay::resolve_threads(threads)
}

/// Restores the thread's previous run pool when a run ends (also by a panic).
struct Restore(Option<Arc<rayon::ThreadPool>>);

impl Drop for Restore {
    fn drop(&mut self) {
        let previous = self.0.take();
        RUN_POOL.with(|p| *p.borrow_mut() = previous);
    }
}

/// Runs `f` on the calling thread as a run on `threads` threads (0: all cores): the parallel
/// steps inside it ([`install`]) run on one pool of that many threads, built here (or the
/// enclosing run's, when it has that size). Should the pool fail to build (no thread can be
/// started), the steps run on rayon's global pool instead: the results are the same.
pub fn with_threads<R>(threads: usize, f: impl FnOnce() -> R) -> R {
    let threads = resolve_threads(threads);
    let current = RUN_POOL.with(|p| p.borrow().clone());
    let pool = match current {
        Some(pool) if pool.current_num_threads() == threads => Some(pool),
        _ => rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("slivermesh-{i}"))
            .build()
            .ok()
            .map(Arc::new),
    };
    let _restore = Restore(RUN_POOL.with(|p| std::mem::replace(&mut *p.borrow_mut(), pool)));
    f()
}

/// Runs the parallel step `f` on the run's pool (outside a run, or on one of the pool's own
/// threads, where it is: rayon's current pool).
pub fn install<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    match RUN_POOL.with(|p| p.borrow().clone()) {
        Some(pool) => pool.install(f),
        None => f(),
    }
}

/// Threads the parallel steps of the current run use (outside a run, or on one of the pool's
/// own threads: rayon's current pool's). With one, the helpers below work on the calling
/// thread, as serial code.
pub fn current_threads() -> usize {
    RUN_POOL
        .with(|p| p.borrow().as_ref().map(|pool| pool.current_num_threads()))
        .unwrap_or_else(rayon::current_num_threads)
}

/// Below this many items a slice is mapped on the calling thread: splitting it would cost more
/// than it saves.
const MIN_PARALLEL: usize = 2048;

/// `items.iter().map(f).collect()`, on the run's threads when `items` is long: the same vector
/// for every thread count. The vector is allocated on the calling thread (in its allocator
/// heap, where the memory the run freed before is: allocated on a pool thread, a big result
/// took fresh pages and doubled the peak memory of a 582,222-tet run).
pub fn map_collect<T: Sync, U: Send>(items: &[T], f: impl Fn(&T) -> U + Sync + Send) -> Vec<U> {
    map_collect_split(items, Split::LONG_CHEAP_ITEMS, f)
}

/// How [`map_collect_split`] shares a map between the threads.
#[derive(Clone, Copy, Debug)]
pub struct Split {
    /// Fewer items are mapped on the calling thread.
    pub min_items: usize,
    /// Fewest items a thread takes at a time.
    pub min_chunk: usize,
    /// Most items a thread takes at a time (small for costly items, so the threads stay busy).
    pub max_chunk: usize,
}

impl Split {
    /// Many cheap items: a thread takes 512 at least.
    pub const LONG_CHEAP_ITEMS: Split = Split {
        min_items: MIN_PARALLEL,
        min_chunk: 512,
        max_chunk: usize::MAX,
    };
}

/// [`map_collect`] with the caller's split between the threads: the same vector for every
/// thread count and split.
pub fn map_collect_split<T: Sync, U: Send>(
    items: &[T],
    split: Split,
    f: impl Fn(&T) -> U + Sync + Send,
) -> Vec<U> {
    if items.len() < split.min_items || current_threads() <= 1 {
        return items.iter().map(f).collect();
    }
    let mut out = Vec::with_capacity(items.len());
    install(|| {
        items
            .par_iter()
            .with_min_len(split.min_chunk)
            .with_max_len(split.max_chunk)
            .map(f)
            .collect_into_vec(&mut out)
    });
    out
}

/// The first index whose item satisfies `pred` (as `items.iter().position(pred)`), on the run's
/// threads when `items` is long.
pub fn position_first<T: Sync>(
    items: &[T],
    pred: impl Fn(&T) -> bool + Sync + Send,
) -> Option<usize> {
    if items.len() < MIN_PARALLEL || current_threads() <= 1 {
        return items.iter().position(pred);
    }
    install(|| items.par_iter().with_min_len(512).position_first(pred))
}

/// Fewest points a thread gets when [`SplitSpacing`] splits a batch.
const MIN_SPACING_SPLIT: usize = 256;

/// A spacing that may be evaluated on several threads at once (a `Sync` Rust type, or a C
/// callback its caller declared thread-safe): its batches of at least 2 x 256 points are split
/// across the run's threads, each part one `at_many` call of the inner spacing (with one thread
/// the whole batch is one call on the calling thread). Each point's value is the inner
/// spacing's at that point, so the split changes no value.
pub struct SplitSpacing<'a>(pub &'a (dyn Spacing + Sync));

impl Spacing for SplitSpacing<'_> {
    fn at(&self, p: DVec3) -> f64 {
        self.0.at(p)
    }

    fn at_many(&self, points: &[DVec3], out: &mut [f64]) {
        let n = points.len().min(out.len());
        let (points, out) = (&points[..n], &mut out[..n]);
        let threads = current_threads();
        if n < 2 * MIN_SPACING_SPLIT || threads <= 1 {
            return self.0.at_many(points, out);
        }
        let inner = self.0;
        let chunk = n.div_ceil(threads).max(MIN_SPACING_SPLIT);
        install(|| {
            points
                .par_chunks(chunk)
                .zip(out.par_chunks_mut(chunk))
                .for_each(|(p, o)| inner.at_many(p, o));
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::spacing::FnSpacing;
    use std::sync::atomic::{AtomicUsize, Ordering};

    #[test]
    fn runs_use_their_thread_count_and_restore_the_previous_pool() {
        with_threads(3, || {
            assert_eq!(current_threads(), 3);
            with_threads(2, || assert_eq!(current_threads(), 2));
            assert_eq!(current_threads(), 3);
            with_threads(1, || assert_eq!(current_threads(), 1));
        });
        with_threads(0, || assert_eq!(current_threads(), resolve_threads(0)));
    }

    #[test]
    fn maps_and_finds_as_the_serial_iterators() {
        let items: Vec<u64> = (0..10_000).map(|i| (i * 7919) % 10_007).collect();
        let want: Vec<u64> = items.iter().map(|x| x * x + 1).collect();
        for threads in [1, 2, 3] {
            with_threads(threads, || {
                assert_eq!(map_collect(&items, |x| x * x + 1), want);
                assert_eq!(
                    position_first(&items, |&x| x > 10_000),
                    items.iter().position(|&x| x > 10_000)
                );
                assert_eq!(position_first(&items, |&x| x > 20_000), None);
            });
        }
    }

    #[test]
    fn split_spacing_gives_every_point_its_value() {
        let calls = AtomicUsize::new(0);
        let f = FnSpacing(|p: DVec3| {
            calls.fetch_add(1, Ordering::Relaxed);
            1.0 + p.x * 0.5 + p.y
        });
        let points: Vec<DVec3> = (0..3000)
            .map(|i| DVec3::new(i as f64, (i % 7) as f64, 0.0))
            .collect();
        let want: Vec<f64> = points.iter().map(|&p| 1.0 + p.x * 0.5 + p.y).collect();
        for threads in [1, 2, 4] {
            with_threads(threads, || {
                let mut out = vec![f64::NAN; points.len()];
                SplitSpacing(&f).at_many(&points, &mut out);
                assert_eq!(out, want);
                let mut few = vec![f64::NAN; 10];
                SplitSpacing(&f).at_many(&points[..10], &mut few);
                assert_eq!(few, want[..10]);
            });
        }
        assert_eq!(calls.load(Ordering::Relaxed), 3 * 3010);
    }
}
