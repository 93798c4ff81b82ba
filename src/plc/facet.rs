//! One facet at a time: index checks, planarity, polygon simplicity, which part of the plane
//! the facet covers (outer polygons minus hole polygons and hole points), and its
//! triangulation into initial subfacets.
//!
//! The facet is triangulated by spade's constrained Delaunay triangulation of the projected
//! vertices with every polygon edge as a constraint; the covered triangles are then found by
//! flood fill (TetGen's rule): triangles reachable from outside the convex hull, from inside
//! a hole polygon, or from a hole point without crossing a polygon edge are not covered.
//! No Steiner points are added, so every triangle is a triple of input vertex ids.

use super::error::{PlcError, PolygonKind, PolygonRef};
use super::exact::{orient2d, segments_meet_2d, shared_end_overlap_2d, P2};
use super::plane::{fit_plane, Fit, Plane};
use super::Facet;
use crate::geom::check_coordinate;
use glam::DVec3;
use rustc_hash::{FxHashMap, FxHashSet};
use spade::handles::{FixedDirectedEdgeHandle, FixedFaceHandle, FixedVertexHandle, InnerTag};
use spade::{ConstrainedDelaunayTriangulation, Point2, PositionInTriangulation, Triangulation};
use std::cmp::Ordering;

/// One boundary loop of a checked facet, oriented with the facet on its left seen from the
/// tip of the facet normal: outer loops counter-clockwise, hole loops clockwise.
#[derive(Debug, Clone, PartialEq)]
pub struct FacetLoop {
    pub vertices: Vec<u32>,
    pub is_hole: bool,
}

/// A checked facet.
#[derive(Debug, Clone, PartialEq)]
pub struct PlcFacet {
    pub marker: i32,
    pub plane: Plane,
    /// The boundary of the covered region (outer loops and hole loops).
    pub loops: Vec<FacetLoop>,
    /// Input polygon edges with the facet on both sides (they are still segments).
    pub interior_edges: Vec<[u32; 2]>,
    /// Triangulation of the covered region (no new vertices), counter-clockwise seen from the
    /// tip of the normal.
    pub triangles: Vec<[u32; 3]>,
    /// Area of the covered region (sum of the triangle areas).
    pub area: f64,
    /// For each triangle, the cell on its normal side and on its other side
    /// (indices into `Plc::cells`).
    pub triangle_cells: Vec<[u32; 2]>,
}

impl PlcFacet {
    /// Area enclosed by the loops (outer minus holes), from the loops alone; equals `area`
    /// when the triangulation covers exactly the polygon.
    pub fn polygon_area(&self, vertices: &[DVec3]) -> f64 {
        let o = self.plane.point;
        let mut twice = 0.0;
        for l in &self.loops {
            let n = l.vertices.len();
            for i in 0..n {
                let a = vertices[l.vertices[i] as usize] - o;
                let b = vertices[l.vertices[(i + 1) % n] as usize] - o;
                twice += a.cross(b).dot(self.plane.normal);
            }
        }
        twice / 2.0
    }

    /// All polygon edges of the facet (loop edges and interior edges), sorted vertex pairs.
    pub fn segments(&self) -> impl Iterator<Item = [u32; 2]> + '_ {
        let sorted = |a: u32, b: u32| [a.min(b), a.max(b)];
        self.loops
            .iter()
            .flat_map(move |l| {
                let n = l.vertices.len();
                (0..n).map(move |i| sorted(l.vertices[i], l.vertices[(i + 1) % n]))
            })
            .chain(self.interior_edges.iter().map(move |e| sorted(e[0], e[1])))
    }
}

/// A polygon edge in facet-local vertex ids, with where it came from.
struct LocalEdge {
    a: usize,
    b: usize,
    from: PolygonRef,
}

type Cdt = ConstrainedDelaunayTriangulation<Point2<f64>>;

