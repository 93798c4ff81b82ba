//! The cell level's loop over bad elements, one piece of code for both modes (keep mode's
//! `quality::Refiner`, the approximate mode's cell level): the bad elements queued per class
//! ([`BadQueues`]), and the driver ([`work_off`]) that takes them in order, asks the level
//! ([`BadLevel`]) whether each is still bad, has it refined, and counts every refusal.

use super::outcome::Outcome;
use crate::run::report::Refusals;
use std::collections::VecDeque;

/// A bad element's class, in refinement priority order: the highest is served first.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Class {
    /// A sliver (sigma < sigma0, or a dihedral angle below the bound).
    Sliver = 0,
    /// Radius-edge ratio over rho0.
    Ratio = 1,
    /// Too large for the spacing.
    Size = 2,
}

/// The bad elements of one level: one FIFO queue per [`Class`], the highest class served
/// first, then the elements put aside ([`Outcome::Deferred`]) until every queue is empty.
pub(crate) struct BadQueues<T> {
    queues: [VecDeque<T>; 3],
    deferred: VecDeque<T>,
}

impl<T> Default for BadQueues<T> {
    fn default() -> Self {
        BadQueues {
            queues: Default::default(),
            deferred: VecDeque::new(),
        }
    }
}

impl<T> BadQueues<T> {
    /// Queues `bad` at the end of its class's queue.
    pub(crate) fn push(&mut self, class: Class, bad: T) {
        self.queues[class as usize].push_back(bad);
    }

    /// Puts `bad` aside until every class queue is empty.
    pub(crate) fn defer(&mut self, bad: T) {
        self.deferred.push_back(bad);
    }

    /// The next element, and whether it was deferred: the front of the highest non-empty
    /// class queue, else of the deferred queue.
    pub(crate) fn pop(&mut self) -> Option<(T, bool)> {
        if let Some(b) = self.queues.iter_mut().rev().find_map(|q| q.pop_front()) {
            return Some((b, false));
        }
        self.deferred.pop_front().map(|b| (b, true))
    }

    /// Every element still queued, deferred ones included (in no particular order).
    pub(crate) fn iter(&self) -> impl Iterator<Item = &T> {
        self.queues.iter().flatten().chain(&self.deferred)
    }
}

/// A level whose bad elements [`work_off`] refines: its hooks.
pub(crate) trait BadLevel {
    /// A queued bad element (as it was when judged).
    type Bad: Copy;
    type Error;

    fn queues(&mut self) -> &mut BadQueues<Self::Bad>;

    /// Before the next element is taken: the levels below are worked off. False stops the
    /// loop ([`Ended::Stopped`]).
    fn before_next(&mut self) -> bool {
        true
    }

    /// Whether queued `bad` is still an element of the mesh and still bad (it may update
    /// what it carries, e.g. its class or a spacing value).
    fn still_bad(&mut self, bad: &mut Self::Bad) -> bool;

    /// Whether a budget allows refining `bad`; false stops the loop ([`Ended::Stopped`]; the
    /// level counts what is left).
    fn within_budget(&mut self, bad: &Self::Bad) -> bool;

    /// The number of vertices (progress, and whether a refinement inserted anything).
    fn num_vertices(&self) -> usize;

    /// Refines `bad` (`deferred`: taken from the deferred queue) and says what it did.
    fn refine(&mut self, bad: Self::Bad, deferred: bool) -> Result<Outcome, Self::Error>;

    /// Where refusals are counted.
    fn refusals(&mut self) -> &mut Refusals;

    /// The level's books after `bad` was refined with `outcome` (`n_before`: the vertex count
    /// before; a refusal is counted already). False stops the loop ([`Ended::Stopped`]).
    fn record(
        &mut self,
        bad: Self::Bad,
        outcome: Outcome,
        n_before: usize,
    ) -> Result<bool, Self::Error>;
}

/// How [`work_off`] ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Ended {
    /// No bad element is left.
    Done,
    /// A hook stopped it (a budget, or a level below).
    Stopped,
    /// The progress callback asked to stop.
    Cancelled,
}

/// Steps between two calls of the progress callback.
const PROGRESS_EVERY: usize = 1024;

