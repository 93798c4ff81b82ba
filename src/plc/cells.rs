//! The volumes the surface encloses: which side of which facet triangle faces which cell,
//! how large each cell is, and which cells the hole and region seeds select.
//!
//! Method: every triangle has two sides. Around each segment the incident triangles are sorted
//! by angle (exact `orient3d` comparisons); consecutive triangles bound one wedge, so the
//! sides facing that wedge belong to the same cell. Union–find over sides gives *shells*
//! (connected boundary pieces of one cell). A shell's signed volume (divergence theorem,
//! outward normals) is positive iff it is the outer boundary of a bounded cell; a negative
//! shell is an inner boundary (a cavity wall, or the outside of the whole surface) and
//! belongs to the innermost positive shell enclosing it, found by exact ray parity. The
//! sign of a shell volume is the one floating-point decision here.

use super::error::{PlcError, Seed};
use super::exact::{orient3, point_in_triangle_3d};
use super::topology::{sorted, FanEntry, Topology};
use super::Region;
use crate::union_find::UnionFind;
use glam::DVec3;
use rustc_hash::FxHashSet;
use std::cmp::Ordering;

/// What a cell is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CellKind {
    /// The unbounded outside.
    Exterior,
    /// A bounded cell removed by `PlcInput::holes[seed]`.
    Hole { seed: usize },
    /// A bounded cell to be meshed, with the index of its region seed if one lies in it.
    Domain { region: Option<usize> },
}

/// A connected component of space minus the surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cell {
    /// Enclosed volume (infinite for the exterior).
    pub volume: f64,
    pub kind: CellKind,
}

/// Cells plus the cell on each side of every global triangle ([normal side, other side]).
pub(crate) struct CellMap {
    pub cells: Vec<Cell>,
    pub triangle_cells: Vec<[u32; 2]>,
}

/// Side ids: 2t is the normal (+) side of global triangle t, 2t + 1 the other side.
fn side(t: u32, plus: bool) -> u32 {
    2 * t + u32::from(!plus)
}