/// Checks facet `k` of an input on its own (indices, polygon sizes, repeated vertices,
/// coordinates, planarity, simple polygons, holes) and triangulates it. Surface-level checks
/// (closure, facet intersections) need [`super::validate`]. `triangle_cells` is left empty.
pub fn build_facet(k: usize, facet: &Facet, vertices: &[DVec3]) -> Result<PlcFacet, PlcError> {
    if let Some(triangle) = lone_triangle(k, facet, vertices)? {
        return Ok(triangle);
    }
    if facet.polygons.is_empty() {
        return Err(PlcError::EmptyFacet { facet: k });
    }
    let polygons: Vec<(PolygonRef, &[u32])> = facet
        .polygons
        .iter()
        .enumerate()
        .map(|(i, p)| (PolygonKind::Outer, i, p))
        .chain(
            facet
                .hole_polygons
                .iter()
                .enumerate()
                .map(|(i, p)| (PolygonKind::Hole, i, p)),
        )
        .map(|(kind, index, p)| {
            let r = PolygonRef {
                facet: k,
                kind,
                index,
            };
            (r, p.as_slice())
        })
        .collect();
    for &(r, p) in &polygons {
        check_polygon(r, p, vertices.len())?;
    }
    // One-vertex outer polygons are lone points: vertices of the triangulation, no edges.
    let (lone, polygons): (Vec<_>, Vec<_>) = polygons.into_iter().partition(|(_, p)| p.len() == 1);
    if polygons
        .first()
        .is_none_or(|(r, _)| r.kind != PolygonKind::Outer)
    {
        return Err(PlcError::EmptyFacet { facet: k });
    }

    if let Some(triangle) = single_triangle(k, facet, &polygons, &lone, vertices)? {
        return Ok(triangle);
    }
    triangulate(k, facet, &polygons, &lone, vertices)
}

/// [`build_facet`] for a facet that is one triangle and nothing else, without the general
/// path's lists (the checks and the result are the same): None when the facet is anything
/// else or [`single_triangle`] leaves it to the general path.
fn lone_triangle(
    k: usize,
    facet: &Facet,
    vertices: &[DVec3],
) -> Result<Option<PlcFacet>, PlcError> {
    let [p] = facet.polygons.as_slice() else {
        return Ok(None);
    };
    if p.len() != 3 || !facet.hole_polygons.is_empty() || !facet.hole_points.is_empty() {
        return Ok(None);
    }
    let r = PolygonRef {
        facet: k,
        kind: PolygonKind::Outer,
        index: 0,
    };
    check_polygon(r, p, vertices.len())?;
    single_triangle(k, facet, &[(r, p.as_slice())], &[], vertices)
}

/// The general path of [`build_facet`], after the per-polygon checks: the plane, the
/// simplicity checks and spade's constrained Delaunay triangulation.
fn triangulate(
    k: usize,
    facet: &Facet,
    polygons: &[(PolygonRef, &[u32])],
    lone: &[(PolygonRef, &[u32])],
    vertices: &[DVec3],
) -> Result<PlcFacet, PlcError> {
    // Facet-local vertex numbering, in order of first appearance.
    let mut global: Vec<u32> = Vec::new();
    let mut local: FxHashMap<u32, usize> = FxHashMap::default();
    for &(_, p) in polygons.iter().chain(lone) {
        for &v in p {
            local.entry(v).or_insert_with(|| {
                global.push(v);
                global.len() - 1
            });
        }
    }
    let points: Vec<DVec3> = global.iter().map(|&v| vertices[v as usize]).collect();
    let first: Vec<DVec3> = polygons[0]
        .1
        .iter()
        .map(|&v| vertices[v as usize])
        .collect();
    let fit = checked_plane(k, &global, &points, &first)?;
    let plane = fit.plane;
    let p2: Vec<P2> = points.iter().map(|&p| plane.project(p)).collect();
    check_coincident(k, &p2, &global)?;

    let mut edges: Vec<LocalEdge> = Vec::new();
    let mut seen: FxHashSet<(usize, usize)> = FxHashSet::default();
    for &(r, p) in polygons {
        for i in 0..p.len() {
            let (a, b) = (local[&p[i]], local[&p[(i + 1) % p.len()]]);
            // The same edge in two polygons of one facet is one constraint.
            if seen.insert((a.min(b), a.max(b))) {
                edges.push(LocalEdge { a, b, from: r });
            }
        }
    }
    check_simple(&p2, &edges, &global)?;
    check_lone_points_off_edges(lone, &p2, &edges, &local)?;

    let cdt = Cdt::bulk_load_cdt(
        p2.iter().map(|p| Point2::new(p[0], p[1])).collect(),
        edges.iter().map(|e| [e.a, e.b]).collect(),
    )
    .expect("coordinates were range-checked before triangulation");
    debug_assert_eq!(cdt.num_vertices(), p2.len());

    for (h, &point) in facet.hole_points.iter().enumerate() {
        let distance = plane.distance(point).abs();
        // A non-finite point is rejected here, before it could reach the point location.
        if check_coordinate(point).is_err() || distance > fit.tolerance {
            return Err(PlcError::HolePointOffPlane {
                facet: k,
                hole: h,
                point,
                distance,
            });
        }
    }
    let outside = classify_faces(k, facet, polygons, &cdt, &p2, &local, &plane)?;
    let (loops, interior_edges) = boundary_loops(&cdt, &edges, &outside, &global, &p2)?;

    let mut triangles = Vec::new();
    let mut area = 0.0;
    for f in cdt.inner_faces() {
        if outside[f.fix().index()] {
            continue;
        }
        let t = f.vertices().map(|v| global[v.fix().index()]);
        let [a, b, c] = t.map(|v| vertices[v as usize]);
        area += (b - a).cross(c - a).length() / 2.0;
        triangles.push(t);
    }
    check_lone_points_covered(lone, &triangles)?;
    let facet = PlcFacet {
        marker: facet.marker,
        plane,
        loops,
        interior_edges,
        triangles,
        area,
        triangle_cells: Vec::new(),
    };
    debug_assert!(
        (facet.polygon_area(vertices) - area).abs() <= 1e-9 * area.max(f64::MIN_POSITIVE),
        "facet {k}: triangles do not tile the polygon"
    );
    Ok(facet)
}

