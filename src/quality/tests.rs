//! Known tets against an independent computation from the six edge lengths only (Cayley–Menger
//! volume, Heron areas, Crelle's circumradius, sin θ_ij = 3 V l_ij / (2 A_k A_l)), the mesh
//! figures against a naive recomputation, the text and the SVG (parsed as XML).

use super::*;
use crate::geom::{REGULAR_ASPECT, REGULAR_DIHEDRAL, REGULAR_RHO, REGULAR_SIGMA};
use crate::mesh::TetMesh;
use glam::DVec3;
use rand::{Rng, SeedableRng};

/// Measures of one tet from its edge lengths alone (no vector products, no orient3d).
#[derive(Debug, Clone, Copy)]
struct Ref {
    min_dihedral: f64,
    max_dihedral: f64,
    rho: f64,
    sigma: f64,
    aspect: f64,
}

const PAIRS: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];

/// Kahan's stable Heron formula.
fn heron(a: f64, b: f64, c: f64) -> f64 {
    let mut s = [a, b, c];
    s.sort_by(|x, y| y.total_cmp(x));
    let [a, b, c] = s;
    let p = (a + (b + c)) * (c - (a - b)) * (c + (a - b)) * (a + (b - c));
    0.25 * p.max(0.0).sqrt()
}

/// Determinant by Gaussian elimination with partial pivoting.
fn det(mut m: Vec<Vec<f64>>) -> f64 {
    let n = m.len();
    let mut d = 1.0;
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))
            .unwrap();
        if m[p][c] == 0.0 {
            return 0.0;
        }
        if p != c {
            m.swap(p, c);
            d = -d;
        }
        d *= m[c][c];
        let pivot = m[c].clone();
        for row in m.iter_mut().skip(c + 1) {
            let f = row[c] / pivot[c];
            for (x, p) in row[c..].iter_mut().zip(&pivot[c..]) {
                *x -= f * p;
            }
        }
    }
    d
}

fn reference(t: [DVec3; 4]) -> Ref {
    let l = |i: usize, j: usize| t[i].distance(t[j]);
    let l2 = |i: usize, j: usize| t[i].distance_squared(t[j]);
    // Cayley–Menger: 288 V² = det.
    let mut cm = vec![vec![1.0; 5]; 5];
    cm[0][0] = 0.0;
    for i in 0..4 {
        for j in 0..4 {
            cm[i + 1][j + 1] = l2(i, j);
        }
    }
    let v = (det(cm) / 288.0).max(0.0).sqrt();
    // Area of the face opposite vertex k.
    let area = |k: usize| {
        let f: Vec<usize> = (0..4).filter(|&i| i != k).collect();
        heron(l(f[0], f[1]), l(f[0], f[2]), l(f[1], f[2]))
    };
    let (mut lo, mut hi) = (180.0f64, 0.0f64);
    for [i, j] in PAIRS {
        let o: Vec<usize> = (0..4).filter(|&k| k != i && k != j).collect();
        let (k, m) = (o[0], o[1]);
        let s = (3.0 * v * l(i, j) / (2.0 * area(k) * area(m))).min(1.0);
        // Obtuse or not: the sign of the dot product of the two altitudes onto the edge, by
        // the polarisation identity (lengths only).
        let e2 = l2(i, j);
        let ex = 0.5 * (e2 + l2(i, k) - l2(j, k));
        let ey = 0.5 * (e2 + l2(i, m) - l2(j, m));
        let xy = 0.5 * (l2(i, k) + l2(i, m) - l2(k, m));
        let cos_sign = xy - ex * ey / e2;
        let a = s.asin().to_degrees();
        let ang = if cos_sign >= 0.0 { a } else { 180.0 - a };
        lo = lo.min(ang);
        hi = hi.max(ang);
    }
    let shortest = PAIRS.iter().map(|&[i, j]| l(i, j)).fold(f64::MAX, f64::min);
    // Crelle: 6 V R = area of the triangle whose sides are the products of opposite edges.
    let r_big = heron(l(0, 1) * l(2, 3), l(0, 2) * l(1, 3), l(0, 3) * l(1, 2)) / (6.0 * v);
    let r_in = 3.0 * v / (0..4).map(area).sum::<f64>();
    Ref {
        min_dihedral: lo,
        max_dihedral: hi,
        rho: r_big / shortest,
        sigma: v / shortest.powi(3),
        aspect: r_big / (3.0 * r_in),
    }
}