/// Refines `level`'s bad elements until none is left or a hook stops it: the levels below
/// first ([`BadLevel::before_next`]), then the next queued element that is still bad, within
/// the budget, refined; every [`Outcome::Refused`] is counted in [`BadLevel::refusals`].
/// `progress` gets the vertex count every [`PROGRESS_EVERY`] refined elements; false cancels.
pub(crate) fn work_off<L: BadLevel>(
    level: &mut L,
    progress: &mut dyn FnMut(usize) -> bool,
) -> Result<Ended, L::Error> {
    let mut steps = 0usize;
    loop {
        if !level.before_next() {
            return Ok(Ended::Stopped);
        }
        let Some((mut bad, deferred)) = level.queues().pop() else {
            return Ok(Ended::Done);
        };
        if !level.still_bad(&mut bad) {
            continue;
        }
        if !level.within_budget(&bad) {
            return Ok(Ended::Stopped);
        }
        steps += 1;
        if steps % PROGRESS_EVERY == 0 && !progress(level.num_vertices()) {
            return Ok(Ended::Cancelled);
        }
        let n_before = level.num_vertices();
        let outcome = level.refine(bad, deferred)?;
        if !book(level, bad, outcome, n_before)? {
            return Ok(Ended::Stopped);
        }
    }
}

/// The books of one refined element: a refusal counted, then the level's own
/// ([`BadLevel::record`]). False when the loop must stop.
pub(crate) fn book<L: BadLevel>(
    level: &mut L,
    bad: L::Bad,
    outcome: Outcome,
    n_before: usize,
) -> Result<bool, L::Error> {
    if let Outcome::Refused(reason) = outcome {
        reason.count(level.refusals());
    }
    level.record(bad, outcome, n_before)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::refine::outcome::Refusal;

    #[test]
    fn highest_class_first_then_fifo_then_deferred() {
        let mut q = BadQueues::default();
        q.push(Class::Sliver, 1);
        q.push(Class::Size, 2);
        q.defer(3);
        q.push(Class::Ratio, 4);
        q.push(Class::Size, 5);
        let order: Vec<_> = std::iter::from_fn(|| q.pop()).collect();
        assert_eq!(
            order,
            [(2, false), (5, false), (4, false), (1, false), (3, true)]
        );
    }

    /// A toy level: odd elements are refused, even ones "insert" a vertex; element 0 is no
    /// longer bad; element 100 stops the loop.
    struct Toy {
        q: BadQueues<u32>,
        n: usize,
        refusals: Refusals,
        seen: Vec<u32>,
    }

    impl BadLevel for Toy {
        type Bad = u32;
        type Error = ();
        fn queues(&mut self) -> &mut BadQueues<u32> {
            &mut self.q
        }
        fn still_bad(&mut self, bad: &mut u32) -> bool {
            *bad != 0
        }
        fn within_budget(&mut self, bad: &u32) -> bool {
            *bad != 100
        }
        fn num_vertices(&self) -> usize {
            self.n
        }
        fn refine(&mut self, bad: u32, _deferred: bool) -> Result<Outcome, ()> {
            self.seen.push(bad);
            Ok(match bad % 2 {
                1 => Outcome::Refused(Refusal::Duplicate),
                _ => {
                    self.n += 1;
                    Outcome::Inserted
                }
            })
        }
        fn refusals(&mut self) -> &mut Refusals {
            &mut self.refusals
        }
        fn record(&mut self, _bad: u32, _o: Outcome, _n: usize) -> Result<bool, ()> {
            Ok(true)
        }
    }

    #[test]
    fn refusals_counted_and_budget_stops() {
        let mut toy = Toy {
            q: BadQueues::default(),
            n: 0,
            refusals: Refusals::default(),
            seen: vec![],
        };
        for b in [1, 0, 2, 3, 100, 4] {
            toy.q.push(Class::Ratio, b);
        }
        let ended = work_off(&mut toy, &mut |_| true);
        assert_eq!(ended, Ok(Ended::Stopped));
        assert_eq!(toy.seen, [1, 2, 3]);
        assert_eq!(toy.refusals.duplicate, 2);
        assert_eq!(toy.refusals.total, 2);
        toy.q = BadQueues::default();
        for b in 1..=3000 {
            toy.q.push(Class::Size, 1000 + 2 * b);
        }
        let ended = work_off(&mut toy, &mut |n| n < 1500);
        assert_eq!(ended, Ok(Ended::Cancelled));
    }
}