/// Checks a facet's vertex coordinates and fits its plane: `global` are the facet's vertex
/// ids, `points` their positions, `first` the positions of its first polygon in order (they
/// orient the normal).
fn checked_plane(
    k: usize,
    global: &[u32],
    points: &[DVec3],
    first: &[DVec3],
) -> Result<Fit, PlcError> {
    // `validate` checks all vertices first; repeated here so `build_facet` is safe alone.
    for (&v, &p) in global.iter().zip(points) {
        check_coordinate(p).map_err(|reason| PlcError::BadCoordinate {
            vertex: v as usize,
            coords: p,
            reason,
        })?;
    }
    let fit = fit_plane(points, first);
    if fit.degenerate {
        return Err(PlcError::DegenerateFacet { facet: k });
    }
    if fit.worst.1 > fit.tolerance {
        let v = global[fit.worst.0];
        return Err(PlcError::NonPlanarFacet {
            facet: k,
            vertex: v,
            coords: points[fit.worst.0],
            distance: fit.worst.1,
            tolerance: fit.tolerance,
        });
    }
    Ok(fit)
}

/// The fast path of [`build_facet`] for a facet that is one triangle and nothing else (almost
/// every facet of a triangulated surface): the triangle is its own triangulation, so spade is
/// not called. `None` when the facet is anything else, or when its projection is not a
/// counter-clockwise triangle (then the general path decides, errors included).
///
/// The result is exactly what [`triangulate`] gives, vertex order included (the area and
/// everything downstream read the triangle in that order; test
/// `single_triangles_match_the_general_path`): the loop is the polygon, and spade's one inner
/// face starts at the vertex [`spade_first_corner`] names.
fn single_triangle(
    k: usize,
    facet: &Facet,
    polygons: &[(PolygonRef, &[u32])],
    lone: &[(PolygonRef, &[u32])],
    vertices: &[DVec3],
) -> Result<Option<PlcFacet>, PlcError> {
    let tri: [u32; 3] = match polygons {
        [(_, p)] if lone.is_empty() && facet.hole_points.is_empty() => match (*p).try_into() {
            Ok(t) => t,
            Err(_) => return Ok(None),
        },
        _ => return Ok(None),
    };
    let points = tri.map(|v| vertices[v as usize]);
    let fit = checked_plane(k, &tri, &points, &points)?;
    let plane = fit.plane;
    let p2 = points.map(|p| plane.project(p));
    if orient2d(p2[0], p2[1], p2[2]) != Ordering::Greater {
        return Ok(None);
    }
    let first = spade_first_corner(&p2);
    let t = [0, 1, 2].map(|i| tri[(first + i) % 3]);
    let [a, b, c] = t.map(|v| vertices[v as usize]);
    let area = (b - a).cross(c - a).length() / 2.0;
    Ok(Some(PlcFacet {
        marker: facet.marker,
        plane,
        loops: vec![FacetLoop {
            vertices: tri.to_vec(),
            is_hole: twice_signed_area(&[0, 1, 2], &p2) < 0.0,
        }],
        interior_edges: Vec::new(),
        triangles: vec![t],
        area,
        triangle_cells: Vec::new(),
    }))
}