fn regular() -> [DVec3; 4] {
    [
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(-1.0, -1.0, 1.0),
    ]
}

/// Four points near a circle, alternately lifted: two dihedral angles near 0, two near 180.
fn sliver() -> [DVec3; 4] {
    let e = 0.02;
    [
        DVec3::new(1.0, 0.0, e),
        DVec3::new(0.0, 1.0, -e),
        DVec3::new(0.0, -1.0, -e),
        DVec3::new(-1.0, 0.0, e),
    ]
}

/// A vertex just above the centre of the opposite face: three angles near 180.
fn cap() -> [DVec3; 4] {
    let h = 3f64.sqrt() / 2.0;
    [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.5, h, 0.0),
        DVec3::new(0.5, h / 3.0, 0.01),
    ]
}

/// A tall spike over a small triangle: large rho and aspect, no small dihedral angle.
fn needle() -> [DVec3; 4] {
    [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(0.3, 0.3, 12.0),
    ]
}

/// A regular tet with two vertices swapped: negative orientation.
fn inverted() -> [DVec3; 4] {
    let [a, b, c, d] = regular();
    [b, a, c, d]
}

fn flat() -> [DVec3; 4] {
    [
        DVec3::new(0.0, 0.0, 0.0),
        DVec3::new(1.0, 0.0, 0.0),
        DVec3::new(0.0, 1.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
    ]
}

/// A mesh of separate tets (each with its own four vertices).
fn mesh_of(tets: &[[DVec3; 4]]) -> TetMesh {
    let mut m = TetMesh::default();
    for t in tets {
        let base = m.vertices.len() as u32;
        m.vertices.extend_from_slice(t);
        m.tets.push([base, base + 1, base + 2, base + 3]);
        m.tet_regions.push(0);
    }
    m
}

#[track_caller]
fn close(got: f64, want: f64, tol: f64) {
    assert!(
        (got - want).abs() <= tol * want.abs().max(1.0),
        "got {got}, want {want}"
    );
}

#[test]
fn regular_tet_known_answers() {
    let q = measure(&mesh_of(&[regular()])).unwrap();
    close(q.min_dihedral_deg, REGULAR_DIHEDRAL, 1e-12);
    close(q.max_dihedral_deg, REGULAR_DIHEDRAL, 1e-12);
    close(q.min_dihedral_deg, 70.528_779_365_509_31, 1e-12);
    close(q.max_rho, REGULAR_RHO, 1e-12);
    close(q.max_rho, 0.612_372_435_695_794_5, 1e-12);
    close(q.min_sigma, REGULAR_SIGMA, 1e-12);
    close(q.min_sigma, 0.117_851_130_197_757_9, 1e-12);
    close(q.max_aspect, REGULAR_ASPECT, 1e-12);
    close(q.volume, 8.0 / 3.0, 1e-12);
    assert_eq!((q.n_inverted, q.n_zero_volume), (0, 0));
    assert_eq!(q.tets_below_deg, [0; 4]);
    let r = reference(regular());
    close(r.min_dihedral, REGULAR_DIHEDRAL, 1e-9);
    close(r.rho, REGULAR_RHO, 1e-12);
    close(r.sigma, REGULAR_SIGMA, 1e-12);
    close(r.aspect, 1.0, 1e-12);
}

#[test]
fn known_bad_tets_agree_with_the_edge_length_formulas() {
    for (name, t) in [
        ("regular", regular()),
        ("sliver", sliver()),
        ("cap", cap()),
        ("needle", needle()),
        ("inverted", inverted()),
    ] {
        let q = measure(&mesh_of(&[t])).unwrap();
        let r = reference(t);
        eprintln!("{name}: {q:?}\n  reference {r:?}");
        // asin near 90 degrees loses half the digits; 1e-6 degrees is still far below the
        // two printed decimals.
        close(q.min_dihedral_deg, r.min_dihedral, 1e-6);
        close(q.max_dihedral_deg, r.max_dihedral, 1e-6);
        close(q.max_rho, r.rho, 1e-9);
        close(q.min_sigma, r.sigma, 1e-9);
        close(q.max_aspect, r.aspect, 1e-9);
        assert_eq!(q.n_inverted, usize::from(name == "inverted"), "{name}");
        assert_eq!(q.n_zero_volume, 0, "{name}");
    }
    // The shapes are what their names say.
    let s = measure(&mesh_of(&[sliver()])).unwrap();
    assert!(
        s.min_dihedral_deg < 10.0 && s.max_dihedral_deg > 170.0,
        "{s:?}"
    );
    assert!(
        s.max_rho < 1.0 && s.min_sigma < 0.02,
        "a sliver has a small rho: {s:?}"
    );
    let c = measure(&mesh_of(&[cap()])).unwrap();
    assert!(
        c.max_dihedral_deg > 170.0 && c.min_dihedral_deg < 10.0,
        "{c:?}"
    );
    let n = measure(&mesh_of(&[needle()])).unwrap();
    assert!(
        n.max_rho > 5.0 && n.max_aspect > 5.0 && n.min_dihedral_deg > 5.0,
        "{n:?}"
    );
    assert_eq!(s.tets_below_deg, [1, 1, 1, 1]);
    assert_eq!(s.tets_above_deg, [1, 1, 1, 1]);
}

#[test]
fn inverted_and_zero_volume_tets_are_counted_by_the_exact_sign() {
    let m = mesh_of(&[regular(), inverted(), flat(), sliver(), inverted()]);
    let q = measure(&m).unwrap();
    assert_eq!((q.n_inverted, q.n_zero_volume), (2, 1));
    assert_eq!(q.worst_tet, 2);
    assert_eq!(q.min_dihedral_deg, 0.0);
    assert_eq!(q.max_dihedral_deg, 180.0);
    assert!(q.max_rho.is_infinite() && q.max_aspect.is_infinite());
    assert_eq!(q.min_sigma, 0.0);
    // Signed sum: regular - inverted - inverted + sliver's small volume.
    let sliver_v = crate::geom::volume(sliver()[0], sliver()[1], sliver()[2], sliver()[3]);
    close(q.volume, -8.0 / 3.0 + sliver_v, 1e-12);
    // A zero-volume tet a rounding error off the plane is not zero volume: the exact sign says so.
    let mut near = flat();
    near[3].z = 1e-300;
    let q = measure(&mesh_of(&[near])).unwrap();
    assert_eq!((q.n_inverted, q.n_zero_volume), (0, 0));
    near[3].z = -1e-300;
    let q = measure(&mesh_of(&[near])).unwrap();
    assert_eq!((q.n_inverted, q.n_zero_volume), (1, 0));
}

/// Random tets: every figure equals a naive recomputation from the reference measures.
#[test]
fn mesh_figures_match_a_naive_recomputation() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut tets = vec![];
    for _ in 0..3000 {
        let c = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 10.0;
        tets.push(
            [0; 4]
                .map(|_: i32| c + DVec3::new(rng.gen(), rng.gen(), rng.gen()) - DVec3::splat(0.5)),
        );
    }
    let m = mesh_of(&tets);
    let q = measure(&m).unwrap();
    let refs: Vec<Ref> = tets.iter().map(|&t| reference(t)).collect();
    let sorted = |f: &dyn Fn(&Ref) -> f64| {
        let mut v: Vec<f64> = refs.iter().map(f).collect();
        v.sort_by(f64::total_cmp);
        v
    };
    // Nearest rank, written out: rank ceil(p n / 100), 1-based.
    let pct = |v: &[f64], p: f64| v[((p / 100.0 * v.len() as f64).ceil() as usize).max(1) - 1];
    let mins = sorted(&|r| r.min_dihedral);
    let maxs = sorted(&|r| r.max_dihedral);
    let tol = 1e-5;
    close(q.min_dihedral_deg, mins[0], tol);
    close(q.max_dihedral_deg, *maxs.last().unwrap(), tol);
    close(q.min_dihedral_p1_deg, pct(&mins, 1.0), tol);
    close(q.min_dihedral_p5_deg, pct(&mins, 5.0), tol);
    close(q.min_dihedral_median_deg, pct(&mins, 50.0), tol);
    close(q.max_dihedral_median_deg, pct(&maxs, 50.0), tol);
    close(q.max_dihedral_p95_deg, pct(&maxs, 95.0), tol);
    close(q.max_dihedral_p99_deg, pct(&maxs, 99.0), tol);
    let rhos = sorted(&|r| r.rho);
    let sigmas = sorted(&|r| r.sigma);
    let aspects = sorted(&|r| r.aspect);
    close(q.max_rho, *rhos.last().unwrap(), 1e-6);
    // The percentiles are taken from f32 copies (7 digits).
    close(q.median_rho, pct(&rhos, 50.0), 1e-6);
    close(q.min_sigma, sigmas[0], 1e-6);
    close(q.median_sigma, pct(&sigmas, 50.0), 1e-6);
    close(q.max_aspect, *aspects.last().unwrap(), 1e-6);
    close(q.median_aspect, pct(&aspects, 50.0), 1e-6);
    for (k, thr) in BELOW_DEG.iter().enumerate() {
        let n = mins.iter().filter(|&&x| x < *thr).count();
        assert_eq!(q.tets_below_deg[k], n, "below {thr}");
    }
    for (k, thr) in ABOVE_DEG.iter().enumerate() {
        let n = maxs.iter().filter(|&&x| x > *thr).count();
        assert_eq!(q.tets_above_deg[k], n, "above {thr}");
    }
    for b in 0..MIN_BINS {
        let (lo, hi) = (b as f64 * MIN_BIN_DEG, (b + 1) as f64 * MIN_BIN_DEG);
        let n = mins.iter().filter(|&&x| lo <= x && x < hi).count();
        assert_eq!(q.min_dihedral_histogram[b], n, "bin {b}");
    }
    assert_eq!(q.n_inverted + q.n_zero_volume, {
        let n = tets
            .iter()
            .filter(|t| crate::geom::orient3d(t[0], t[1], t[2], t[3]) <= 0.0)
            .count();
        assert!(n > 1000, "random tets are inverted half the time");
        n
    });
    let h = dihedral_histogram(&m).unwrap();
    assert_eq!(h.iter().sum::<usize>(), 6 * tets.len());
}

