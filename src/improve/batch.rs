//! Plans made ahead on the run's threads (issue 39: the same mesh for every thread count).
//!
//! The improver still takes the bad tets from its heap one at a time, worst first, and works
//! on each (`Improver::work_on`) on the calling thread, exactly as with one thread. What the
//! threads do is make, in batches, the plans it will ask for: when the tet taken from the heap
//! has none, the next due entries of the heap (`batch_size`, the heap left as it was) are
//! planned on the run's threads against the mesh as it stands (`Improver::plan_ahead`: the
//! tet's best flip, else the smoothings of its vertices, else an insertion and a deletion).
//! When `work_on` then needs a plan, it takes the one made ahead if it is still the plan it
//! would make now, and makes it now otherwise.
//!
//! Whether it still is, is decided exactly. Every plan is a pure function of the working mesh
//! (the radius-edge tally it counts included), and while it is made ahead it records its
//! footprint: every vertex whose star it scanned and every vertex of every tet it read
//! (`note`, called by `Work::ring`, `Work::face_tets` and the planners that walk a star, the
//! tet's own vertices). Every change of the mesh marks vertices with the current batch
//! (`Work::touch`): the four vertices of every tet it kills or makes, a moved vertex, a vertex
//! whose constraint changes, the corners of a boundary triangle it replaces. What a plan reads
//! only changes through a change that marks a vertex of its footprint:
//!
//! - a star changes only when a tet holding its vertex comes or goes (that vertex is marked);
//! - a tet's vertices, region and objective change only when it is killed or made, or when one
//!   of its vertices moves (a tet read has its four vertices in the footprint);
//! - a face or an edge changes boundary status only in a boundary flip, which kills and makes
//!   tets holding all its vertices; a vertex's constraint (and its boundary triangles) only
//!   when it is marked.
//!
//! So a plan whose footprint holds no vertex marked since its batch began is, bit for bit, the
//! plan the same code makes now (the unit tests make every such plan again and compare). The
//! changes, their order, the stats and the mesh are therefore those of the one-thread run,
//! whichever plans were made ahead: the batch size, the thread count and the scheduling of the
//! threads decide only how much planning is done twice. No hashing decides anything either
//! (the plans made ahead are looked up by tet, never iterated).

use super::flips::Plan;
use super::{delete::Deletion, insert::Insertion, smooth::Smoothing};
use std::cell::{Cell, RefCell};

/// Entries a batch plans per thread of the run. Any size gives the same mesh; larger batches
/// keep the threads busy for longer, smaller ones leave fewer plans to go stale before they are
/// used (rotor.off in keep mode, 2 threads: batches of 64 made 4.8% of the plans again, of
/// 256: 11%).
const PER_THREAD: usize = 32;

/// Entries a batch plans: `PER_THREAD` per thread, at least 64.
pub(crate) fn batch_size(threads: usize) -> usize {
    (PER_THREAD * threads).max(64)
}

thread_local! {
    /// The footprint being recorded on this thread, if any.
    static FOOTPRINT: RefCell<Option<Vec<u32>>> = const { RefCell::new(None) };
    /// Radius-edge refusals and give-ways counted by the plan running on this thread.
    static TALLY: Cell<Tally> = const { Cell::new(Tally { vetoes: 0, yields: 0 }) };
}

/// What the radius-edge bound did during one plan (`ImproveStats::rho_vetoes`, `rho_yields`):
/// added to the stats when the plan is used, so discarded speculation counts nothing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Tally {
    pub vetoes: usize,
    pub yields: usize,
}

/// Counts a refusal (true) or a give-way (false) for the plan running on this thread.
pub(crate) fn count_rho(vetoed: bool) {
    TALLY.with(|c| {
        let mut t = c.get();
        if vetoed {
            t.vetoes += 1;
        } else {
            t.yields += 1;
        }
        c.set(t);
    });
}

/// Adds `vertices` to the footprint being recorded on this thread (none: nothing).
#[inline]
pub(crate) fn note(vertices: &[u32]) {
    FOOTPRINT.with(|f| {
        if let Some(foot) = f.borrow_mut().as_mut() {
            foot.extend_from_slice(vertices);
        }
    });
}

/// `f()` with the radius-edge tally it made.
pub(crate) fn tallied<T>(f: impl FnOnce() -> T) -> (T, Tally) {
    let before = TALLY.with(|c| c.replace(Tally::default()));
    let value = f();
    let tally = TALLY.with(|c| c.replace(before));
    (value, tally)
}

/// A plan computed ahead, with what it read and what the radius-edge bound did.
pub(crate) struct Memo<T> {
    pub value: T,
    pub footprint: Vec<u32>,
    pub tally: Tally,
}

/// `f()` as a [`Memo`]: its footprint starts with `start` (the vertices the caller read).
pub(crate) fn recorded<T>(start: &[u32], f: impl FnOnce() -> T) -> Memo<T> {
    let mut foot = Vec::with_capacity(256);
    foot.extend_from_slice(start);
    let previous = FOOTPRINT.with(|c| c.replace(Some(foot)));
    let (value, tally) = tallied(f);
    let mut footprint = FOOTPRINT.with(|c| c.replace(previous)).unwrap_or_default();
    // Each vertex once: the commit checks them on the calling thread.
    footprint.sort_unstable();
    footprint.dedup();
    footprint.shrink_to_fit();
    Memo {
        value,
        footprint,
        tally,
    }
}

/// The plans made ahead for one tet of a batch, in the order `Improver::work_on` asks for
/// them (a plan it would not reach on the mesh as it stood is left out).
#[derive(Default)]
pub(crate) struct Ahead {
    /// The batch they were made in (`Work::epoch`).
    pub epoch: u32,
    pub flip: Option<Memo<Option<Plan>>>,
    /// The smoothing of each of the tet's vertices, in the tet's vertex order.
    pub smooth: [Option<Memo<Smoothing>>; 4],
    pub insertion: Option<Memo<Option<Insertion>>>,
    pub deletion: Option<Memo<Option<Deletion>>>,
}

/// How a batch's plans are shared between the threads: a batch has a few hundred items, each
/// worth tens of microseconds, so a thread takes a few at a time.
pub(crate) const PLAN_SPLIT: crate::parallel::Split = crate::parallel::Split {
    min_items: 2,
    min_chunk: 1,
    max_chunk: 4,
};
