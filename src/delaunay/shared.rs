//! Probes through a shared reference: several threads search cavities of one triangulation at
//! once (refinement plans its next points so, `refine::plan`), each with its own buffers and
//! marks and a walk seeded by the point, so a probe's result depends on the triangulation and
//! the point only. Its cavity comes out owned ([`OwnedCavity`]) and is inserted later
//! ([`Delaunay::insert_owned`]) if it is still the point's cavity then: no tet of it and no
//! tet across its boundary removed since the probe ([`Delaunay::track_removals`]). Then every
//! cavity tet still conflicts with the point and every tet across its boundary still does not,
//! so (the conflict region of a point being connected) it is the cavity a fresh search would
//! find.

use super::cavity::{CavityWatch, Marks, SearchBuffers};
use super::{BoundaryFace, Delaunay, DelaunayError, Inserted};
use glam::DVec3;

/// A probe's own buffers: the search lists and the marks of the tets it visited.
#[derive(Debug, Default)]
pub struct ProbeBuffers {
    search: SearchBuffers,
    marks: MarkTable,
}

/// What a shared probe found.
#[derive(Debug)]
pub enum SharedProbe {
    /// The point equals this vertex.
    Duplicate(u32),
    Cavity(OwnedCavity),
}

/// A point's cavity as a probe found it: the tets its insertion deletes and the cavity's
/// boundary faces (one new tet each).
#[derive(Debug, Clone)]
pub struct OwnedCavity {
    p: DVec3,
    tets: Vec<u32>,
    boundary: Vec<BoundaryFace>,
}

impl OwnedCavity {
    /// The probed point.
    #[inline]
    pub fn point(&self) -> DVec3 {
        self.p
    }
    /// The tets inserting the point deletes.
    #[inline]
    pub fn tets(&self) -> &[u32] {
        &self.tets
    }
    /// The cavity's boundary faces.
    #[inline]
    pub fn boundary(&self) -> &[BoundaryFace] {
        &self.boundary
    }

    /// Whether it is still the point's cavity in `dt`: no tet of it or across its boundary
    /// was removed since `dt` began tracking removals (which must be before the probe).
    pub fn intact(&self, dt: &Delaunay) -> bool {
        self.tets.iter().all(|&t| !dt.removed_since_tracking(t))
            && self
                .boundary
                .iter()
                .all(|f| !dt.removed_since_tracking(f.outer_tet()))
    }
}

impl Delaunay {
    /// The cavity a new point at `p` would have (as [`Delaunay::probe_watched`], `watch`
    /// seeing its boundary faces and able to stop the search: None), through a shared
    /// reference with the caller's buffers. The walk starts at `hint` (the last tet created
    /// when `hint` is not alive) and its random choices are seeded by `p`, so the result
    /// depends only on the triangulation and `p`.
    pub fn probe_shared<W: CavityWatch>(
        &self,
        p: DVec3,
        hint: u32,
        buf: &mut ProbeBuffers,
        watch: &mut W,
    ) -> Option<SharedProbe> {
        let start = if self.is_alive(hint) { hint } else { self.last };
        let start = self.walk(p, start, &mut walk_seed(p));
        if let Some(dup) = self.coincident_vertex(start, p) {
            return Some(SharedProbe::Duplicate(dup));
        }
        buf.marks.begin();
        // The would-be vertex ranks above every existing one, as a real insertion would.
        let rank = self.points.len() as u32;
        self.search_cavity(&mut buf.marks, &mut buf.search, p, rank, start, watch)
            .then(|| {
                SharedProbe::Cavity(OwnedCavity {
                    p,
                    tets: buf.search.cavity.clone(),
                    boundary: buf.search.boundary.clone(),
                })
            })
    }

    /// A tet whose closure contains `p` (or a hull tet with `p` strictly outside its hull
    /// face), walking from `hint` as [`Self::probe_shared`] does: through a shared reference.
    pub fn locate_shared(&self, p: DVec3, hint: u32) -> u32 {
        let start = if self.is_alive(hint) { hint } else { self.last };
        self.walk(p, start, &mut walk_seed(p))
    }