#[test]
fn percentile_is_nearest_rank() {
    let mut v = vec![5.0, 1.0, 4.0, 2.0, 3.0];
    assert_eq!(percentile(&mut v, 50.0), 3.0);
    assert_eq!(percentile(&mut v, 1.0), 1.0);
    assert_eq!(percentile(&mut v, 20.0), 1.0);
    assert_eq!(percentile(&mut v, 21.0), 2.0);
    assert_eq!(percentile(&mut v, 100.0), 5.0);
}

#[test]
fn bad_meshes_are_errors_not_panics() {
    let mut m = mesh_of(&[regular()]);
    m.tets.push([0, 1, 2, 9]);
    m.tet_regions.push(0);
    let e = measure(&m).unwrap_err();
    assert!(
        e.to_string().contains("tet 1") && e.to_string().contains("vertex 9"),
        "{e}"
    );
    assert!(dihedral_histogram(&m).is_err());
    let mut m = mesh_of(&[regular()]);
    m.boundary.push([0, 1, 4]);
    m.boundary_markers.push(1);
    assert!(matches!(
        measure(&m),
        Err(QualityError::VertexOutOfRange { vertex: 4, .. })
    ));
    let mut m = mesh_of(&[regular()]);
    m.vertices[2].y = f64::NAN;
    assert_eq!(measure(&m), Err(QualityError::NotFinite { vertex: 2 }));
    assert_eq!(measure(&TetMesh::default()), Err(QualityError::NoTets));
}

