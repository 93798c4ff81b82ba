use super::*;
use crate::geom::orient3d;

fn vol(m: &TetMesh) -> f64 {
    m.tets
        .iter()
        .map(|t| {
            let p = t.map(|v| m.vertices[v as usize]);
            orient3d(p[0], p[1], p[2], p[3]) / 6.0
        })
        .sum()
}

/// `t` with its last two vertices swapped if it is negatively oriented.
fn positively_oriented(mut t: [u32; 4], vertices: &[DVec3]) -> [u32; 4] {
    let p = t.map(|v| vertices[v as usize]);
    if orient3d(p[0], p[1], p[2], p[3]) < 0.0 {
        t.swap(2, 3);
    }
    t
}

/// The Kuhn split of an `n`^3 grid of cells into 6 positively oriented tets each; `id` numbers
/// the grid's (n + 1)^3 vertices.
fn kuhn_tets(
    n: usize,
    id: impl Fn(usize, usize, usize) -> u32,
    vertices: &[DVec3],
) -> Vec<[u32; 4]> {
    let mut tets = vec![];
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let c = [
                    id(i, j, k),
                    id(i + 1, j, k),
                    id(i + 1, j + 1, k),
                    id(i, j + 1, k),
                    id(i, j, k + 1),
                    id(i + 1, j, k + 1),
                    id(i + 1, j + 1, k + 1),
                    id(i, j + 1, k + 1),
                ];
                for t in [
                    [0, 1, 2, 6],
                    [0, 2, 3, 6],
                    [0, 3, 7, 6],
                    [0, 7, 4, 6],
                    [0, 4, 5, 6],
                    [0, 5, 1, 6],
                ] {
                    tets.push(positively_oriented(t.map(|x| c[x]), vertices));
                }
            }
        }
    }
    tets
}

fn min_q(m: &TetMesh) -> f64 {
    m.tets
        .iter()
        .map(|t| {
            let p = t.map(|v| m.vertices[v as usize]);
            quality::min_sin(p[0], p[1], p[2], p[3])
        })
        .fold(f64::INFINITY, f64::min)
}

/// Three tets around the edge (a, b) = (0, 1): the 3-2 flip (edge removal) must turn them
/// into two better ones.
#[test]
fn three_two_flip_removes_a_long_edge() {
    let a = DVec3::new(0.0, 0.0, -1.0);
    let b = DVec3::new(0.0, 0.0, 1.0);
    let r: Vec<DVec3> = (0..3)
        .map(|k| {
            let t = k as f64 * std::f64::consts::TAU / 3.0;
            DVec3::new(t.cos(), t.sin(), 0.0)
        })
        .collect();
    let mut vertices = vec![a, b];
    vertices.extend(&r);
    let mut tets = vec![];
    for i in 0..3u32 {
        let (x, y) = (2 + i, 2 + (i + 1) % 3);
        tets.push(positively_oriented([0, 1, x, y], &vertices));
    }
    // Stretch the edge so the three tets are needles around it.
    vertices[0].z = -6.0;
    vertices[1].z = 6.0;
    let mesh = TetMesh {
        vertices,
        tets,
        tet_regions: vec![3; 3],
        ..Default::default()
    };
    let before = min_q(&mesh);
    let (out, stats) = improve(&mesh, None, &Options::default());
    assert_eq!(out.tets.len(), 2, "{stats:?}");
    assert_eq!(stats.edge_removals, 1);
    assert!(min_q(&out) > before);
    assert!((vol(&out) - vol(&mesh)).abs() <= 1e-12 * vol(&mesh));
    assert!(out.tet_regions.iter().all(|&r| r == 3));
    check_no_degenerate(&out).unwrap();
}

