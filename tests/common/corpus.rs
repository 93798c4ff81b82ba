//! Closed triangle surfaces generated at test time (deterministic, nothing stored): shapes the
//! approximate surface mode has not been tuned on, each with the volume it encloses, a writer
//! for the .off or ASCII STL file the CLI reads, and a sampled two-sided Hausdorff distance
//! that does not use the crate's own surface code.
//!
//! Every body is outward-oriented, closed, 2-manifold and free of self-intersections; the
//! sizes of the thin and near-contact features are fractions of the file's bounding-box
//! diagonal, the scale the CLI's default distance bound (0.001 x diagonal) is taken from.

use slivermesh::surface::oracle::closest_on_triangle;
use slivermesh::DVec3;
use std::collections::{HashMap, HashSet};
use std::f64::consts::PI;

/// One closed, outward-oriented triangle surface (or several, when appended).
#[derive(Debug, Clone, Default)]
pub struct Surface {
    pub vertices: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Surface {
    /// Signed enclosed volume, by the divergence theorem (positive for outward orientation).
    pub fn volume(&self) -> f64 {
        let six_v: f64 = self
            .triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| self.vertices[v as usize]);
                a.dot(b.cross(c))
            })
            .sum();
        six_v / 6.0
    }

    /// Total triangle area.
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                (b - a).cross(c - a).length() / 2.0
            })
            .sum()
    }

    pub fn bbox(&self) -> (DVec3, DVec3) {
        self.vertices.iter().fold(
            (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
            |(l, h), &p| (l.min(p), h.max(p)),
        )
    }

    pub fn diagonal(&self) -> f64 {
        let (lo, hi) = self.bbox();
        (hi - lo).length()
    }

    /// Reverses every triangle.
    pub fn flip(&mut self) {
        for t in &mut self.triangles {
            t.swap(1, 2);
        }
    }

    /// Flips the surface if it encloses a negative volume (generators build either way).
    fn orient_outward(mut self) -> Surface {
        if self.volume() < 0.0 {
            self.flip();
        }
        self
    }

    /// Adds `other`'s triangles on their own vertices (a disjoint union in one vertex list).
    pub fn append(&mut self, other: &Surface) {
        let base = self.vertices.len() as u32;
        self.vertices.extend_from_slice(&other.vertices);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|v| v + base)));
    }

    pub fn corners(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|v| self.vertices[v as usize])
    }

    /// The triangles `keep` accepts, without the vertices no kept triangle uses (renumbered
    /// in order of first use).
    pub fn keep_triangles(&self, keep: impl Fn(usize) -> bool) -> Surface {
        let mut id = vec![u32::MAX; self.vertices.len()];
        let mut out = Surface::default();
        for (k, t) in self.triangles.iter().enumerate() {
            if !keep(k) {
                continue;
            }
            let t = t.map(|v| {
                if id[v as usize] == u32::MAX {
                    id[v as usize] = out.vertices.len() as u32;
                    out.vertices.push(self.vertices[v as usize]);
                }
                id[v as usize]
            });
            out.triangles.push(t);
        }
        out
    }

    /// Checks that the surface is a closed, consistently oriented 2-manifold: every directed
    /// edge is used once and its reverse once, no triangle is degenerate, no two vertices share
    /// a position (an STL reader identifies vertices by position), every vertex is used.
    pub fn check_closed_manifold(&self) -> Result<(), String> {
        let mut directed: HashMap<[u32; 2], u32> = HashMap::new();
        let mut used = vec![false; self.vertices.len()];
        for (k, t) in self.triangles.iter().enumerate() {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                return Err(format!("triangle {k} {t:?} repeats a vertex"));
            }
            let [a, b, c] = self.corners(k);
            if (b - a).cross(c - a).length_squared() == 0.0 {
                return Err(format!("triangle {k} {t:?} has zero area"));
            }
            for i in 0..3 {
                used[t[i] as usize] = true;
                let e = [t[i], t[(i + 1) % 3]];
                *directed.entry(e).or_default() += 1;
            }
        }
        for (e, &n) in &directed {
            if n != 1 {
                return Err(format!("directed edge {e:?} used {n} times"));
            }
            if directed.get(&[e[1], e[0]]) != Some(&1) {
                return Err(format!("edge {e:?} has no opposite half-edge"));
            }
        }
        if let Some(v) = used.iter().position(|&u| !u) {
            return Err(format!("vertex {v} is used by no triangle"));
        }
        let mut seen: HashMap<[u64; 3], usize> = HashMap::new();
        for (i, p) in self.vertices.iter().enumerate() {
            if let Some(j) = seen.insert(p.to_array().map(f64::to_bits), i) {
                return Err(format!("vertices {j} and {i} share the position {p}"));
            }
        }
        Ok(())
    }

    /// Connected components (through shared vertices) and Euler characteristic V - E + F of
    /// the used vertices, edges and triangles.
    pub fn topology(&self) -> (usize, i64) {
        topology(&self.triangles, self.vertices.len())
    }

    /// The surface as OFF text (vertices as Rust prints them: shortest round-trip decimal).
    pub fn off_text(&self) -> String {
        let mut s = format!("OFF\n{} {} 0\n", self.vertices.len(), self.triangles.len());
        for p in &self.vertices {
            s.push_str(&format!("{} {} {}\n", p.x, p.y, p.z));
        }
        for t in &self.triangles {
            s.push_str(&format!("3 {} {} {}\n", t[0], t[1], t[2]));
        }
        s
    }

    /// One ASCII STL `solid` block.
    pub fn stl_solid(&self, name: &str) -> String {
        let mut s = format!("solid {name}\n");
        for k in 0..self.triangles.len() {
            let [a, b, c] = self.corners(k);
            let n = (b - a).cross(c - a).normalize();
            s.push_str(&format!(
                "  facet normal {} {} {}\n    outer loop\n",
                n.x, n.y, n.z
            ));
            for p in [a, b, c] {
                s.push_str(&format!("      vertex {} {} {}\n", p.x, p.y, p.z));
            }
            s.push_str("    endloop\n  endfacet\n");
        }
        s.push_str(&format!("endsolid {name}\n"));
        s
    }
}