#[test]
fn near_flat_shape_measures_are_not_printed_as_zero() {
    let mut near = flat();
    near[3] = DVec3::new(0.3, 0.3, 1e-9);
    let t = table(&measure(&mesh_of(&[near])).unwrap());
    let row = |k: &str| t.lines().find(|l| l.contains(k)).unwrap().to_string();
    assert!(row("sigma").contains("e-"), "{t}");
    assert!(row("aspect").contains('e'), "{t}");
    assert!(row("dihedral min / max").contains("0.00 / 180.00"), "{t}");
    assert!(row("inverted / zero-volume").ends_with("0 / 0"), "{t}");
}

#[test]
fn table_and_histogram_text() {
    let m = mesh_of(&[regular(), sliver(), cap(), needle(), inverted()]);
    let q = measure(&m).unwrap();
    let t = table(&q);
    let inv = t
        .lines()
        .find(|l| l.contains("inverted / zero-volume"))
        .unwrap();
    assert!(inv.ends_with("  1 / 0"), "{t}");
    assert!(t.contains(&format!(
        "{:.2} / {:.2}",
        q.min_dihedral_deg, q.max_dihedral_deg
    )));
    assert!(t.contains("tets below 5/10/15/20 deg"), "{t}");
    // Every angle has (at least) two decimals.
    let row = t
        .lines()
        .find(|l| l.contains("dihedral min / max"))
        .unwrap();
    for v in row.split_whitespace().filter(|w| w.contains('.')) {
        assert!(v.split('.').nth(1).unwrap().len() >= 2, "{row}");
    }
    let h = histogram_text(&q);
    // 5 tets, one line each in its bin (sliver and cap in 0-5).
    let total: usize = h
        .lines()
        .skip(1)
        .map(|l| {
            l.split('|')
                .next()
                .unwrap()
                .split_whitespace()
                .last()
                .unwrap()
                .parse::<usize>()
                .unwrap()
        })
        .sum();
    assert_eq!(total, 5, "{h}");
    assert!(h.lines().nth(1).unwrap().starts_with("   0-5 "), "{h}");
    let c = compare_table("a.mesh", &q, "b.mesh", &q);
    assert!(c.lines().next().unwrap().contains("a.mesh") && c.contains("b.mesh"));
    assert_eq!(c.lines().count(), t.lines().count() + 1);
    let ch = compare_histogram_text("a", &q, "b", &q);
    assert_eq!(ch.lines().count(), h.lines().count() + 1, "{ch}");
}