/// The corner spade 2.15's bulk loading starts the one inner face of a counter-clockwise
/// triangle at: it inserts the points nearest first to their mean (squared distance, ties by
/// larger x, then larger y) and the face starts at the last one inserted. Computed with
/// spade's own arithmetic (sum from zero, times 1/3) so that ties come out the same.
fn spade_first_corner(p: &[P2; 3]) -> usize {
    let sum = p.iter().fold([0.0, 0.0], |s, q| [s[0] + q[0], s[1] + q[1]]);
    let centre = [sum[0] * (1.0 / 3.0), sum[1] * (1.0 / 3.0)];
    let distance = |q: P2| {
        let (dx, dy) = (centre[0] - q[0], centre[1] - q[1]);
        dx * dx + dy * dy
    };
    // The first in spade's order (farthest, then smallest x, then smallest y) is inserted last.
    let inserted_later = |i: usize, j: usize| {
        let (di, dj) = (distance(p[i]), distance(p[j]));
        di > dj || (di == dj && (p[i][0], p[i][1]) < (p[j][0], p[j][1]))
    };
    (1..3).fold(0, |best, i| if inserted_later(i, best) { i } else { best })
}

/// Twice the signed area of the loop `lp` (local ids into `p2`), by the shoelace formula
/// relative to its first vertex, to limit cancellation.
fn twice_signed_area(lp: &[usize], p2: &[P2]) -> f64 {
    let o = p2[lp[0]];
    (0..lp.len())
        .map(|i| {
            let (a, b) = (p2[lp[i]], p2[lp[(i + 1) % lp.len()]]);
            (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
        })
        .sum()
}

/// Index range, length and repeated vertices of one polygon.
fn check_polygon(r: PolygonRef, p: &[u32], num_vertices: usize) -> Result<(), PlcError> {
    for (position, &index) in p.iter().enumerate() {
        if index as usize >= num_vertices {
            return Err(PlcError::IndexOutOfRange {
                polygon: r,
                position,
                index,
                num_vertices,
            });
        }
    }
    let lone_point = p.len() == 1 && r.kind == PolygonKind::Outer;
    if p.len() < 3 && !lone_point {
        return Err(PlcError::TooFewVertices {
            polygon: r,
            count: p.len(),
        });
    }
    // Short polygons (nearly all) are sorted on the stack.
    let mut short = [0u32; 16];
    let mut long;
    let sorted: &mut [u32] = if p.len() <= short.len() {
        let s = &mut short[..p.len()];
        s.copy_from_slice(p);
        s
    } else {
        long = p.to_vec();
        &mut long
    };
    sorted.sort_unstable();
    if let Some(w) = sorted.windows(2).find(|w| w[0] == w[1]) {
        return Err(PlcError::RepeatedVertex {
            polygon: r,
            vertex: w[0],
        });
    }
    Ok(())
}

/// A lone point exactly on a polygon edge (exact, in the projection every check here uses).
fn check_lone_points_off_edges(
    lone: &[(PolygonRef, &[u32])],
    p2: &[P2],
    edges: &[LocalEdge],
    local: &FxHashMap<u32, usize>,
) -> Result<(), PlcError> {
    for &(r, p) in lone {
        let q = p2[local[&p[0]]];
        let on = |e: &LocalEdge| {
            let (a, b) = (p2[e.a], p2[e.b]);
            let within = |i: usize| a[i].min(b[i]) <= q[i] && q[i] <= a[i].max(b[i]);
            // The box test first: it settles almost every edge without the predicate.
            within(0) && within(1) && orient2d(a, b, q) == Ordering::Equal
        };
        if edges.iter().any(on) {
            return Err(PlcError::LonePointOffFacet {
                polygon: r,
                vertex: p[0],
                on_edge: true,
            });
        }
    }
    Ok(())
}

/// A lone point that no covered triangle uses lies outside the facet (or in a hole).
fn check_lone_points_covered(
    lone: &[(PolygonRef, &[u32])],
    triangles: &[[u32; 3]],
) -> Result<(), PlcError> {
    let used: FxHashSet<u32> = triangles.iter().flatten().copied().collect();
    match lone.iter().find(|(_, p)| !used.contains(&p[0])) {
        Some(&(r, p)) => Err(PlcError::LonePointOffFacet {
            polygon: r,
            vertex: p[0],
            on_edge: false,
        }),
        None => Ok(()),
    }
}

fn lex(a: P2, b: P2) -> Ordering {
    a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1]))
}