/// Builds the cells, fills every segment's fan, and applies the seeds.
pub(crate) fn build_cells(
    vertices: &[DVec3],
    topo: &mut Topology,
    holes: &[DVec3],
    regions: &[Region],
) -> Result<CellMap, PlcError> {
    let ntri = topo.tris.len() as u32;
    let mut uf = UnionFind::new(2 * ntri as usize);
    let mut fans: Vec<Vec<(u32, u32)>> = vec![Vec::new(); topo.segments.len()]; // (tri, ccw side)
    for (edge, users) in &topo.edge_tris {
        let Some(&s) = topo.segment_of.get(edge) else {
            // An edge inside one facet: both triangles are wound alike, so like sides meet.
            debug_assert_eq!(users.len(), 2);
            uf.union(side(users[0], true), side(users[1], true));
            uf.union(side(users[0], false), side(users[1], false));
            continue;
        };
        let [u, v] = *edge;
        let forward = |t: u32| {
            let tv = topo.tris[t as usize].2;
            (0..3).any(|i| tv[i] == u && tv[(i + 1) % 3] == v)
        };
        let third = |t: u32| {
            let tv = topo.tris[t as usize].2;
            vertices[*tv.iter().find(|&&x| x != u && x != v).unwrap() as usize]
        };
        let (pu, pv) = (vertices[u as usize], vertices[v as usize]);
        // One or two triangles have only one order (the edges of a manifold surface: all but
        // a few), and no list to allocate.
        let sorted_order;
        let order: &[usize] = if users.len() <= 2 {
            &[0, 1][..users.len()]
        } else {
            let thirds: Vec<DVec3> = users.iter().map(|&t| third(t)).collect();
            sorted_order = radial_order(pu, pv, &thirds);
            &sorted_order
        };
        let k = order.len();
        for i in 0..k {
            let (a, b) = (users[order[i]], users[order[(i + 1) % k]]);
            // The wedge after a (counter-clockwise about u→v) sees a's side towards which it
            // turns: the normal side iff a contains u→v. It sees b from b's other turn.
            let sa = side(a, forward(a));
            let sb = side(b, !forward(b));
            uf.union(sa, sb);
            fans[s].push((a, sa));
        }
    }

    // Shells and their signed volumes.
    let (lo, hi) = bounds(vertices);
    let origin = (lo + hi) / 2.0;
    let mut shell_of = vec![u32::MAX; 2 * ntri as usize];
    let mut shells: Vec<Shell> = Vec::new();
    for sd in 0..2 * ntri {
        let r = uf.find(sd);
        if shell_of[r as usize] == u32::MAX {
            shell_of[r as usize] = shells.len() as u32;
            shells.push(Shell::default());
        }
        let sh = shell_of[r as usize];
        shell_of[sd as usize] = sh;
        let t = sd / 2;
        let [a, b, c] = topo.tris[t as usize]
            .2
            .map(|x| vertices[x as usize] - origin);
        let det = a.dot(b.cross(c)) / 6.0;
        let shell = &mut shells[sh as usize];
        // The normal of the + side points into the cell it faces: outward is the other way.
        shell.volume += if sd % 2 == 0 { -det } else { det };
        shell.tris.push(t);
    }
    for shell in &mut shells {
        shell.finish(vertices, &topo.tris);
    }

    // One bounded cell per positive shell; negative shells join the innermost enclosing one.
    let mut cells = vec![Cell {
        volume: f64::INFINITY,
        kind: CellKind::Exterior,
    }];
    let mut cell_of_shell = vec![0u32; shells.len()];
    let mut positive: Vec<usize> = Vec::new();
    for (i, sh) in shells.iter().enumerate() {
        if sh.volume > 0.0 {
            cell_of_shell[i] = cells.len() as u32;
            positive.push(i);
            cells.push(Cell {
                volume: sh.volume,
                kind: CellKind::Domain { region: None },
            });
        }
    }
    // Innermost first, so the first enclosing shell found is the answer.
    positive.sort_by(|&a, &b| shells[a].volume.total_cmp(&shells[b].volume));
    for n in 0..shells.len() {
        if shells[n].volume > 0.0 {
            continue;
        }
        let parent = positive.iter().copied().find(|&p| {
            shells[p].contains_box(&shells[n])
                && shell_encloses_shell(vertices, topo, &shells[p], &shells[n])
        });
        if let Some(p) = parent {
            let c = cell_of_shell[p];
            cell_of_shell[n] = c;
            cells[c as usize].volume += shells[n].volume;
        }
    }

    apply_seeds(
        vertices,
        topo,
        &shells,
        &positive,
        &cell_of_shell,
        &mut cells,
        holes,
        regions,
    )?;

    for (s, fan) in fans.into_iter().enumerate() {
        topo.segments[s].fan = fan
            .into_iter()
            .map(|(t, sd)| {
                let (facet, triangle, _) = topo.tris[t as usize];
                FanEntry {
                    facet,
                    triangle,
                    cell_after: cell_of_shell[shell_of[sd as usize] as usize],
                }
            })
            .collect();
    }
    let triangle_cells = (0..ntri)
        .map(|t| [true, false].map(|plus| cell_of_shell[shell_of[side(t, plus) as usize] as usize]))
        .collect();
    Ok(CellMap {
        cells,
        triangle_cells,
    })
}

/// Bounding box of all vertices.
pub(crate) fn bounds(vertices: &[DVec3]) -> (DVec3, DVec3) {
    vertices.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    )
}

#[derive(Default)]
struct Shell {
    volume: f64,
    /// Global triangle ids, once per side in the shell (a triangle with both sides in the
    /// same cell appears twice, which keeps ray parity right).
    tris: Vec<u32>,
    verts: FxHashSet<u32>,
    lo: DVec3,
    hi: DVec3,
}

impl Shell {
    fn finish(&mut self, vertices: &[DVec3], tris: &[(u32, u32, [u32; 3])]) {
        self.verts = self.tris.iter().flat_map(|&t| tris[t as usize].2).collect();
        let pts: Vec<DVec3> = self.verts.iter().map(|&v| vertices[v as usize]).collect();
        (self.lo, self.hi) = bounds(&pts);
    }
    fn contains_box(&self, other: &Shell) -> bool {
        self.lo.cmple(other.lo).all() && self.hi.cmpge(other.hi).all()
    }
}