/// Components and Euler characteristic of a triangle set over `n_vertices` vertex ids.
pub fn topology(triangles: &[[u32; 3]], n_vertices: usize) -> (usize, i64) {
    let mut parent: Vec<u32> = (0..n_vertices as u32).collect();
    fn find(parent: &mut [u32], mut v: u32) -> u32 {
        while parent[v as usize] != v {
            parent[v as usize] = parent[parent[v as usize] as usize];
            v = parent[v as usize];
        }
        v
    }
    let mut used = vec![false; n_vertices];
    let mut edges = std::collections::HashSet::new();
    for t in triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            used[a as usize] = true;
            edges.insert([a.min(b), a.max(b)]);
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            parent[ra as usize] = rb;
        }
    }
    let n_used = used.iter().filter(|&&u| u).count();
    let components = (0..n_vertices as u32)
        .filter(|&v| used[v as usize] && find(&mut parent, v) == v)
        .count();
    let euler = n_used as i64 - edges.len() as i64 + triangles.len() as i64;
    (components, euler)
}

/// Edges (by vertex ids) not shared by exactly two triangles.
pub fn edges_not_in_two(triangles: &[[u32; 3]]) -> usize {
    let mut count: HashMap<[u32; 2], u32> = HashMap::new();
    for t in triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *count.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    count.values().filter(|&&n| n != 2).count()
}

/// Vertices whose triangles do not form one fan around them (sheets touching at a point).
pub fn pinched_vertices(triangles: &[[u32; 3]], n_vertices: usize) -> Vec<u32> {
    // Each vertex's link: the edge opposite it in each of its triangles.
    let mut link: Vec<Vec<[u32; 2]>> = vec![Vec::new(); n_vertices];
    for t in triangles {
        for i in 0..3 {
            link[t[i] as usize].push([t[(i + 1) % 3], t[(i + 2) % 3]]);
        }
    }
    let connected = |l: &[[u32; 2]]| {
        let mut reached = vec![false; l.len()];
        let mut stack = vec![0];
        reached[0] = true;
        while let Some(i) = stack.pop() {
            for j in 0..l.len() {
                if !reached[j] && l[j].iter().any(|x| l[i].contains(x)) {
                    reached[j] = true;
                    stack.push(j);
                }
            }
        }
        reached.iter().all(|&r| r)
    };
    (0..n_vertices)
        .filter(|&v| !link[v].is_empty() && !connected(&link[v]))
        .map(|v| v as u32)
        .collect()
}

/// A test shape: one or several closed bodies written to one file.
#[derive(Debug, Clone)]
pub struct Shape {
    pub name: &'static str,
    /// Each closed body, outward-oriented (a single-body shape has one).
    pub solids: Vec<Surface>,
    /// Written as ASCII STL with one `solid` per body (touching bodies: their common faces
    /// appear once per body, with opposite orientations) instead of one .off.
    pub stl: bool,
    /// Volume of each part of the domain: each body, or for nested and touching bodies each
    /// region between them; from the triangles by the divergence theorem.
    pub part_volumes: Vec<f64>,
    /// Volume of the smooth or exact shape the triangles describe, and the relative difference
    /// allowed between it and the triangles' volume (the tessellation's deficit).
    pub analytic_volume: Option<(f64, f64)>,
    /// Area of the faces between two regions (0 for one body or bodies apart).
    pub interface_area: f64,
}

impl Shape {
    fn single(name: &'static str, s: Surface, analytic_volume: Option<(f64, f64)>) -> Shape {
        Shape {
            name,
            part_volumes: vec![s.volume()],
            solids: vec![s],
            stl: false,
            analytic_volume,
            interface_area: 0.0,
        }
    }

    pub fn file_name(&self) -> String {
        format!("{}.{}", self.name, if self.stl { "stl" } else { "off" })
    }

    pub fn file_text(&self) -> String {
        if self.stl {
            self.solids
                .iter()
                .enumerate()
                .map(|(k, s)| s.stl_solid(&format!("{}_{k}", self.name)))
                .collect()
        } else {
            self.all().off_text()
        }
    }