/// Two apexes over a fan of three faces (a flat pentagonal bipyramid): removing faces of the
/// fan at once makes tets around the axis.
#[test]
fn multi_face_removal_takes_out_a_fan_of_faces() {
    let (d, e) = (DVec3::new(0.0, 0.0, 0.25), DVec3::new(0.0, 0.0, -0.25));
    let mut vertices = vec![d, e];
    vertices.extend((0..5).map(|k| {
        let t = k as f64 * std::f64::consts::TAU / 5.0;
        DVec3::new(t.cos(), t.sin(), 0.0)
    }));
    let mut tets = vec![];
    for [x, y, z] in [[2, 3, 4], [2, 4, 5], [2, 5, 6]] {
        tets.push(positively_oriented([0, x, y, z], &vertices));
        tets.push(positively_oriented([1, x, y, z], &vertices));
    }
    let mesh = TetMesh {
        vertices,
        tets,
        tet_regions: vec![1; 6],
        ..Default::default()
    };
    let before = min_q(&mesh);
    let mut im = improver_for(&mesh);
    // The axis de misses face (r0, r1, r2): its 2-3 flip would make an inverted tet. The
    // removal grows over the next face(s) of the fan.
    let plan = im.plan_faces([2, 3, 4]).expect("face removal improves");
    assert!(plan.new_min > before + 0.1, "{before} -> {}", plan.new_min);
    im.apply(plan);
    assert_eq!(im.stats.multi_face_removals, 1, "{:?}", im.stats);
    let out = im.w.to_mesh();
    let around_de = out
        .tets
        .iter()
        .filter(|t| t.contains(&0) && t.contains(&1))
        .count();
    assert!(around_de >= 4, "{:?}", out.tets);
    assert!(min_q(&out) >= before);
    assert!((vol(&out) - vol(&mesh)).abs() <= 1e-12 * vol(&mesh));
    check_no_degenerate(&out).unwrap();
}

/// An improver on `mesh` with every vertex fixed, for planning changes directly.
fn improver_for(mesh: &TetMesh) -> Improver<'static> {
    Improver {
        w: Work::new(mesh, quality::Objective::new(26.0, f64::INFINITY)),
        cons: vec![Constraint::Fixed; mesh.vertices.len()],
        normals: vec![],
        slide: None,
        stats: ImproveStats::default(),
    }
}

/// A flat tet (four coplanar points) gets reported with its vertices and coordinates.
#[test]
fn degenerate_tet_is_named() {
    let mesh = TetMesh {
        vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)],
        tets: vec![[0, 1, 2, 3]],
        tet_regions: vec![0],
        ..Default::default()
    };
    let e = check_no_degenerate(&mesh).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("[0, 1, 2, 3]") && msg.contains("(1, 1, 0)"),
        "{msg}"
    );
    assert!(msg.contains("flat"), "{msg}");
}

/// An interior vertex pushed next to a face of its star is moved back by smoothing.
#[test]
fn smoothing_recentres_an_interior_vertex() {
    // An octahedron around an interior vertex 6.
    let mut vertices = vec![
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
        DVec3::new(0.5, 0.2, 0.1),
    ];
    let faces = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    let mut tets = vec![];
    let mut boundary = vec![];
    for f in faces {
        let mut t = [f[0], f[1], f[2], 6];
        let p = t.map(|v: u32| vertices[v as usize]);
        if orient3d(p[0], p[1], p[2], p[3]) < 0.0 {
            t.swap(0, 1);
        }
        tets.push(t);
        boundary.push(f);
    }
    let mesh = TetMesh {
        vertices: vertices.clone(),
        tets,
        tet_regions: vec![0; 8],
        boundary_markers: vec![1; 8],
        boundary,
    };
    let before = min_q(&mesh);
    let (out, stats) = improve(&mesh, None, &Options::default());
    assert!(stats.smoothed >= 1, "{stats:?}");
    assert!(min_q(&out) > before + 0.1, "{} -> {}", before, min_q(&out));
    assert!(out.vertices[6].length() < 0.3, "{:?}", out.vertices[6]);
    // Boundary vertices stay where they were.
    vertices.truncate(6);
    assert_eq!(&out.vertices[..6], &vertices[..]);
    assert!((vol(&out) - vol(&mesh)).abs() <= 1e-12);
    check_no_degenerate(&out).unwrap();
}

/// Same input, same output (no hashing decides anything).
#[test]
fn deterministic() {
    let mut vertices = vec![];
    for i in 0..4 {
        for j in 0..4 {
            for k in 0..4 {
                let jitter = ((i * 7 + j * 13 + k * 29) % 11) as f64 * 0.02;
                vertices.push(DVec3::new(i as f64 + jitter, j as f64, k as f64 - jitter));
            }
        }
    }
    let n = vertices.len();
    // A Kuhn triangulation of the grid cells (valid for the small jitter used).
    let id = |i: usize, j: usize, k: usize| (i * 16 + j * 4 + k) as u32;
    let tets = kuhn_tets(3, id, &vertices);
    let mesh = TetMesh {
        vertices,
        tet_regions: vec![0; tets.len()],
        tets,
        ..Default::default()
    };
    assert_eq!(mesh.vertices.len(), n);
    let opts = Options {
        target_deg: 60.0,
        ..Options::default()
    };
    let (a, sa) = improve(&mesh, None, &opts);
    let (b, _) = improve(&mesh, None, &opts);
    assert_eq!(a, b);
    assert!(sa.changed());
    assert!(min_q(&a) >= min_q(&mesh));
    assert!((vol(&a) - vol(&mesh)).abs() <= 1e-9 * vol(&mesh));
    check_no_degenerate(&a).unwrap();
}