/// Sorts the third vertices of the triangles around the axis u→v, counter-clockwise, starting
/// from `w[0]`. Exact: half-plane classification and `orient3d` comparisons.
fn radial_order(u: DVec3, v: DVec3, w: &[DVec3]) -> Vec<usize> {
    // Starting from w[0], one or two triangles have only one order (the edges of a manifold
    // surface: all but a few).
    if w.len() <= 2 {
        return (0..w.len()).collect();
    }
    // A point off the plane (u, v, w0) tells the two half-planes of that plane apart.
    let q = off_plane_point(u, v, w[0]);
    let ref_side = orient3(u, v, q, w[0]);
    let half = |x: DVec3| match orient3(u, v, w[0], x) {
        Ordering::Greater => 0,
        Ordering::Less => 1,
        Ordering::Equal if orient3(u, v, q, x) == ref_side => 0,
        Ordering::Equal => 1,
    };
    let halves: Vec<u8> = w.iter().map(|&x| half(x)).collect();
    let mut order: Vec<usize> = (0..w.len()).collect();
    order.sort_by(|&i, &j| {
        // Within a half-turn, j is ahead of i iff (u, v, w_i, w_j) is positively oriented.
        halves[i]
            .cmp(&halves[j])
            .then_with(|| orient3(u, v, w[j], w[i]))
    });
    let start = order.iter().position(|&i| i == 0).unwrap();
    order.rotate_left(start);
    order
}

fn off_plane_point(u: DVec3, v: DVec3, w: DVec3) -> DVec3 {
    let n = (v - u).cross(w - u);
    let scale = (v - u).length().max((w - u).length());
    let candidates = [
        u + n.normalize_or_zero() * scale,
        u + DVec3::X * scale,
        u + DVec3::Y * scale,
        u + DVec3::Z * scale,
    ];
    candidates
        .into_iter()
        .find(|&q| orient3(u, v, w, q) != Ordering::Equal)
        .expect("some point near a non-degenerate triangle lies off its plane")
}

enum Crossing {
    Yes,
    No,
    Degenerate,
}