/// Distinct vertices must stay distinct in the projection (rounding could merge them).
fn check_coincident(k: usize, p2: &[P2], global: &[u32]) -> Result<(), PlcError> {
    let mut order: Vec<usize> = (0..p2.len()).collect();
    order.sort_by(|&i, &j| lex(p2[i], p2[j]));
    for w in order.windows(2) {
        if p2[w[0]] == p2[w[1]] {
            let (a, b) = (global[w[0]], global[w[1]]);
            return Err(PlcError::CoincidentInPlane {
                facet: k,
                first: a.min(b),
                second: a.max(b),
            });
        }
    }
    Ok(())
}

/// No two polygon edges of the facet may meet except at a shared endpoint (sort and sweep
/// along x, exact tests).
fn check_simple(p2: &[P2], edges: &[LocalEdge], global: &[u32]) -> Result<(), PlcError> {
    let lo_x = |e: &LocalEdge| p2[e.a][0].min(p2[e.b][0]);
    let hi_x = |e: &LocalEdge| p2[e.a][0].max(p2[e.b][0]);
    let mut order: Vec<usize> = (0..edges.len()).collect();
    order.sort_by(|&i, &j| lo_x(&edges[i]).total_cmp(&lo_x(&edges[j])));
    let mut active: Vec<usize> = Vec::new();
    for &i in &order {
        let e = &edges[i];
        active.retain(|&j| hi_x(&edges[j]) >= lo_x(e));
        for &j in &active {
            let f = &edges[j];
            let (ylo, yhi) = (p2[e.a][1].min(p2[e.b][1]), p2[e.a][1].max(p2[e.b][1]));
            if p2[f.a][1].max(p2[f.b][1]) < ylo || p2[f.a][1].min(p2[f.b][1]) > yhi {
                continue;
            }
            let clash = if let Some((p, a, d)) = shared_endpoint(e, f) {
                shared_end_overlap_2d(p2[p], p2[a], p2[d])
            } else {
                segments_meet_2d(p2[e.a], p2[e.b], p2[f.a], p2[f.b])
            };
            if clash {
                let name = |x: &LocalEdge| (x.from, [global[x.a], global[x.b]]);
                let (first, second) = if (f.from.kind, f.from.index) <= (e.from.kind, e.from.index)
                {
                    (name(f), name(e))
                } else {
                    (name(e), name(f))
                };
                return Err(PlcError::EdgesIntersect { first, second });
            }
        }
        active.push(i);
    }
    Ok(())
}

/// (shared, other end of e, other end of f) when the edges share exactly one endpoint.
fn shared_endpoint(e: &LocalEdge, f: &LocalEdge) -> Option<(usize, usize, usize)> {
    if e.a == f.a {
        Some((e.a, e.b, f.b))
    } else if e.a == f.b {
        Some((e.a, e.b, f.a))
    } else if e.b == f.a {
        Some((e.b, e.a, f.b))
    } else if e.b == f.b {
        Some((e.b, e.a, f.a))
    } else {
        None
    }
}

/// Floods `outside` from `seeds` across edges that are not polygon edges.
type Face = FixedFaceHandle<InnerTag>;
type Edge<'a> = spade::handles::DirectedEdgeHandle<'a, Point2<f64>, (), spade::CdtEdge<()>, ()>;

/// Marks `seeds` outside and floods from them across edges that are not barriers.
fn flood(cdt: &Cdt, outside: &mut [bool], seeds: Vec<Face>, barrier: &dyn Fn(Edge) -> bool) {
    for f in &seeds {
        outside[f.index()] = true;
    }
    let mut stack = seeds;
    while let Some(f) = stack.pop() {
        for e in cdt.face(f).adjacent_edges() {
            if barrier(e) {
                continue;
            }
            if let Some(g) = e.rev().face().as_inner() {
                if !outside[g.fix().index()] {
                    outside[g.fix().index()] = true;
                    stack.push(g.fix());
                }
            }
        }
    }
}