/// A flat tet lying on a facet (two of its faces are the facet's triangles) is removed by the
/// boundary 2-2 flip, with or without improvement, and the facet keeps its area and marker.
#[test]
fn flat_tet_on_a_facet_is_flipped_away() {
    use crate::plc::Facet;
    let vertices = vec![
        DVec3::ZERO,
        DVec3::X,
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::Y,
        DVec3::new(0.5, 0.5, 1.0),
    ];
    let orient = |mut t: [u32; 4]| {
        let p = t.map(|v| vertices[v as usize]);
        if orient3d(p[0], p[1], p[2], p[3]) < 0.0 {
            t.swap(0, 1);
        }
        t
    };
    let facet = |ids: &[u32], marker| Facet {
        polygons: vec![ids.to_vec()],
        marker,
        ..Default::default()
    };
    let input = PlcInput {
        vertices: vertices.clone(),
        facets: vec![
            facet(&[0, 3, 2, 1], 7),
            facet(&[0, 1, 4], 1),
            facet(&[1, 2, 4], 1),
            facet(&[2, 3, 4], 1),
            facet(&[3, 0, 4], 1),
        ],
        ..Default::default()
    };
    let mesh = TetMesh {
        vertices: vertices.clone(),
        tets: vec![[0, 1, 2, 3], orient([0, 1, 3, 4]), orient([1, 2, 3, 4])],
        tet_regions: vec![0; 3],
        boundary: vec![
            [0, 2, 1],
            [0, 3, 2],
            [0, 1, 4],
            [1, 2, 4],
            [2, 3, 4],
            [3, 0, 4],
        ],
        boundary_markers: vec![7, 7, 1, 1, 1, 1],
    };
    assert!(check_no_degenerate(&mesh).is_err());
    for improve_on in [false, true] {
        let params = Params {
            improve: improve_on,
            ..Default::default()
        };
        let (out, stats) = finish(mesh.clone(), Some(&input), &params, None).unwrap();
        assert_eq!(out.tets.len(), 2, "{stats:?}");
        assert_eq!(stats.boundary_flips, 1);
        assert!(stats.changed());
        let mut base: Vec<[u32; 3]> = out
            .boundary
            .iter()
            .zip(&out.boundary_markers)
            .filter(|(_, &m)| m == 7)
            .map(|(t, _)| topo::key3(*t))
            .collect();
        base.sort_unstable();
        assert_eq!(base, vec![[0, 1, 3], [1, 2, 3]]);
        // Oriented like before: normals still point down (out of the pyramid).
        for (t, &m) in out.boundary.iter().zip(&out.boundary_markers) {
            if m == 7 {
                let [a, b, c] = t.map(|v| out.vertices[v as usize]);
                assert!((b - a).cross(c - a).z < 0.0, "{t:?}");
            }
        }
        assert!((vol(&out) - 1.0 / 3.0).abs() < 1e-12);
    }
    // Without the input description the boundary may not flip; here the interior 3-2 flip
    // of edge 1-3 removes the flat tet instead, keeping the base's triangles.
    let (out, stats) = finish(mesh.clone(), None, &Default::default(), None).unwrap();
    assert_eq!(out.boundary, mesh.boundary);
    assert_eq!(stats.edge_removals, 1);
    assert_eq!(out.tets.len(), 2);
}

/// A 2-3 flip: two tets sharing a face whose opposite vertices are far apart.
#[test]
fn two_three_flip() {
    let vertices = vec![
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(-0.5, 0.87, 0.0),
        DVec3::new(-0.5, -0.87, 0.0),
        DVec3::new(0.0, 0.0, 0.15),
        DVec3::new(0.0, 0.0, -0.15),
    ];
    let mut tets = vec![[0, 1, 2, 3], [0, 2, 1, 4]];
    for t in &mut tets {
        let p = t.map(|v| vertices[v as usize]);
        if orient3d(p[0], p[1], p[2], p[3]) < 0.0 {
            t.swap(0, 1);
        }
    }
    let im = improver_for(&TetMesh {
        vertices,
        tets,
        tet_regions: vec![0, 0],
        ..Default::default()
    });
    let plan = im.plan_faces([0, 1, 2]).expect("2-3 flip improves");
    assert!(plan.new_min > im.w.q[0].max(im.w.q[1]));
}