    /// Every body's triangles in one surface, vertices at equal positions merged; a triangle
    /// two bodies share (an interface, listed the other way round by the second) once.
    pub fn all(&self) -> Surface {
        let mut s = Surface::default();
        let mut ids: HashMap<[u64; 3], u32> = HashMap::new();
        let mut seen: HashSet<[u32; 3]> = HashSet::new();
        for b in &self.solids {
            for t in &b.triangles {
                let t = t.map(|v| {
                    let p = b.vertices[v as usize];
                    *ids.entry(p.to_array().map(f64::to_bits))
                        .or_insert_with(|| {
                            s.vertices.push(p);
                            s.vertices.len() as u32 - 1
                        })
                });
                let mut key = t;
                key.sort_unstable();
                if seen.insert(key) {
                    s.triangles.push(t);
                }
            }
        }
        s
    }

    pub fn n_triangles(&self) -> usize {
        self.solids.iter().map(|s| s.triangles.len()).sum()
    }

    /// Volume of the whole domain.
    pub fn volume(&self) -> f64 {
        self.part_volumes.iter().sum()
    }
}

/// The single-body shapes.
pub fn single_body() -> Vec<Shape> {
    vec![
        noisy_sphere(),
        thin_box_plate(),
        thin_ellipsoid_fin(),
        near_contact(),
        torus_thin(),
    ]
}

/// The shapes of several bodies or regions.
pub fn multi_body() -> Vec<Shape> {
    vec![
        two_bodies(),
        half_balls(),
        sphere_in_box(),
        two_touching_blocks_stl(),
        three_regions_edge(),
    ]
}

pub fn all() -> Vec<Shape> {
    let mut v = single_body();
    v.extend(multi_body());
    v
}

// ---------------------------------------------------------------------------------------------
// Generators.

/// A bumpy sphere r(theta, phi) = 1 + 0.15 sin(3 theta) cos(2 phi) (theta polar) on a level-6
/// icosphere (81,920 triangles), every vertex then moved along its normal by uniform noise of
/// amplitude 0.1% of the bounding-box diagonal (a scanned surface).
pub fn noisy_sphere() -> Shape {
    const EPS: f64 = 0.15;
    let mut s = icosphere(6);
    for p in &mut s.vertices {
        let theta = p.z.clamp(-1.0, 1.0).acos();
        let phi = p.y.atan2(p.x);
        *p *= 1.0 + EPS * (3.0 * theta).sin() * (2.0 * phi).cos();
    }
    let amplitude = 1e-3 * s.diagonal();
    let normals = vertex_normals(&s);
    let mut rng = XorShift(0x9e37_79b9_7f4a_7c15);
    for (p, n) in s.vertices.iter_mut().zip(normals) {
        *p += n * (amplitude * rng.symmetric());
    }
    // (1/3) integral of r^3 over the sphere: the linear and cubic terms in EPS integrate to 0,
    // the quadratic one to 3 EPS^2 (36 pi / 35).
    let exact = 4.0 * PI / 3.0 + EPS * EPS * 36.0 * PI / 35.0;
    Shape::single("noisy_sphere", s, Some((exact, 5e-4)))
}

/// A 1 x 1 x t box whose thickness t is 1/100 of its diagonal, each face cut into a grid
/// (1,152 triangles).
pub fn thin_box_plate() -> Shape {
    // t = sqrt(2 + t^2) / 100.
    let t = (2e-4f64 / (1.0 - 1e-4)).sqrt();
    let s = grid_box(DVec3::ZERO, DVec3::new(1.0, 1.0, t), [16, 16, 1]);
    Shape::single("thin_box_plate", s, Some((t, 1e-12)))
}

/// An ellipsoid with semi-axes 0.5, 0.5, c whose thickness 2c is 1/100 of its diagonal, on a
/// latitude-longitude grid (10,528 triangles); the rim is a ring of vertices.
pub fn thin_ellipsoid_fin() -> Shape {
    let a = 0.5;
    // 2c = sqrt(8 a^2 + 4 c^2) / 100.
    let c = a * (2e-4f64 / (1.0 - 1e-4)).sqrt();
    let (n_lat, n_lon) = (48, 112);
    let mut rows = vec![Row::Pole(DVec3::new(0.0, 0.0, c))];
    for k in 1..n_lat {
        let theta = PI * k as f64 / n_lat as f64;
        rows.push(Row::Ring(
            (0..n_lon)
                .map(|j| {
                    let phi = 2.0 * PI * j as f64 / n_lon as f64;
                    DVec3::new(
                        a * theta.sin() * phi.cos(),
                        a * theta.sin() * phi.sin(),
                        c * theta.cos(),
                    )
                })
                .collect(),
        ));
    }
    rows.push(Row::Pole(DVec3::new(0.0, 0.0, -c)));
    let s = stitch_rows(&rows, false);
    Shape::single(
        "thin_ellipsoid_fin",
        s,
        Some((4.0 / 3.0 * PI * a * a * c, 3e-3)),
    )
}