#[test]
fn svg_is_well_formed_with_bars_and_the_four_lines() {
    let m = mesh_of(&[regular(), sliver(), cap(), needle(), inverted()]);
    let q = measure(&m).unwrap();
    let bins = dihedral_histogram(&m).unwrap();
    let name = "a <b> & \"c\"";
    let series = [
        SvgSeries {
            name,
            bins: &bins,
            quality: &q,
        },
        SvgSeries {
            name: "other",
            bins: &bins,
            quality: &q,
        },
    ];
    let text = svg("title & more", &series);
    let doc = roxmltree::Document::parse(&text).expect("well-formed XML");
    let root = doc.root_element();
    assert_eq!(root.tag_name().name(), "svg");
    assert_eq!(
        root.tag_name().namespace(),
        Some("http://www.w3.org/2000/svg")
    );
    let class = |c: &str| {
        doc.descendants()
            .filter(|n| n.attribute("class") == Some(c))
            .collect::<Vec<_>>()
    };
    let bars = class("bar");
    assert_eq!(bars.len(), bins.iter().filter(|&&c| c > 0).count());
    assert!(bars
        .iter()
        .all(|b| b.attribute("height").unwrap().parse::<f64>().unwrap() >= 1.0));
    let lines = class("threshold");
    assert_eq!(lines.len(), 4);
    // The lines sit at 5, 10, 15, 20 degrees on the bars' x scale: equally spaced, in order.
    let xs: Vec<f64> = lines
        .iter()
        .map(|l| l.attribute("x1").unwrap().parse().unwrap())
        .collect();
    let step = xs[1] - xs[0];
    assert!(step > 0.0);
    for w in xs.windows(2) {
        assert!((w[1] - w[0] - step).abs() < 0.02, "{xs:?}");
    }
    let bar_x0: f64 = class("bar")[0].attribute("x").unwrap().parse().unwrap();
    let bar_w: f64 = class("bar")[0].attribute("width").unwrap().parse().unwrap();
    assert!((step - 5.0 * bar_w).abs() < 0.05, "5 degrees = 5 bins");
    let first_bin = bins.iter().position(|&c| c > 0).unwrap() as f64;
    assert!((bar_x0 - (xs[0] - 5.0 * bar_w) - first_bin * bar_w).abs() < 0.05);
    let legend: String = class("legend").iter().filter_map(|n| n.text()).collect();
    assert!(
        legend.contains(name),
        "names are escaped and read back: {legend}"
    );
    assert!(doc
        .descendants()
        .any(|n| n.attribute("id") == Some("outline")));
    assert_eq!(text, svg("title & more", &series), "deterministic");
}