/// A flat tet on a slightly folded base, under a pyramid whose every vertex is on the hull
/// (so fixed): a vertex inserted above the base lifts it (the insertion planned directly: on
/// this small cavity the 3-2 flip would also do).
#[test]
fn insertion_lifts_a_flat_tet_off_a_fold() {
    let vertices = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(1.0, 1.0, 1e-3),
        DVec3::new(0.5, 0.5, 0.8),
    ];
    // The flat tet (lower faces abc, bcd on the hull) and the two tets above its upper faces
    // abd, acd.
    let tets =
        [[0, 1, 2, 3], [0, 1, 3, 4], [0, 2, 3, 4]].map(|t| positively_oriented(t, &vertices));
    let mesh = TetMesh {
        vertices,
        tets: tets.to_vec(),
        tet_regions: vec![1; 3],
        ..Default::default()
    };
    let before = min_q(&mesh);
    assert!(before < 1e-2);
    let mut w = topo::Work::new(&mesh, quality::Objective::new(26.0, f64::INFINITY));
    let (cons, normals) = constraints::classify(&mut w, None);
    let mut im = Improver {
        w,
        cons,
        normals,
        slide: None,
        stats: ImproveStats::default(),
    };
    let plan = im.plan_insertion(0).expect("an insertion");
    let made = im.apply_insertion(plan);
    assert_eq!((made.len(), im.stats.insertions), (6, 1));
    let out = im.w.to_mesh();
    assert_eq!(out.vertices.len(), 6);
    assert!(
        out.vertices[..5] == mesh.vertices[..],
        "a hull vertex moved"
    );
    assert!(min_q(&out) > 0.15, "{} -> {}", before, min_q(&out));
    assert!((vol(&out) - vol(&mesh)).abs() <= 1e-12 * vol(&mesh));
    assert!(out.tet_regions.iter().all(|&r| r == 1));
    check_no_degenerate(&out).unwrap();
}

/// A free vertex just below one face of a regular-ish tet, joined to its four faces: the three
/// tets on that face side are flat, and the vertex goes (contracted onto a corner), leaving the
/// one good tet; the deleted vertex is dropped from the output.
#[test]
fn deletion_removes_a_vertex_squeezed_against_a_face() {
    let vertices = vec![
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.5, 0.9, 0.0),
        DVec3::new(0.5, 0.3, 0.8),
        DVec3::new(0.5, 0.3, 1e-3),
    ];
    let tets = [[1, 2, 3, 4], [0, 2, 3, 4], [0, 1, 3, 4], [0, 1, 2, 4]]
        .map(|t| positively_oriented(t, &vertices));
    let mesh = TetMesh {
        vertices,
        tets: tets.to_vec(),
        tet_regions: vec![7; 4],
        boundary: vec![[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]],
        boundary_markers: vec![1; 4],
    };
    let before = min_q(&mesh);
    assert!(before < 1e-2);
    let mut w = topo::Work::new(&mesh, quality::Objective::new(26.0, f64::INFINITY));
    let (cons, normals) = constraints::classify(&mut w, None);
    assert!(matches!(cons[4], Constraint::Free) && matches!(cons[0], Constraint::Fixed));
    let mut im = Improver {
        w,
        cons,
        normals,
        slide: None,
        stats: ImproveStats::default(),
    };
    let worst = (0..4u32)
        .min_by(|&a, &b| im.w.q[a as usize].total_cmp(&im.w.q[b as usize]))
        .unwrap();
    let plan = im.plan_deletion(worst).expect("a deletion");
    let made = im.apply_deletion(plan);
    assert_eq!((made.len(), im.stats.deletions), (1, 1));
    let out = im.w.to_mesh();
    assert_eq!(out.vertices, mesh.vertices[..4].to_vec());
    assert_eq!(out.tets.len(), 1);
    assert!(min_q(&out) > 0.3, "{} -> {}", before, min_q(&out));
    assert!((vol(&out) - vol(&mesh)).abs() <= 1e-12 * vol(&mesh));
    assert_eq!(out.tet_regions, vec![7]);
    check_no_degenerate(&out).unwrap();
}