/// A bent capsule: the points within rho = 0.25 of a circular arc of radius 1 that leaves a
/// gap at +x, its two round tips facing each other across diag / 200 without touching (one
/// connected, smooth body; the closest points of the tips are vertices, so the triangles'
/// gap is exactly diag / 200). About 21k triangles.
pub fn near_contact() -> Shape {
    let (big_r, rho) = (1.0, 0.25);
    // The arc's half-opening phi0 and the diagonal depend on each other: iterate.
    let mut phi0: f64 = 0.3;
    let mut s = bent_capsule(big_r, rho, phi0);
    for _ in 0..50 {
        let gap = s.diagonal() / 200.0;
        let next = ((gap + 2.0 * rho) / (2.0 * big_r)).asin();
        let done = (next - phi0).abs() <= 1e-15;
        phi0 = next;
        s = bent_capsule(big_r, rho, phi0);
        if done {
            break;
        }
    }
    // Pappus for the tube, plus the two hemispheres.
    let exact = PI * rho * rho * big_r * (2.0 * PI - 2.0 * phi0) + 4.0 / 3.0 * PI * rho.powi(3);
    Shape::single("near_contact", s, Some((exact, 5e-3)))
}

/// The near-contact gap of [`near_contact`]'s surface: the smallest distance between a vertex
/// of one tip (y > 0, x > 0) and one of the other (y < 0, x > 0).
pub fn tip_gap(s: &Surface) -> f64 {
    let tip = |sign: f64| -> Vec<DVec3> {
        s.vertices
            .iter()
            .copied()
            .filter(|p| p.x > 0.5 && p.y * sign > 0.0)
            .collect()
    };
    let (a, b) = (tip(1.0), tip(-1.0));
    a.iter()
        .flat_map(|p| b.iter().map(move |q| p.distance(*q)))
        .fold(f64::MAX, f64::min)
}

/// A torus of major radius 1 whose minor radius is 1/60 of its diagonal (7,680 triangles).
pub fn torus_thin() -> Shape {
    let big_r: f64 = 1.0;
    // r = sqrt(8 (R + r)^2 + 4 r^2) / 60: a contraction, iterated to convergence.
    let mut r: f64 = 0.05;
    for _ in 0..100 {
        r = (8.0 * (big_r + r).powi(2) + 4.0 * r * r).sqrt() / 60.0;
    }
    let (n_major, n_minor) = (160, 24);
    let rows: Vec<Row> = (0..n_major)
        .map(|i| {
            let phi = 2.0 * PI * i as f64 / n_major as f64;
            let (er, ez) = (DVec3::new(phi.cos(), phi.sin(), 0.0), DVec3::Z);
            Row::Ring(
                (0..n_minor)
                    .map(|j| {
                        let psi = 2.0 * PI * j as f64 / n_minor as f64;
                        er * (big_r + r * psi.cos()) + ez * (r * psi.sin())
                    })
                    .collect(),
            )
        })
        .collect();
    let s = stitch_rows(&rows, true);
    Shape::single(
        "torus_thin",
        s,
        Some((2.0 * PI * PI * big_r * r * r, 1.5e-2)),
    )
}

/// Two disjoint unit spheres (level-4 icospheres, 5,120 triangles each) 0.5 apart, in one .off.
pub fn two_bodies() -> Shape {
    let mut a = icosphere(4);
    let mut b = a.clone();
    for p in &mut a.vertices {
        p.x -= 1.25;
    }
    for p in &mut b.vertices {
        p.x += 1.25;
    }
    let exact = 2.0 * 4.0 / 3.0 * PI;
    Shape {
        name: "two_bodies",
        part_volumes: vec![a.volume(), b.volume()],
        solids: vec![a, b],
        stl: false,
        analytic_volume: Some((exact, 3e-3)),
        interface_area: 0.0,
    }
}

/// A box [-1.5, 1.5]^3 with a unit sphere inside it, both oriented out of their own body, in
/// one .off: two regions, the sphere and the shell between it and the box.
pub fn sphere_in_box() -> Shape {
    let b = grid_box(DVec3::splat(-1.5), DVec3::splat(1.5), [4, 4, 4]);
    let s = icosphere(4);
    let interface_area = s.area();
    Shape {
        name: "sphere_in_box",
        interface_area,
        part_volumes: vec![b.volume() - s.volume(), s.volume()],
        solids: vec![b, s],
        stl: false,
        analytic_volume: Some((27.0, 1e-12)),
    }
}