/// Does the segment x→far cross triangle abc? x is known not to lie on the triangle.
fn crossing(x: DVec3, far: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Crossing {
    let of = orient3(a, b, c, far);
    if of == Ordering::Equal {
        return Crossing::Degenerate;
    }
    let ox = orient3(a, b, c, x);
    if ox == Ordering::Equal || ox == of {
        return Crossing::No;
    }
    let o = [
        orient3(x, far, a, b),
        orient3(x, far, b, c),
        orient3(x, far, c, a),
    ];
    if o.contains(&Ordering::Less) && o.contains(&Ordering::Greater) {
        Crossing::No
    } else if o.contains(&Ordering::Equal) {
        Crossing::Degenerate
    } else {
        Crossing::Yes
    }
}

/// Ray parity of point x against a shell: Some(true) if enclosed, None if x lies on it.
fn encloses(vertices: &[DVec3], topo: &Topology, shell: &Shell, x: DVec3) -> Option<bool> {
    let tri = |t: u32| topo.tris[t as usize].2.map(|i| vertices[i as usize]);
    for &t in &shell.tris {
        let [a, b, c] = tri(t);
        if point_in_triangle_3d(x, a, b, c) {
            return None;
        }
    }
    let reach = 2.0 * ((shell.hi - shell.lo).length() + (x - (shell.lo + shell.hi) / 2.0).length());
    // Rays in irrational-ish directions; retry when one grazes an edge or vertex exactly.
    for attempt in 0..64u32 {
        let f = attempt as f64;
        let theta = std::f64::consts::TAU * ((0.1234 + f * 0.618_033_988_749_895) % 1.0);
        let z = ((0.5678 + f * 0.754_877_666_246_692_7) % 1.0) * 2.0 - 1.0;
        let r = (1.0 - z * z).sqrt();
        let far = x + DVec3::new(r * theta.cos(), r * theta.sin(), z) * reach;
        let mut odd = false;
        let mut degenerate = false;
        for &t in &shell.tris {
            let [a, b, c] = tri(t);
            match crossing(x, far, a, b, c) {
                Crossing::Yes => odd = !odd,
                Crossing::No => {}
                Crossing::Degenerate => {
                    degenerate = true;
                    break;
                }
            }
        }
        if !degenerate {
            return Some(odd);
        }
    }
    panic!("encloses: every ray from {x} grazed the surface")
}

/// Is the (negative) shell `n` inside the region enclosed by the (positive) shell `p`?
/// Decided at a point of `n` that is not on `p`: a vertex, else an edge midpoint, else a
/// triangle centroid. If `n` lies entirely on `p`, they are two sides of one surface and the
/// negative side faces away from the enclosed region.
fn shell_encloses_shell(vertices: &[DVec3], topo: &Topology, p: &Shell, n: &Shell) -> bool {
    let tri = |t: u32| topo.tris[t as usize].2;
    let p_tris: FxHashSet<u32> = p.tris.iter().copied().collect();
    let vertex_points = n
        .verts
        .iter()
        .filter(|v| !p.verts.contains(v))
        .map(|&v| vertices[v as usize]);
    // Only midpoints of edges not on p: a rounded midpoint of p's own edge may fall on
    // either side of p.
    let edges = |t: u32| {
        let tv = tri(t);
        (0..3).map(move |i| sorted(tv[i], tv[(i + 1) % 3]))
    };
    let p_edges: FxHashSet<[u32; 2]> = p.tris.iter().flat_map(|&t| edges(t)).collect();
    let midpoints = n
        .tris
        .iter()
        .flat_map(|&t| edges(t))
        .filter(|e| !p_edges.contains(e))
        .map(|e| (vertices[e[0] as usize] + vertices[e[1] as usize]) / 2.0);
    let centroids = n.tris.iter().filter(|t| !p_tris.contains(t)).map(|&t| {
        tri(t)
            .map(|i| vertices[i as usize])
            .into_iter()
            .sum::<DVec3>()
            / 3.0
    });
    vertex_points
        .chain(midpoints)
        .chain(centroids)
        .find_map(|x| encloses(vertices, topo, p, x))
        .unwrap_or(false)
}

/// Which cell holds x? The innermost positive shell enclosing it (exterior if none).
fn locate(
    vertices: &[DVec3],
    topo: &Topology,
    shells: &[Shell],
    positive: &[usize],
    cell_of_shell: &[u32],
    x: DVec3,
) -> u32 {
    positive
        .iter()
        .find(|&&p| {
            let s = &shells[p];
            x.cmpge(s.lo).all()
                && x.cmple(s.hi).all()
                && encloses(vertices, topo, s, x) == Some(true)
        })
        .map_or(0, |&p| cell_of_shell[p])
}

#[allow(clippy::too_many_arguments)]
fn apply_seeds(
    vertices: &[DVec3],
    topo: &Topology,
    shells: &[Shell],
    positive: &[usize],
    cell_of_shell: &[u32],
    cells: &mut [Cell],
    holes: &[DVec3],
    regions: &[Region],
) -> Result<(), PlcError> {
    let (lo, hi) = bounds(vertices);
    let place = |seed: Seed, x: DVec3| -> Result<u32, PlcError> {
        if !(x.cmpge(lo).all() && x.cmple(hi).all()) {
            return Err(PlcError::SeedOutsideBoundingBox { seed, point: x });
        }
        for &(f, _, t) in &topo.tris {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            if point_in_triangle_3d(x, a, b, c) {
                return Err(PlcError::SeedOnFacet {
                    seed,
                    point: x,
                    facet: f as usize,
                });
            }
        }
        match locate(vertices, topo, shells, positive, cell_of_shell, x) {
            0 => Err(PlcError::SeedOutsideDomain { seed, point: x }),
            c => Ok(c),
        }
    };
    for (h, &x) in holes.iter().enumerate() {
        let c = place(Seed::Hole(h), x)?;
        if !matches!(cells[c as usize].kind, CellKind::Hole { .. }) {
            cells[c as usize].kind = CellKind::Hole { seed: h };
        }
    }
    for (r, reg) in regions.iter().enumerate() {
        let c = place(Seed::Region(r), reg.point)? as usize;
        match cells[c].kind {
            CellKind::Hole { seed } => {
                return Err(PlcError::RegionInHole {
                    region: r,
                    hole: seed,
                })
            }
            CellKind::Domain { region: Some(q) } => {
                let same =
                    regions[q].attribute == reg.attribute && regions[q].max_size == reg.max_size;
                if !same {
                    return Err(PlcError::ConflictingRegions {
                        first: q,
                        second: r,
                    });
                }
            }
            _ => cells[c].kind = CellKind::Domain { region: Some(r) },
        }
    }
    if !cells
        .iter()
        .any(|c| matches!(c.kind, CellKind::Domain { .. }))
    {
        return Err(PlcError::EmptyDomain);
    }
    Ok(())
}