/// A grid of `n`^3 unit cells cut into Kuhn tets (smallest dihedral angle 45 degrees), the
/// vertices inside the grid jittered (those on a side within it, as `slides`), with its hull
/// triangles as the boundary when `boundary`.
fn jittered_grid(n: usize, boundary: bool) -> TetMesh {
    let m = n + 1;
    let id = |i: usize, j: usize, k: usize| (i * m * m + j * m + k) as u32;
    let mut vertices = vec![];
    for i in 0..m {
        for j in 0..m {
            for k in 0..m {
                let jitter = |salt: usize| {
                    let h = (i * 73_856_093) ^ (j * 19_349_663) ^ (k * 83_492_791) ^ (salt * 97);
                    (h % 1001) as f64 / 1000.0 - 0.5
                };
                let inside = |c: usize| c > 0 && c < n;
                let mut p = DVec3::new(i as f64, j as f64, k as f64);
                for (axis, c) in [i, j, k].into_iter().enumerate() {
                    if inside(c) {
                        p[axis] += 0.2 * jitter(axis + 1);
                    }
                }
                vertices.push(p);
            }
        }
    }
    let tets = kuhn_tets(n, id, &vertices);
    let mut hull = vec![];
    if boundary {
        let mut faces: Vec<([u32; 3], [u32; 3])> = tets
            .iter()
            .flat_map(|&t| (0..4).map(move |i| topo::face(t, i)))
            .map(|f| (topo::key3(f), f))
            .collect();
        faces.sort_unstable();
        for (k, g) in faces.chunk_by(|a, b| a.0 == b.0).enumerate() {
            if g.len() == 1 {
                hull.push((k, g[0].1));
            }
        }
    }
    TetMesh {
        vertices,
        tet_regions: vec![0; tets.len()],
        tets,
        boundary_markers: vec![1; hull.len()],
        boundary: hull.into_iter().map(|(_, f)| f).collect(),
    }
}

/// Vertices on one side of the grid of `n` cells (not on its edges) slide in that side.
struct GridSides {
    n: usize,
    vertices: Vec<DVec3>,
}

impl GridSides {
    /// The axis of the side vertex `v` is on, if exactly one.
    fn side(&self, v: u32) -> Option<usize> {
        let p = self.vertices.get(v as usize)?;
        let on = |c: f64| c == 0.0 || c == self.n as f64;
        let axes: Vec<usize> = (0..3).filter(|&a| on(p[a])).collect();
        (axes.len() == 1).then_some(axes[0])
    }
}

impl SurfaceSlide for GridSides {
    fn slides(&self, v: u32) -> bool {
        self.side(v).is_some()
    }

    fn along(&self, _: u32, _: DVec3) -> Option<DVec3> {
        None
    }

    fn project(&self, v: u32, mut x: DVec3) -> Option<DVec3> {
        let a = self.side(v)?;
        x[a] = self.vertices[v as usize][a];
        Some(x)
    }

    fn keeps_close(&self, _: [DVec3; 3]) -> bool {
        true
    }
}

/// On several threads the plans are made ahead in batches; in this build every plan used as
/// made ahead is made again and compared (`Improver::use_plan`), so a footprint that misses
/// something a plan read fails here. The meshes and stats match the one-thread run's. Every
/// tet of the grids is below the 60-degree target: many batches, flips, smoothings (hull
/// vertices found and fixed, sides sliding), insertions, deletions and radius-edge vetoes.
#[test]
fn plans_made_ahead_are_the_plans_made_now() {
    let untimed = |s: &ImproveStats| ImproveStats {
        seconds: 0.0,
        seconds_plans: 0.0,
        seconds_smooth: 0.0,
        ..s.clone()
    };
    let opts = Options {
        target_deg: 60.0,
        ..Options::default()
    };
    let kept = Options {
        keep_rho: 1.2,
        ..opts
    };
    for (boundary, opts) in [(false, opts), (true, opts), (true, kept)] {
        let mesh = jittered_grid(8, boundary);
        assert!(mesh.tets.iter().all(|t| {
            let p = t.map(|v| mesh.vertices[v as usize]);
            orient3d(p[0], p[1], p[2], p[3]) > 0.0
        }));
        let sides = GridSides {
            n: 8,
            vertices: mesh.vertices.clone(),
        };
        let slide: Option<&dyn SurfaceSlide> = if boundary { Some(&sides) } else { None };
        let run = |threads| {
            crate::parallel::with_threads(threads, || improve_with(&mesh, None, &opts, slide))
        };
        let (want, stats) = run(1);
        assert!(stats.smoothed > 0 && stats.edge_removals > 0, "{stats:?}");
        for threads in [2, 3] {
            let (got, s) = run(threads);
            assert!(got == want, "the mesh differs with {threads} threads");
            assert_eq!(untimed(&s), untimed(&stats), "{threads} threads");
        }
        check_no_degenerate(&want).unwrap();
        assert!((vol(&want) - vol(&mesh)).abs() <= 1e-9 * vol(&mesh));
    }
}