/// A ball cut by the plane z = 0 into two regions, in one .off: the two hemispheres and the
/// disk between them (16 rings a side, 64 around), which meets the sphere along the equator
/// (three faces at every equator edge). Solids: the upper and the lower half, each closed by
/// the disk.
pub fn half_balls() -> Shape {
    let (around, rings) = (64usize, 16usize);
    let mut vertices = vec![];
    let mut ring = |r: f64, z: f64| -> Vec<u32> {
        (0..around)
            .map(|k| {
                let a = 2.0 * PI * k as f64 / around as f64;
                vertices.push(DVec3::new(r * a.cos(), r * a.sin(), z));
                vertices.len() as u32 - 1
            })
            .collect()
    };
    // Rows from the equator inwards, each a ring; the last row closes at a centre vertex.
    let equator = ring(1.0, 0.0);
    let mut rows_of = |shape: &dyn Fn(usize) -> (f64, f64)| -> Vec<Vec<u32>> {
        let mut rows = vec![equator.clone()];
        rows.extend((1..rings).map(|i| {
            let (r, z) = shape(i);
            ring(r, z)
        }));
        rows
    };
    let angle = |i: usize| PI / 2.0 * i as f64 / rings as f64;
    let top = rows_of(&|i| (angle(i).cos(), angle(i).sin()));
    let bottom = rows_of(&|i| (angle(i).cos(), -angle(i).sin()));
    let disk = rows_of(&|i| (1.0 - i as f64 / rings as f64, 0.0));
    let mut centre = |p: DVec3| {
        vertices.push(p);
        vertices.len() as u32 - 1
    };
    let centres = [centre(DVec3::Z), centre(-DVec3::Z), centre(DVec3::ZERO)];
    // Triangles of the rows and their centre, counter-clockwise seen from +z.
    let fan = |rows: &[Vec<u32>], c: u32| -> Vec<[u32; 3]> {
        let mut t = vec![];
        for w in rows.windows(2) {
            for k in 0..around {
                let k1 = (k + 1) % around;
                t.push([w[0][k], w[0][k1], w[1][k1]]);
                t.push([w[0][k], w[1][k1], w[1][k]]);
            }
        }
        let last = rows.last().unwrap();
        t.extend((0..around).map(|k| [last[k], last[(k + 1) % around], c]));
        t
    };
    let flip =
        |t: Vec<[u32; 3]>| -> Vec<[u32; 3]> { t.into_iter().map(|[a, b, c]| [a, c, b]).collect() };
    let (up, down, lid) = (
        fan(&top, centres[0]),
        flip(fan(&bottom, centres[1])),
        fan(&disk, centres[2]),
    );
    let solid = |a: &[[u32; 3]], b: &[[u32; 3]]| {
        compact(Surface {
            vertices: vertices.clone(),
            triangles: a.iter().chain(b).copied().collect(),
        })
    };
    let upper = solid(&up, &flip(lid.clone()));
    let lower = solid(&down, &lid);
    let interface_area = compact(Surface {
        vertices: vertices.clone(),
        triangles: lid,
    })
    .area();
    Shape {
        name: "half_balls",
        part_volumes: vec![upper.volume(), lower.volume()],
        solids: vec![upper, lower],
        stl: false,
        analytic_volume: Some((4.0 / 3.0 * PI, 1e-2)),
        interface_area,
    }
}

/// `s` without the vertices no triangle uses, renumbered in order.
fn compact(s: Surface) -> Surface {
    s.keep_triangles(|_| true)
}

/// Two unit cubes sharing the face x = 1, as two STL solids: the common face appears in both,
/// triangulated the same way, with opposite orientations.
pub fn two_touching_blocks_stl() -> Shape {
    let a = grid_box(DVec3::ZERO, DVec3::ONE, [2, 2, 2]);
    let b = grid_box(DVec3::X, DVec3::new(2.0, 1.0, 1.0), [2, 2, 2]);
    Shape {
        name: "two_touching_blocks",
        part_volumes: vec![a.volume(), b.volume()],
        solids: vec![a, b],
        stl: true,
        analytic_volume: Some((2.0, 1e-12)),
        interface_area: 1.0,
    }
}

/// A unit hexagonal prism (height 1) cut into three rhombic prisms that meet along its axis,
/// as three STL solids: each interface appears once per adjacent solid.
pub fn three_regions_edge() -> Shape {
    let hex = |k: usize| {
        let a = PI / 3.0 * (k % 6) as f64;
        DVec3::new(a.cos(), a.sin(), 0.0)
    };
    let solids: Vec<Surface> = (0..3)
        .map(|k| {
            let base = [DVec3::ZERO, hex(2 * k), hex(2 * k + 1), hex(2 * k + 2)];
            convex_prism(&base, 1.0)
        })
        .collect();
    Shape {
        name: "three_regions_edge",
        part_volumes: solids.iter().map(Surface::volume).collect(),
        solids,
        stl: true,
        analytic_volume: Some((1.5 * 3f64.sqrt(), 1e-12)),
        interface_area: 3.0,
    }
}

// ---------------------------------------------------------------------------------------------
// Building blocks.