    /// Inserts `cavity`'s point with that cavity, which must still be intact
    /// ([`OwnedCavity::intact`]): the caller checks.
    pub fn insert_owned(&mut self, cavity: &OwnedCavity) -> Result<Inserted, DelaunayError> {
        debug_assert!(cavity.tets.iter().all(|&t| self.is_alive(t)));
        let id = self.push_vertex(cavity.p)?;
        let s = &mut self.scratch.search;
        s.cavity.clone_from(&cavity.tets);
        s.boundary.clone_from(&cavity.boundary);
        self.fill_cavity(id);
        self.n_vertices += 1;
        Ok(Inserted::New(id))
    }

    /// Starts recording which tets are removed (a new record: what an earlier one held is
    /// forgotten). One bit per tet slot.
    pub fn track_removals(&mut self) {
        let log = self.removals.get_or_insert_with(RemovalLog::default);
        for &w in &log.dirty {
            log.bits[w as usize] = 0;
        }
        log.dirty.clear();
    }

    /// Stops recording removals and frees the record.
    pub fn untrack_removals(&mut self) {
        self.removals = None;
    }

    /// Whether tet slot `t` was removed (its tet deleted, the slot maybe reused) since
    /// [`Self::track_removals`]; false when not tracking.
    #[inline]
    pub fn removed_since_tracking(&self, t: u32) -> bool {
        self.removals.as_ref().is_some_and(|log| log.get(t))
    }
}

/// The tet slots removed since tracking began: a bit per slot, and the words holding set
/// bits (so a new record clears only those).
#[derive(Debug, Clone, Default)]
pub(super) struct RemovalLog {
    bits: Vec<u64>,
    dirty: Vec<u32>,
}

impl RemovalLog {
    #[inline]
    pub(super) fn set(&mut self, t: u32) {
        let w = (t / 64) as usize;
        if w >= self.bits.len() {
            self.bits.resize(w + 1, 0);
        }
        if self.bits[w] == 0 {
            self.dirty.push(w as u32);
        }
        self.bits[w] |= 1 << (t % 64);
    }

    #[inline]
    fn get(&self, t: u32) -> bool {
        self.bits
            .get((t / 64) as usize)
            .is_some_and(|w| w & (1 << (t % 64)) != 0)
    }

    pub(super) fn memory_bytes(&self) -> usize {
        self.bits.capacity() * 8 + self.dirty.capacity() * 4
    }
}

/// The walk's random state for point `p`: a hash of its coordinates (nonzero).
fn walk_seed(p: DVec3) -> u32 {
    let h = p.x.to_bits() ^ p.y.to_bits().rotate_left(21) ^ p.z.to_bits().rotate_left(42);
    let h = h.wrapping_mul(0x9E37_79B9_7F4A_7C15);
    ((h >> 32) as u32) | 1
}

/// A search's marks in a hash table of the tets it visits (a mark array per thread would
/// cost a byte per tet each): open addressing with linear probing, emptied wholesale per
/// search by a generation stamp, doubled when half full.
#[derive(Debug, Default)]
struct MarkTable {
    slots: Vec<MarkSlot>,
    generation: u32,
    len: usize,
    shift: u32,
    /// The tet the last `get` looked up and the slot it found (a search reads a tet's mark,
    /// then sets it).
    last: std::cell::Cell<(u32, usize)>,
}

#[derive(Debug, Clone, Copy, Default)]
struct MarkSlot {
    tet: u32,
    stamp: u32,
    mark: u8,
}

impl MarkTable {
    const MIN_SLOTS: usize = 256;

    /// Empties the table for a new search.
    fn begin(&mut self) {
        self.last.set((u32::MAX, 0));
        if self.slots.is_empty() {
            self.resize(Self::MIN_SLOTS);
        }
        self.len = 0;
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.slots.fill(MarkSlot::default());
            self.generation = 1;
        }
    }

    fn resize(&mut self, n: usize) {
        self.last.set((u32::MAX, 0));
        let old = std::mem::replace(&mut self.slots, vec![MarkSlot::default(); n]);
        let generation = self.generation;
        self.shift = 32 - n.trailing_zeros();
        self.len = 0;
        for s in old.into_iter().filter(|s| s.stamp == generation) {
            *self.slot_mut(s.tet) = s;
            self.len += 1;
        }
    }

    /// The slot of tet `t`: its own, or the empty one where it would go.
    #[inline]
    fn find(&self, t: u32) -> usize {
        let mask = self.slots.len() - 1;
        let mut i = (t.wrapping_mul(0x9E37_79B1) >> self.shift) as usize;
        loop {
            let s = &self.slots[i];
            if s.stamp != self.generation || s.tet == t {
                return i;
            }
            i = (i + 1) & mask;
        }
    }

    fn slot_mut(&mut self, t: u32) -> &mut MarkSlot {
        let i = self.find(t);
        &mut self.slots[i]
    }
}