fn directed(cdt: &Cdt, a: usize, b: usize) -> FixedDirectedEdgeHandle {
    cdt.get_edge_from_neighbors(
        FixedVertexHandle::from_index(a),
        FixedVertexHandle::from_index(b),
    )
    .expect("every polygon edge is a constraint edge of the triangulation")
    .fix()
}

/// Marks the faces of the triangulation that the facet does not cover (index 0 is spade's
/// outer face and is always outside).
fn classify_faces(
    k: usize,
    facet: &Facet,
    polygons: &[(PolygonRef, &[u32])],
    cdt: &Cdt,
    p2: &[P2],
    local: &FxHashMap<u32, usize>,
    plane: &Plane,
) -> Result<Vec<bool>, PlcError> {
    let mut outside = vec![false; cdt.num_all_faces()];
    outside[0] = true;
    // 1. Everything reachable from beyond the convex hull without crossing an outer polygon
    //    (hole polygons are no barrier yet, so a hole outside the outer polygons shows).
    let outer_edges: FxHashSet<(usize, usize)> = polygons
        .iter()
        .filter(|(r, _)| r.kind == PolygonKind::Outer)
        .flat_map(|(_, p)| {
            (0..p.len()).map(|i| {
                let (a, b) = (local[&p[i]], local[&p[(i + 1) % p.len()]]);
                (a.min(b), a.max(b))
            })
        })
        .collect();
    let outer_barrier = |e: Edge| {
        let (a, b) = (e.from().fix().index(), e.to().fix().index());
        outer_edges.contains(&(a.min(b), a.max(b)))
    };
    let any_barrier = |e: Edge| e.as_undirected().is_constraint_edge();
    let mut seeds = Vec::new();
    for f in cdt.inner_faces() {
        let hull_side = f
            .adjacent_edges()
            .iter()
            .any(|&e| e.rev().face().is_outer() && !outer_barrier(e));
        if hull_side {
            seeds.push(f.fix());
        }
    }
    flood(cdt, &mut outside, seeds, &outer_barrier);

    // 2. Inside each hole polygon; each must lie in what the outer polygons cover.
    let mut seeds = Vec::new();
    for &(r, p) in polygons.iter().filter(|(r, _)| r.kind == PolygonKind::Hole) {
        let ids: Vec<usize> = p.iter().map(|v| local[v]).collect();
        let ccw = loop_orientation(&ids, p2) == Ordering::Greater;
        for i in 0..ids.len() {
            let e = cdt.directed_edge(directed(cdt, ids[i], ids[(i + 1) % ids.len()]));
            let inner = if ccw { e.face() } else { e.rev().face() };
            match inner.as_inner() {
                Some(f) if !outside[f.fix().index()] => seeds.push(f.fix()),
                _ => return Err(PlcError::HoleOutsideFacet { polygon: r }),
            }
        }
    }
    flood(cdt, &mut outside, seeds, &any_barrier);

    // 3. Hole points, all located before any is flooded (several may share a hole).
    let mut seeds = Vec::new();
    for (h, &point) in facet.hole_points.iter().enumerate() {
        let q = plane.project(point);
        let face = match cdt.locate(Point2::new(q[0], q[1])) {
            PositionInTriangulation::OnFace(f) => Some(f),
            PositionInTriangulation::OnEdge(e) => {
                let e = cdt.directed_edge(e);
                if e.as_undirected().is_constraint_edge() {
                    return Err(PlcError::HolePointOnEdge {
                        facet: k,
                        hole: h,
                        point,
                    });
                }
                e.face().as_inner().map(|f| f.fix())
            }
            PositionInTriangulation::OnVertex(_) => {
                return Err(PlcError::HolePointOnEdge {
                    facet: k,
                    hole: h,
                    point,
                })
            }
            _ => None,
        };
        match face {
            Some(f) if !outside[f.index()] => seeds.push(f),
            _ => {
                return Err(PlcError::HolePointOutsideFacet {
                    facet: k,
                    hole: h,
                    point,
                })
            }
        }
    }
    flood(cdt, &mut outside, seeds, &any_barrier);
    Ok(outside)
}