/// Deterministic noise (xorshift64*).
struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in [-1, 1).
    fn symmetric(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// The unit icosahedron subdivided `level` times, vertices projected onto the unit sphere
/// (20 * 4^level triangles).
pub fn icosphere(level: u32) -> Surface {
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut vertices: Vec<DVec3> = [
        [-1.0, g, 0.0],
        [1.0, g, 0.0],
        [-1.0, -g, 0.0],
        [1.0, -g, 0.0],
        [0.0, -1.0, g],
        [0.0, 1.0, g],
        [0.0, -1.0, -g],
        [0.0, 1.0, -g],
        [g, 0.0, -1.0],
        [g, 0.0, 1.0],
        [-g, 0.0, -1.0],
        [-g, 0.0, 1.0],
    ]
    .iter()
    .map(|&p| DVec3::from_array(p).normalize())
    .collect();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut mid: HashMap<[u32; 2], u32> = HashMap::new();
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for t in &triangles {
            let m = [0, 1, 2].map(|i| {
                let (a, b) = (t[i], t[(i + 1) % 3]);
                *mid.entry([a.min(b), a.max(b)]).or_insert_with(|| {
                    let p = (vertices[a as usize] + vertices[b as usize]).normalize();
                    vertices.push(p);
                    vertices.len() as u32 - 1
                })
            });
            next.push([t[0], m[0], m[2]]);
            next.push([t[1], m[1], m[0]]);
            next.push([t[2], m[2], m[1]]);
            next.push(m);
        }
        triangles = next;
    }
    Surface {
        vertices,
        triangles,
    }
    .orient_outward()
}

/// Area-weighted unit vertex normals.
fn vertex_normals(s: &Surface) -> Vec<DVec3> {
    let mut n = vec![DVec3::ZERO; s.vertices.len()];
    for (k, t) in s.triangles.iter().enumerate() {
        let [a, b, c] = s.corners(k);
        let w = (b - a).cross(c - a);
        for v in t {
            n[*v as usize] += w;
        }
    }
    n.into_iter().map(DVec3::normalize).collect()
}

/// One row of a latitude-longitude style grid: a single pole point or a ring of points.
enum Row {
    Pole(DVec3),
    Ring(Vec<DVec3>),
}

/// Triangulates consecutive rows (rings of equal length, poles joined by fans); `wrap` joins
/// the last row to the first (a torus), otherwise the first and last rows are poles.
fn stitch_rows(rows: &[Row], wrap: bool) -> Surface {
    let mut s = Surface::default();
    let ids: Vec<Vec<u32>> = rows
        .iter()
        .map(|r| {
            let pts: &[DVec3] = match r {
                Row::Pole(p) => std::slice::from_ref(p),
                Row::Ring(v) => v,
            };
            let first = s.vertices.len() as u32;
            s.vertices.extend_from_slice(pts);
            (first..s.vertices.len() as u32).collect()
        })
        .collect();
    let n_pairs = if wrap { rows.len() } else { rows.len() - 1 };
    for k in 0..n_pairs {
        let (a, b) = (&ids[k], &ids[(k + 1) % rows.len()]);
        match (a.len(), b.len()) {
            (1, n) => (0..n).for_each(|j| s.triangles.push([a[0], b[j], b[(j + 1) % n]])),
            (n, 1) => (0..n).for_each(|j| s.triangles.push([a[j], b[0], a[(j + 1) % n]])),
            (n, m) => {
                assert_eq!(n, m, "rings of different lengths");
                for j in 0..n {
                    let j1 = (j + 1) % n;
                    s.triangles.push([a[j], b[j], b[j1]]);
                    s.triangles.push([a[j], b[j1], a[j1]]);
                }
            }
        }
    }
    s.orient_outward()
}

/// The boundary of the points within `rho` of the arc of radius `big_r` (in the z = 0 plane,
/// centred at the origin) from angle phi0 to 2 pi - phi0: a tube with hemispherical tips.
fn bent_capsule(big_r: f64, rho: f64, phi0: f64) -> Surface {
    let (n_around, n_along, n_cap) = (48usize, 192usize, 12usize);
    let center = |phi: f64| DVec3::new(phi.cos(), phi.sin(), 0.0) * big_r;
    let radial = |phi: f64| DVec3::new(phi.cos(), phi.sin(), 0.0);
    let tangent = |phi: f64| DVec3::new(-phi.sin(), phi.cos(), 0.0);
    // Cross-section direction psi in the plane of the radial direction and z.
    let ring = |phi: f64, beta: f64, along: DVec3| -> Vec<DVec3> {
        (0..n_around)
            .map(|j| {
                let psi = 2.0 * PI * j as f64 / n_around as f64;
                let d = (radial(phi) * psi.cos() + DVec3::Z * psi.sin()) * beta.sin()
                    + along * beta.cos();
                center(phi) + d * rho
            })
            .collect()
    };
    // Polar angles of the tip rows from the pole (0) to the tube (pi/2). The direction from
    // one tip's centre towards the other's is at beta = phi0, psi = pi: a row there puts a
    // vertex on each tip's closest point.
    let k0 = 3;
    let betas: Vec<f64> = (0..=n_cap)
        .map(|k| {
            if k <= k0 {
                phi0 * k as f64 / k0 as f64
            } else {
                phi0 + (PI / 2.0 - phi0) * (k - k0) as f64 / (n_cap - k0) as f64
            }
        })
        .collect();
    let phi1 = 2.0 * PI - phi0;
    let mut rows = Vec::new();
    // Tip at the start of the arc (bulging along -tangent), pole first.
    let back = -tangent(phi0);
    rows.push(Row::Pole(center(phi0) + back * rho));
    for &b in &betas[1..] {
        rows.push(Row::Ring(ring(phi0, b, back)));
    }
    // The tube between the tips' last rings.
    for i in 1..n_along {
        let phi = phi0 + (phi1 - phi0) * i as f64 / n_along as f64;
        rows.push(Row::Ring(ring(phi, PI / 2.0, DVec3::ZERO)));
    }
    // Tip at the end of the arc, from the tube to the pole.
    let fore = tangent(phi1);
    for &b in betas[1..].iter().rev() {
        rows.push(Row::Ring(ring(phi1, b, fore)));
    }
    rows.push(Row::Pole(center(phi1) + fore * rho));
    stitch_rows(&rows, false)
}