impl Marks for MarkTable {
    #[inline]
    fn get(&self, t: u32) -> u8 {
        let i = self.find(t);
        self.last.set((t, i));
        let s = &self.slots[i];
        if s.stamp == self.generation {
            s.mark
        } else {
            0
        }
    }

    #[inline]
    fn set(&mut self, t: u32, m: u8) {
        // Usually the slot `get` just found for `t` (its own, or the empty one for it).
        let i = match self.last.replace((u32::MAX, 0)) {
            (tet, i) if tet == t => i,
            _ => self.find(t),
        };
        if self.slots[i].stamp != self.generation {
            if 2 * (self.len + 1) > self.slots.len() {
                self.resize(2 * self.slots.len());
                return self.set(t, m);
            }
            self.len += 1;
        }
        self.slots[i] = MarkSlot {
            tet: t,
            stamp: self.generation,
            mark: m,
        };
    }

    #[inline(always)]
    fn prefetch(&self, _t: u32) {}

    /// Nothing to do: the next search starts a new generation.
    #[inline]
    fn clear(&mut self, _cavity: &[u32], _boundary: &[BoundaryFace]) {}
}

#[cfg(test)]
mod tests {
    use super::super::tests::{grid, uniform};
    use super::*;
    use crate::delaunay::Probe;

    fn sorted(mut v: Vec<u32>) -> Vec<u32> {
        v.sort_unstable();
        v
    }

    /// A shared probe finds the cavity the triangulation's own probe finds.
    #[test]
    fn shared_probe_finds_the_same_cavity() {
        for (points, queries) in [
            (uniform(3000, 7), uniform(200, 8)),
            (grid(8), uniform(200, 9).iter().map(|p| *p * 7.0).collect()),
        ] {
            let (mut dt, _) = Delaunay::from_points(&points).unwrap();
            let mut buf = ProbeBuffers::default();
            for &q in &queries {
                let shared = dt.probe_shared(q, 0, &mut buf, &mut super::super::cavity::NoWatch);
                let Some(SharedProbe::Cavity(c)) = shared else {
                    panic!("no cavity for {q}");
                };
                let Probe::Cavity(own) = dt.probe(q, Some(0)) else {
                    panic!("duplicate {q}");
                };
                let (tets, faces) = dt.cavity(&own);
                assert_eq!(sorted(c.tets().to_vec()), sorted(tets.to_vec()));
                assert_eq!(c.boundary().len(), faces.len());
            }
        }
    }

    /// Cavities probed together and inserted one after another while intact give a valid
    /// Delaunay triangulation; the ones left out are exactly those a removal touched.
    #[test]
    fn intact_cavities_insert_into_a_valid_triangulation() {
        let (mut dt, _) = Delaunay::from_points(&uniform(2000, 3)).unwrap();
        let queries = uniform(400, 4);
        dt.track_removals();
        let mut buf = ProbeBuffers::default();
        let cavities: Vec<OwnedCavity> = queries
            .iter()
            .filter_map(|&q| {
                match dt.probe_shared(q, 0, &mut buf, &mut super::super::cavity::NoWatch) {
                    Some(SharedProbe::Cavity(c)) => Some(c),
                    _ => None,
                }
            })
            .collect();
        let (mut inserted, mut stale) = (0, 0);
        for c in &cavities {
            if c.intact(&dt) {
                dt.insert_owned(c).unwrap();
                inserted += 1;
            } else {
                stale += 1;
            }
        }
        dt.validate().unwrap();
        assert!(
            inserted > 100 && stale > 10,
            "{inserted} inserted, {stale} stale"
        );
        assert_eq!(dt.num_vertices(), 2000 + inserted);
        dt.untrack_removals();
        assert!(!dt.removed_since_tracking(0));
    }
}