/// Exact orientation of a simple polygon: the turn at its lexicographically smallest vertex
/// (a convex hull vertex whose neighbours cannot be collinear with it in a simple polygon).
fn loop_orientation(ids: &[usize], p2: &[P2]) -> Ordering {
    let n = ids.len();
    let m = (0..n).min_by(|&i, &j| lex(p2[ids[i]], p2[ids[j]])).unwrap();
    orient2d(p2[ids[(m + n - 1) % n]], p2[ids[m]], p2[ids[(m + 1) % n]])
}

/// Sorts polygon edges into region boundary (oriented, facet on the left) and interior edges,
/// then chains the boundary edges into loops.
fn boundary_loops(
    cdt: &Cdt,
    edges: &[LocalEdge],
    outside: &[bool],
    global: &[u32],
    p2: &[P2],
) -> Result<(Vec<FacetLoop>, Vec<[u32; 2]>), PlcError> {
    let mut next: FxHashMap<usize, Vec<usize>> = FxHashMap::default();
    let mut interior = Vec::new();
    let mut count = 0;
    for e in edges {
        let d = cdt.directed_edge(directed(cdt, e.a, e.b));
        let left = !outside[d.face().fix().index()];
        let right = !outside[d.rev().face().fix().index()];
        match (left, right) {
            (true, true) => interior.push([global[e.a], global[e.b]]),
            (false, false) => {
                return Err(PlcError::EdgeOutsideFacet {
                    polygon: e.from,
                    edge: [global[e.a], global[e.b]],
                })
            }
            (true, false) => next.entry(e.a).or_default().push(e.b),
            (false, true) => next.entry(e.b).or_default().push(e.a),
        }
        count += usize::from(left != right);
    }
    // The boundary of a union of triangles is a cycle: in-degree = out-degree everywhere.
    let mut starts: Vec<usize> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut loops = Vec::new();
    let mut used = 0;
    for s in starts {
        while let Some(mut v) = next.get_mut(&s).and_then(|o| o.pop()) {
            let mut lp = vec![s];
            used += 1;
            while v != s {
                lp.push(v);
                v = next
                    .get_mut(&v)
                    .and_then(|o| o.pop())
                    .expect("facet boundary is a cycle");
                used += 1;
            }
            loops.push(FacetLoop {
                vertices: lp.iter().map(|&i| global[i]).collect(),
                is_hole: twice_signed_area(&lp, p2) < 0.0,
            });
        }
    }
    debug_assert_eq!(used, count);
    Ok((loops, interior))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The general path on the same facet, for comparison.
    fn general(facet: &Facet, vertices: &[DVec3]) -> Result<PlcFacet, PlcError> {
        let r = PolygonRef {
            facet: 0,
            kind: PolygonKind::Outer,
            index: 0,
        };
        triangulate(0, facet, &[(r, &facet.polygons[0])], &[], vertices)
    }

    /// The fast path for one-triangle facets gives what spade's triangulation gives, bit for
    /// bit, corner order included: random triangles in every orientation, on a coarse grid
    /// (many ties in spade's distance order) and at random coordinates.
    #[test]
    fn single_triangles_match_the_general_path() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let mut fast = 0;
        for round in 0..20_000 {
            let coordinate = |rng: &mut rand_chacha::ChaCha8Rng| match round % 3 {
                0 => rng.gen_range(-2..=2) as f64,
                1 => rng.gen_range(-20..=20) as f64 * 0.1,
                _ => rng.gen_range(-1.0..1.0) * 1e3,
            };
            let vertices: Vec<DVec3> = (0..3)
                .map(|_| {
                    let x = coordinate(&mut rng);
                    let y = coordinate(&mut rng);
                    let z = coordinate(&mut rng);
                    DVec3::new(x, y, z)
                })
                .collect();
            let facet = Facet {
                polygons: vec![vec![0, 1, 2]],
                marker: 7,
                ..Facet::default()
            };
            let expected = general(&facet, &vertices);
            let got = build_facet(0, &facet, &vertices);
            assert_eq!(got, expected, "{vertices:?}");
            let r = PolygonRef {
                facet: 0,
                kind: PolygonKind::Outer,
                index: 0,
            };
            let one = [(r, facet.polygons[0].as_slice())];
            fast += usize::from(matches!(
                single_triangle(0, &facet, &one, &[], &vertices),
                Ok(Some(_))
            ));
        }
        // Collinear draws fail both ways; every other draw takes the fast path.
        assert!(fast > 15_000, "{fast}");
    }
}