/// Vertex ids by position, for grids whose shared edges are computed on both sides.
#[derive(Default)]
struct Welder {
    surface: Surface,
    ids: HashMap<[i64; 3], u32>,
}

impl Welder {
    fn vertex(&mut self, p: DVec3) -> u32 {
        // Positions computed along different faces agree to far better than 1e-9.
        let key = (p * 1e9).round().to_array().map(|x| x as i64);
        let s = &mut self.surface;
        *self.ids.entry(key).or_insert_with(|| {
            s.vertices.push(p);
            s.vertices.len() as u32 - 1
        })
    }

    /// The planar convex quad `c` (counter-clockwise seen from outside) cut into an n x m grid
    /// of cells, each split along the diagonal parallel to the one from the quad's
    /// lexicographically smallest corner: a face shared by two solids, listed in opposite
    /// orders, is cut the same way by both.
    fn quad(&mut self, c: [DVec3; 4], n: usize, m: usize) {
        let first = (0..4)
            .min_by(|&i, &j| c[i].to_array().partial_cmp(&c[j].to_array()).unwrap())
            .unwrap();
        let c: [DVec3; 4] = std::array::from_fn(|k| c[(k + first) % 4]);
        let (n, m) = if first % 2 == 0 { (n, m) } else { (m, n) };
        // Corners exactly (STL solids sharing a face must write the same coordinates).
        let mix = |a: DVec3, b: DVec3, i: usize, n: usize| match i {
            0 => a,
            _ if i == n => b,
            _ => a + (b - a) * (i as f64 / n as f64),
        };
        let at = |i: usize, j: usize| mix(mix(c[0], c[1], i, n), mix(c[3], c[2], i, n), j, m);
        for i in 0..n {
            for j in 0..m {
                let [a, b, cc, d] = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                    .map(|(x, y)| self.vertex(at(x, y)));
                self.surface.triangles.push([a, b, cc]);
                self.surface.triangles.push([a, cc, d]);
            }
        }
    }
}

/// The box [lo, hi], each face cut into the grid of the counts along its two axes.
pub fn grid_box(lo: DVec3, hi: DVec3, counts: [usize; 3]) -> Surface {
    let mut w = Welder::default();
    let corner = |x: usize, y: usize, z: usize| {
        DVec3::new([lo.x, hi.x][x], [lo.y, hi.y][y], [lo.z, hi.z][z])
    };
    let [nx, ny, nz] = counts;
    // Each face counter-clockwise seen from outside.
    let faces = [
        ([(0, 0, 0), (0, 1, 0), (1, 1, 0), (1, 0, 0)], ny, nx), // z = lo
        ([(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)], nx, ny), // z = hi
        ([(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)], nx, nz), // y = lo
        ([(0, 1, 0), (0, 1, 1), (1, 1, 1), (1, 1, 0)], nz, nx), // y = hi
        ([(0, 0, 0), (0, 0, 1), (0, 1, 1), (0, 1, 0)], nz, ny), // x = lo
        ([(1, 0, 0), (1, 1, 0), (1, 1, 1), (1, 0, 1)], ny, nz), // x = hi
    ];
    for (c, n, m) in faces {
        w.quad(c.map(|(x, y, z)| corner(x, y, z)), n, m);
    }
    w.surface.orient_outward()
}

/// The prism of height `h` over the convex polygon `base` (counter-clockwise from +z, in the
/// z = 0 plane), each face split into triangles without new vertices.
fn convex_prism(base: &[DVec3], h: f64) -> Surface {
    let mut w = Welder::default();
    let top: Vec<DVec3> = base.iter().map(|&p| p + DVec3::Z * h).collect();
    let n = base.len();
    assert_eq!(n, 4, "quadrilateral bases only");
    w.quad([base[0], base[3], base[2], base[1]], 1, 1);
    w.quad([top[0], top[1], top[2], top[3]], 1, 1);
    for k in 0..n {
        let k1 = (k + 1) % n;
        w.quad([base[k], base[k1], top[k1], top[k]], 1, 1);
    }
    w.surface.orient_outward()
}

// ---------------------------------------------------------------------------------------------
// Sampled Hausdorff distance (independent of the crate's surface module).

/// An AABB tree over triangles, for closest-point queries.
pub struct TriangleTree {
    tris: Vec<[DVec3; 3]>,
    nodes: Vec<Node>,
    order: Vec<u32>,
}

struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf (count > 0): `order[start..start + count]`; inner node (count 0): `start` and
    /// `right` are the children.
    start: u32,
    count: u32,
    right: u32,
}

const LEAF: usize = 4;

impl TriangleTree {
    pub fn new(s: &Surface) -> TriangleTree {
        let tris: Vec<[DVec3; 3]> = (0..s.triangles.len()).map(|k| s.corners(k)).collect();
        let mut t = TriangleTree {
            order: (0..tris.len() as u32).collect(),
            tris,
            nodes: Vec::new(),
        };
        let n = t.order.len();
        t.build(0, n);
        t
    }

    fn build(&mut self, start: usize, end: usize) -> u32 {
        let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
        let (mut clo, mut chi) = (lo, hi);
        for &k in &self.order[start..end] {
            let t = &self.tris[k as usize];
            for p in t {
                lo = lo.min(*p);
                hi = hi.max(*p);
            }
            let c = (t[0] + t[1] + t[2]) / 3.0;
            clo = clo.min(c);
            chi = chi.max(c);
        }
        let id = self.nodes.len() as u32;
        self.nodes.push(Node {
            lo,
            hi,
            start: start as u32,
            count: (end - start) as u32,
            right: 0,
        });
        if end - start <= LEAF {
            return id;
        }
        let ext = chi - clo;
        let axis = if ext.x >= ext.y && ext.x >= ext.z {
            0
        } else if ext.y >= ext.z {
            1
        } else {
            2
        };
        let mid = (start + end) / 2;
        let tris = &self.tris;
        let key = |k: &u32| {
            let t = &tris[*k as usize];
            (t[0] + t[1] + t[2])[axis]
        };
        self.order[start..end]
            .select_nth_unstable_by(mid - start, |a, b| key(a).partial_cmp(&key(b)).unwrap());
        let left = self.build(start, mid);
        let right = self.build(mid, end);
        let node = &mut self.nodes[id as usize];
        node.count = 0;
        node.start = left;
        node.right = right;
        id
    }

    /// Distance from `p` to the nearest triangle; `hint` (a triangle index, updated) starts
    /// the search near the previous query's answer.
    pub fn distance(&self, p: DVec3, hint: &mut usize) -> f64 {
        let mut best = f64::MAX;
        if *hint < self.tris.len() {
            let [a, b, c] = self.tris[*hint];
            best = p.distance_squared(closest_on_triangle(p, a, b, c));
        }
        let box_d2 = |n: &Node| {
            let d = (n.lo - p).max(p - n.hi).max(DVec3::ZERO);
            d.length_squared()
        };
        let mut stack = vec![0u32];
        while let Some(id) = stack.pop() {
            let n = &self.nodes[id as usize];
            if box_d2(n) >= best {
                continue;
            }
            if n.count > 0 {
                for &k in &self.order[n.start as usize..(n.start + n.count) as usize] {
                    let [a, b, c] = self.tris[k as usize];
                    let d2 = p.distance_squared(closest_on_triangle(p, a, b, c));
                    if d2 < best {
                        best = d2;
                        *hint = k as usize;
                    }
                }
            } else {
                let (l, r) = (n.start, n.right);
                let (dl, dr) = (
                    box_d2(&self.nodes[l as usize]),
                    box_d2(&self.nodes[r as usize]),
                );
                // Nearer child popped first.
                if dl < dr {
                    stack.extend([r, l]);
                } else {
                    stack.extend([l, r]);
                }
            }
        }
        best.sqrt()
    }
}

/// Points of every triangle of `s` on a barycentric grid whose step is at most `spacing`
/// along each edge, capped at `max_steps` steps per edge (vertices, edge points and interior
/// points; shared points are repeated).
pub fn samples(s: &Surface, spacing: f64, max_steps: usize) -> Vec<DVec3> {
    let mut out = Vec::new();
    for k in 0..s.triangles.len() {
        let [a, b, c] = s.corners(k);
        let longest = a.distance(b).max(b.distance(c)).max(c.distance(a));
        let n = ((longest / spacing).ceil() as usize).clamp(2, max_steps.max(2));
        for i in 0..=n {
            for j in 0..=n - i {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                out.push(a + (b - a) * u + (c - a) * v);
            }
        }
    }
    out
}

/// The largest distance from a sample of `from` to the surface `to`, and the sample.
pub fn one_sided(from: &Surface, to: &TriangleTree, spacing: f64) -> (f64, DVec3) {
    let mut hint = 0;
    let mut worst = (0.0, DVec3::ZERO);
    for p in samples(from, spacing, 6) {
        let d = to.distance(p, &mut hint);
        if d > worst.0 {
            worst = (d, p);
        }
    }
    worst
}

/// Two-sided sampled Hausdorff distance: (a to b, worst point of a), (b to a, worst point of
/// b). Samples are at most `spacing` apart along each triangle edge (or 6 steps per edge on
/// larger triangles), so this underestimates the true distance by up to about that step.
pub fn hausdorff(a: &Surface, b: &Surface, spacing: f64) -> ((f64, DVec3), (f64, DVec3)) {
    let (ta, tb) = (TriangleTree::new(a), TriangleTree::new(b));
    (one_sided(a, &tb, spacing), one_sided(b, &ta, spacing))
}
