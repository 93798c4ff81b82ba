//! `slivermesh mesh --repair` on dirty surfaces (tests/common/dirty.rs): open holes, an open
//! bottom, overlapping copies, flipped triangles, a triangle soup, a crack and a fold, built
//! from an icosphere, two scans and fandisk.
//!
//! For every case, without `--repair` the CLI must refuse: exit status 1, a hint naming
//! `--repair` on stderr, no mesh written (`refuses_without_repair::*`, any build). With
//! `--repair` it must finish within 120 s and write a mesh whose tets are all positive (exact
//! orient3d), whose smallest dihedral angle is at least 20 degrees, whose volume is the case's
//! expected volume, and whose boundary passes within 0.5% of the diagonal of at least 98% of
//! the input's area (`repairs::*`, release builds only: `cargo test --release --test
//! dirty_surfaces`). The corpus's own tests (`corpus_*`, any build) check that each generator
//! makes the defect it claims.

mod common;

use common::corpus::{self, Surface, TriangleTree};
use common::dirty::{self, Dirty, Kind};
use common::{tail, ScratchDir};
use slivermesh::geom::orient3d;
use slivermesh::{DVec3, TetMesh};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// Largest output -> input distance away from spanned holes, in distance bounds (the clean
/// models' approximate mode ends at 0.8-1.0 on the same measure; this corpus at 0.64-1.00).
const OUT_IN_BOUNDS: f64 = 1.1;

/// Default floor of the smallest dihedral angle (the approximate mode's improvement target).
const MIN_DIHEDRAL: f64 = 20.0;

/// Wall-clock limit of one repaired run, in seconds.
const TIME_LIMIT: f64 = 120.0;

/// Share of the input's area (of the triangles on the solid's boundary) that must lie within
/// [`NEAR`] of the output boundary.
const AREA_SHARE: f64 = 0.98;

/// Distance from the output boundary, relative to the input's bounding-box diagonal.
const NEAR: f64 = 5e-3;

/// Largest relative difference between the repaired mesh's volume and the case's expected
/// volume.
///
/// 1% for most cases. The small holes are filled by a surface the repair invents; their
/// patches lie around an extreme point of the surface, on a convex part, where a fill spanning
/// the hole's loop differs little from the clean cap: even a flat-ish fan from the loop's
/// centroid loses only 0.02% to 0.18% of the volume (`corpus_small_hole_leaves_one_open_loop`).
/// The crack's small disk moves by less than the crack's width (0.2% of the diagonal). The
/// fold's expected volume is the winding number's {w >= 1/2}, measured exactly
/// (tests/common/dirty.rs, `fold`); its tube is 1.9% of the volume, so 1% tells a repair that
/// keeps the tube from one that fills it.
///
/// 3% for the open bottoms: a quarter of the surface is missing and the repair invents the
/// whole bottom, which the surface-distance bound does not hold to anything. The expected
/// volume is that of the flat fill (over a planar rim, the winding number's 1/2 level set is
/// the flat disk, here the clean bottom); 3% admits a fill that strays from it by about 1.5%
/// of the diagonal on average (the dome: 0.70 of base area x 0.016 = 3% of 0.375), 1% only by
/// 0.5%.
fn volume_tolerance(kind: Kind) -> f64 {
    match kind {
        Kind::OpenBottom => 3e-2,
        _ => 1e-2,
    }
}

/// This file's scratch directories.
fn scratch(name: &str) -> ScratchDir {
    ScratchDir::new("dirty", name)
}

/// One CLI run: its exit code (None if killed or ended by a signal), output and wall time.
struct Run {
    code: Option<i32>,
    timed_out: bool,
    stdout: String,
    stderr: String,
    seconds: f64,
    mesh: PathBuf,
    json: PathBuf,
}

/// Writes the case's file into `dir` and runs `slivermesh mesh IN -o OUT.mesh --stats-json
/// J.json` on it (with `--repair` if asked), killing it after `limit`. Output goes to files
/// (a pipe could fill up while the run is polled).
fn run_cli(d: &Dirty, dir: &Path, repair: bool, limit: Duration) -> Run {
    let input = dir.join(d.file_name());
    std::fs::write(&input, d.file_text()).unwrap();
    let (mesh, json) = (
        dir.join(format!("{}.mesh", d.name)),
        dir.join(format!("{}.json", d.name)),
    );
    let (out, err) = (dir.join("stdout.txt"), dir.join("stderr.txt"));
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_slivermesh"));
    cmd.arg("mesh")
        .arg(&input)
        .arg("-o")
        .arg(&mesh)
        .arg("--stats-json")
        .arg(&json);
    if repair {
        cmd.arg("--repair");
    }
    let start = Instant::now();
    let mut child = cmd
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&out).unwrap())
        .stderr(std::fs::File::create(&err).unwrap())
        .spawn()
        .unwrap();
    let mut timed_out = false;
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break Some(s);
        }
        if start.elapsed() > limit {
            child.kill().ok();
            child.wait().ok();
            timed_out = true;
            break None;
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    let seconds = start.elapsed().as_secs_f64();
    let read =
        |p: &Path| String::from_utf8_lossy(&std::fs::read(p).unwrap_or_default()).into_owned();
    Run {
        code: status.and_then(|s| s.code()),
        timed_out,
        stdout: read(&out),
        stderr: read(&err),
        seconds,
        mesh,
        json,
    }
}

/// Without `--repair`: exit status 1, `--repair` named on stderr, no mesh written. Flipped
/// triangles are the exception: the approximate mode takes inside and outside from the
/// surface's cells, not from the triangles' orientation, so it meshes them as they are.
fn check_refusal(d: &Dirty) {
    let dir = scratch(&format!("refuse-{}", d.name));
    let run = run_cli(d, &dir.0, false, Duration::from_secs(120));
    let name = &d.name;
    assert!(
        !run.timed_out,
        "{name}: still running after {:.0}s without --repair (expected a prompt refusal)",
        run.seconds
    );
    if d.name.starts_with("flipped") {
        assert_eq!(
            run.code,
            Some(0),
            "{name}: flipped triangles need no repair\nstderr (tail):\n{}",
            tail(&run.stderr, 20)
        );
        return;
    }
    let mut failures = Vec::new();
    if run.code != Some(1) {
        failures.push(format!("exit code {:?}, expected 1", run.code));
    }
    if !run.stderr.contains("--repair") {
        failures.push("stderr does not mention --repair".to_string());
    }
    if run.mesh.exists() {
        failures.push(format!("{} was written", run.mesh.display()));
    }
    assert!(
        failures.is_empty(),
        "{name} without --repair:\n  {}\nstderr (tail):\n{}\nstdout (tail):\n{}",
        failures.join("\n  "),
        tail(&run.stderr, 20),
        tail(&run.stdout, 20)
    );
}

/// The repaired runs one at a time, so that each has the machine to itself for its time limit.
static ONE_RUN_AT_A_TIME: Mutex<()> = Mutex::new(());

/// Faces of exactly one tet, oriented out of it: the solid's boundary.
fn open_faces(m: &TetMesh) -> Vec<[u32; 3]> {
    let mut faces: HashMap<[u32; 3], ([u32; 3], u32)> = HashMap::new();
    for t in &m.tets {
        for f in [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]] {
            let face = f.map(|k| t[k]);
            let mut key = face;
            key.sort_unstable();
            faces.entry(key).or_insert((face, 0)).1 += 1;
        }
    }
    faces
        .into_values()
        .filter(|f| f.1 == 1)
        .map(|f| f.0)
        .collect()
}

/// Share of the area of `input` within `bound` of the triangles of `tree`: each triangle cut
/// into n x n congruent triangles (edges at most `spacing`, n at most 16), each represented by
/// its centroid, weighted by its area.
fn area_share_within(input: &Surface, tree: &TriangleTree, bound: f64, spacing: f64) -> f64 {
    let (mut near, mut total) = (0.0, 0.0);
    let mut hint = 0;
    for k in 0..input.triangles.len() {
        let [a, b, c] = input.corners(k);
        let area = (b - a).cross(c - a).length() / 2.0;
        let longest = a.distance(b).max(b.distance(c)).max(c.distance(a));
        let n = ((longest / spacing).ceil() as usize).clamp(1, 16);
        let w = area / (n * n) as f64;
        let (u, v) = ((b - a) / n as f64, (c - a) / n as f64);
        for i in 0..n {
            for j in 0..n - i {
                // The upward sub-triangle at (i, j) and, but in the last row, the downward one.
                let base = a + u * i as f64 + v * j as f64;
                let mut centroids = vec![base + (u + v) / 3.0];
                if i + j + 1 < n {
                    centroids.push(base + (u + v) * (2.0 / 3.0));
                }
                for p in centroids {
                    total += w;
                    if tree.distance(p, &mut hint) <= bound {
                        near += w;
                    }
                }
            }
        }
    }
    near / total
}

/// With `--repair` (release builds): within the time limit, exit 0; the written mesh has only
/// positive tets, a smallest dihedral angle of at least 20 degrees, the expected volume, and a
/// boundary near the input. Every failed check is reported together.
fn check_repair(d: &Dirty) {
    if cfg!(debug_assertions) {
        eprintln!("skipped in a debug build: run cargo test --release");
        return;
    }
    let name = &d.name;
    let dir = scratch(&format!("repair-{name}"));
    let run = {
        let _one = ONE_RUN_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
        run_cli(d, &dir.0, true, Duration::from_secs_f64(TIME_LIMIT + 5.0))
    };
    let seconds = run.seconds;
    assert!(
        run.code == Some(0) && seconds <= TIME_LIMIT,
        "{name}: slivermesh mesh --repair: exit code {:?}{} after {seconds:.1}s (limit \
         {TIME_LIMIT}s)\nstderr (tail):\n{}\nstdout (tail):\n{}",
        run.code,
        if run.timed_out { " (killed)" } else { "" },
        tail(&run.stderr, 20),
        tail(&run.stdout, 20)
    );
    let mesh = slivermesh::io::read_mesh(&run.mesh)
        .unwrap_or_else(|e| panic!("{name}: reading the written mesh: {e}"));
    let stats: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&run.json).unwrap())
            .unwrap_or_else(|e| panic!("{name}: the stats JSON: {e}"));
    let mut failures: Vec<String> = Vec::new();
    if !stats["surface"]["repair"].is_object() {
        failures.push("the stats JSON has no \"repair\" object".to_string());
    }
    // The output boundary lies on the input except where it spans holes (the report leaves
    // those out of its output -> input distance, measured on the written boundary).
    let out_in = stats["surface"]["hausdorff_output_to_input"]
        .as_f64()
        .unwrap_or(f64::NAN)
        / stats["surface"]["surface_distance"]
            .as_f64()
            .unwrap_or(f64::NAN);
    if out_in.is_nan() || out_in > OUT_IN_BOUNDS {
        failures.push(format!(
            "output -> input distance {out_in:.3} bounds > {OUT_IN_BOUNDS} (spans left out)"
        ));
    }

    let bad: Vec<usize> = (0..mesh.tets.len())
        .filter(|&i| {
            let p = mesh.tets[i].map(|v| mesh.vertices[v as usize]);
            orient3d(p[0], p[1], p[2], p[3]) <= 0.0
        })
        .collect();
    if !bad.is_empty() {
        failures.push(format!(
            "{} tets are inverted or flat (first: tet {})",
            bad.len(),
            bad[0]
        ));
    }

    let q = slivermesh::quality::measure(&mesh)
        .unwrap_or_else(|e| panic!("{name}: measuring the written mesh: {e}"));
    if q.min_dihedral_deg < MIN_DIHEDRAL {
        failures.push(format!(
            "min dihedral {:.3} deg < {MIN_DIHEDRAL} (tets below 5/10/15/20 deg: {:?})",
            q.min_dihedral_deg, q.tets_below_deg
        ));
    }

    let want = d.expected_volume;
    let rel_volume = (q.volume - want) / want;
    let tol = volume_tolerance(d.kind);
    if rel_volume.abs() > tol {
        failures.push(format!(
            "volume {:.6} vs expected {want:.6} (clean {:.6}): relative difference \
             {rel_volume:+.3e} beyond {tol}",
            q.volume, d.clean_volume
        ));
    }

    // The input's area near the output boundary. Overlapping copies: not measured, half of
    // each copy lies inside the union and is rightly not on its boundary.
    let diag = d.surface.diagonal();
    let share = if d.all_on_boundary {
        let boundary = Surface {
            vertices: mesh.vertices.clone(),
            triangles: open_faces(&mesh),
        };
        let tree = TriangleTree::new(&boundary);
        let share = area_share_within(&d.surface, &tree, NEAR * diag, NEAR * diag / 2.0);
        if share < AREA_SHARE {
            failures.push(format!(
                "{:.2}% of the input's area lies within {:.3e} (0.5% of the diagonal) of the \
                 output boundary, less than {:.0}%",
                100.0 * share,
                NEAR * diag,
                100.0 * AREA_SHARE
            ));
        }
        Some(share)
    } else {
        None
    };

    println!(
        "{name}: {} triangles, {seconds:.2}s, {} tets, min dihedral {:.2} deg, volume \
         {rel_volume:+.3e} (tolerance {tol}), out->in {out_in:.3} bounds, area within 0.5% \
         diag: {}",
        d.n_triangles(),
        mesh.tets.len(),
        q.min_dihedral_deg,
        share.map_or("not measured".to_string(), |s| format!("{:.2}%", 100.0 * s))
    );
    assert!(failures.is_empty(), "{name}:\n  {}", failures.join("\n  "));
}

/// For each corpus case (a constructor in tests/common/dirty.rs), one refusal test and one
/// repair test of that name; the repair tests of the cases after `open:` are ignored (not
/// meshed yet: see the case's comment).
macro_rules! per_case {
    ($($case:ident),* $(,)? ; open: $($open:ident),* $(,)?) => {
        mod refuses_without_repair {
            $(
                #[test]
                fn $case() {
                    super::check_refusal(&super::dirty::$case());
                }
            )*
            $(
                #[test]
                fn $open() {
                    super::check_refusal(&super::dirty::$open());
                }
            )*
        }
        mod repairs {
            $(
                #[test]
                fn $case() {
                    super::check_repair(&super::dirty::$case());
                }
            )*
            $(
                #[test]
                #[ignore = "open: the cell level's boundary does not converge (see issue 38)"]
                fn $open() {
                    super::check_repair(&super::dirty::$open());
                }
            )*
        }
        /// The macro's lists are the corpus's.
        #[test]
        fn corpus_cases_all_have_tests() {
            let mut listed = vec![$(stringify!($case)),* $(, stringify!($open))*];
            let mut cases: Vec<&str> = dirty::CASES.iter().map(|c| c.0).collect();
            listed.sort_unstable();
            cases.sort_unstable();
            assert_eq!(listed, cases);
        }
    };
}

per_case!(
    small_hole_sphere,
    small_hole_homer,
    small_hole_bear,
    open_bottom_dome,
    open_bottom_fandisk,
    overlap_sphere,
    flipped_bear,
    flipped_fandisk,
    soup_fandisk,
    soup_homer,
    crack_sphere,
    crack_bear,
    fold_slab;
    // Two homers 1% apart: where the copies' feet meet the union's boundary has a
    // near-tangential contact (two sheets across a gap far below the distance bound), and the
    // cell level's boundary extraction finds non-manifold edges there after every mend.
    open: overlap_homer,
);

// ---------------------------------------------------------------------------------------------
// The corpus itself (any build).

fn build(names: &[&str]) -> Vec<Dirty> {
    names
        .iter()
        .map(|n| {
            let (_, make) = dirty::CASES
                .iter()
                .find(|c| c.0 == *n)
                .unwrap_or_else(|| panic!("no case {n}"));
            let d = make();
            assert_eq!(d.name, *n);
            d
        })
        .collect()
}

fn cases_of(kind: Kind) -> Vec<Dirty> {
    // Built by name: the kind is in the name.
    let prefix = match kind {
        Kind::SmallHole => "small_hole",
        Kind::OpenBottom => "open_bottom",
        Kind::OverlappingCopies => "overlap",
        Kind::Flipped => "flipped",
        Kind::Soup => "soup",
        Kind::Crack => "crack",
        Kind::Fold => "fold",
    };
    let names: Vec<&str> = dirty::CASES
        .iter()
        .map(|c| c.0)
        .filter(|n| n.starts_with(prefix))
        .collect();
    let cases = build(&names);
    assert!(!cases.is_empty(), "no {kind:?} case");
    for d in &cases {
        assert_eq!(d.kind, kind, "{}", d.name);
    }
    cases
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b) / b
}

/// A model's name and constructor.
type Model = (&'static str, fn() -> Surface);

/// The closed models the corpus starts from.
const MODELS: [Model; 6] = [
    ("sphere", dirty::sphere),
    ("slab", dirty::slab),
    ("dome", dirty::dome),
    ("homer", dirty::homer),
    ("bear", dirty::bear),
    ("fandisk", dirty::fandisk),
];

/// The models the corpus starts from are closed, outward-oriented 2-manifolds without
/// self-intersections.
#[test]
fn corpus_models_are_closed_manifolds() {
    let turned: Model = ("fandisk_flat_face_down", dirty::fandisk_flat_face_down);
    for (name, make) in MODELS.into_iter().chain([turned]) {
        let s = make();
        s.check_closed_manifold()
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(s.volume() > 0.0, "{name}: volume {}", s.volume());
        assert_eq!(s.topology().0, 1, "{name}: components");
        assert!(s.triangles.len() < 50_000, "{name}: size");
        assert_eq!(
            dirty::count_crossings(&s, 1),
            0,
            "{name}: self-intersections"
        );
    }
    let (f, g) = (dirty::fandisk(), dirty::fandisk_flat_face_down());
    assert!(
        rel(g.volume(), f.volume()).abs() < 1e-12,
        "the rotation is exact"
    );
}

/// The column-integrated winding-number volume against the divergence theorem on the clean
/// models (the accuracy the generators' doc comments state), and on two overlapping cubes
/// whose union is known exactly.
#[test]
fn corpus_winding_volume_matches_divergence_volume() {
    for (name, make) in MODELS {
        let s = make();
        let w = dirty::winding_volume(&s, dirty::WINDING_GRID, f64::MIN);
        let r = rel(w.volume, s.volume());
        println!(
            "{name}: winding volume {:.6}, divergence {:.6}, relative {r:+.2e}, {} lines moved",
            w.volume,
            s.volume(),
            w.moved_columns
        );
        assert_eq!(w.unbalanced_columns, 0, "{name}");
        assert!(r.abs() <= 2e-4, "{name}: relative difference {r:+.3e}");
    }
    // [0, 1]^3 and [0.5, 1.5]^3: union 2 - 1/8; grid-aligned walls and coincident coordinates
    // (lines through edges are moved).
    let a = corpus::grid_box(DVec3::ZERO, DVec3::ONE, [3, 3, 3]);
    let b = corpus::grid_box(DVec3::splat(0.5), DVec3::splat(1.5), [3, 3, 3]);
    let mut both = a.clone();
    both.append(&b);
    let w = dirty::winding_volume(&both, dirty::WINDING_GRID, f64::MIN);
    println!(
        "cubes: union {:.6}, {} lines moved",
        w.volume, w.moved_columns
    );
    assert_eq!(w.unbalanced_columns, 0);
    assert!(rel(w.volume, 1.875).abs() < 2e-3, "union {}", w.volume);
    // Clipped at z = 0.25: 0.75 + 1 - 0.125.
    let w = dirty::winding_volume(&both, dirty::WINDING_GRID, 0.25);
    println!("cubes: clipped union {:.6}", w.volume);
    assert!(
        rel(w.volume, 1.625).abs() < 2e-3,
        "clipped union {}",
        w.volume
    );
}

/// Small holes: the patch's triangles are gone, leaving open edges along one simple loop; a
/// fan fill of the loop from its centroid encloses the clean volume within 0.1%.
#[test]
fn corpus_small_hole_leaves_one_open_loop() {
    for d in cases_of(Kind::SmallHole) {
        let name = &d.name;
        let removed = d.clean.triangles.len() - d.surface.triangles.len();
        assert!((20..=200).contains(&removed), "{name}: {removed} removed");
        assert!(corpus::edges_not_in_two(&d.surface.triangles) > 0, "{name}");
        let loops = dirty::boundary_loops(&d.surface).expect("simple loops");
        assert_eq!(loops.len(), 1, "{name}: one hole");
        assert!(
            rel(d.surface.area() + d.hole_area, d.clean.area()).abs() < 1e-9,
            "{name}: hole area"
        );
        assert_eq!(d.expected_volume, d.clean_volume);
        let filled = fan_fill(&d.surface, &loops[0]);
        filled
            .check_closed_manifold()
            .unwrap_or_else(|e| panic!("{name}: fan fill: {e}"));
        let r = rel(filled.volume(), d.clean_volume);
        println!(
            "{name}: {removed} triangles removed, hole area {:.3e} ({:.2}%), loop of {}, fan \
             fill volume {r:+.2e}",
            d.hole_area,
            100.0 * d.hole_area / d.clean.area(),
            loops[0].len()
        );
        assert!(r.abs() < 3e-3, "{name}: fan fill volume {r:+.3e}");
    }
}

/// `s` with the loop closed by a fan from its centroid (the loop oriented as the holes'
/// boundary edges run in `s`, reversed).
fn fan_fill(s: &Surface, lp: &[u32]) -> Surface {
    let mut out = s.clone();
    let c = lp.iter().map(|&v| s.vertices[v as usize]).sum::<DVec3>() / lp.len() as f64;
    out.vertices.push(c);
    let cid = out.vertices.len() as u32 - 1;
    // Is the directed edge lp[0] -> lp[1] used by a triangle of s? Then the fill runs the
    // other way.
    let used = s
        .triangles
        .iter()
        .any(|t| (0..3).any(|i| t[i] == lp[0] && t[(i + 1) % 3] == lp[1]));
    for k in 0..lp.len() {
        let (a, b) = (lp[k], lp[(k + 1) % lp.len()]);
        out.triangles
            .push(if used { [b, a, cid] } else { [a, b, cid] });
    }
    out
}

/// Open bottoms: about a quarter of the area removed, along one planar loop; the expected
/// volume (the solid above the plane) is the clean volume on these flat bottoms.
#[test]
fn corpus_open_bottom_removes_a_flat_quarter() {
    for d in cases_of(Kind::OpenBottom) {
        let name = &d.name;
        let share = d.hole_area / d.clean.area();
        assert!(
            (0.2..=0.3).contains(&share),
            "{name}: {share} of the area removed"
        );
        assert!(corpus::edges_not_in_two(&d.surface.triangles) > 0, "{name}");
        let loops = dirty::boundary_loops(&d.surface).expect("simple loops");
        assert_eq!(loops.len(), 1, "{name}: one opening");
        let zs: Vec<f64> = loops[0]
            .iter()
            .map(|&v| d.surface.vertices[v as usize].z)
            .collect();
        let (zlo, zhi) = zs
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), &z| (l.min(z), h.max(z)));
        assert!(
            zhi - zlo <= 1e-12,
            "{name}: rim not planar ({zlo} to {zhi})"
        );
        let filled = fan_fill(&d.surface, &loops[0]);
        let r_fill = rel(filled.volume(), d.clean_volume);
        let r = rel(d.expected_volume, d.clean_volume);
        println!(
            "{name}: {:.2}% of the area removed, rim of {} at z = {zlo}, expected volume \
             {:.6} ({r:+.2e} from clean), fan fill {r_fill:+.2e}",
            100.0 * share,
            loops[0].len(),
            d.expected_volume
        );
        assert!(
            r_fill.abs() < 1e-12,
            "{name}: the flat fill is the clean bottom"
        );
        assert!(
            r.abs() < 2e-4,
            "{name}: expected volume {r:+.3e} from clean"
        );
    }
}

/// Overlapping copies: two closed copies whose triangles cross; the union's volume agrees with
/// the analytic lens formula on the sphere.
#[test]
fn corpus_overlapping_copies_cross() {
    for d in cases_of(Kind::OverlappingCopies) {
        let name = &d.name;
        assert_eq!(d.surface.triangles.len(), 2 * d.clean.triangles.len());
        d.surface
            .check_closed_manifold()
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(d.surface.topology().0, 2, "{name}: two copies");
        let crossings = dirty::count_crossings(&d.surface, 10);
        assert!(crossings >= 1, "{name}: the copies do not cross");
        let r = rel(d.expected_volume, d.clean_volume);
        println!(
            "{name}: {crossings}+ crossing edge-triangle pairs, union {:.6} ({r:+.3e} over \
             one copy)",
            d.expected_volume
        );
        assert!(r > 0.0 && r < 0.2, "{name}: union {r:+.3e} over one copy");
        if name == "overlap_sphere" {
            // Balls of radius R at distance t: the union adds V - lens = pi (4R + t)(2R - t)^2
            // / 12 short of V, i.e. about pi R^2 t.
            let (big_r, t): (f64, f64) = (0.5, 0.01 * d.clean.diagonal());
            let ball = 4.0 / 3.0 * std::f64::consts::PI * big_r.powi(3);
            let lens = std::f64::consts::PI * (4.0 * big_r + t) * (2.0 * big_r - t).powi(2) / 12.0;
            let added = d.expected_volume - d.clean_volume;
            let r = rel(added, ball - lens);
            println!(
                "{name}: added volume {added:.6}, analytic {:.6} ({r:+.2e})",
                ball - lens
            );
            assert!(
                r.abs() < 2e-2,
                "{name}: added volume {r:+.3e} from analytic"
            );
        }
    }
}

/// Flipped: exactly 5% of the triangles (rounded) reversed, the rest and the vertices as they
/// were.
#[test]
fn corpus_flipped_reverses_five_percent() {
    for d in cases_of(Kind::Flipped) {
        let name = &d.name;
        assert_eq!(d.surface.vertices, d.clean.vertices, "{name}");
        let n = d.clean.triangles.len();
        let reversed: Vec<usize> = (0..n)
            .filter(|&k| d.surface.triangles[k] != d.clean.triangles[k])
            .collect();
        for &k in &reversed {
            let [a, b, c] = d.clean.triangles[k];
            assert_eq!(d.surface.triangles[k], [a, c, b], "{name}: triangle {k}");
        }
        let want = (0.05 * n as f64).round() as usize;
        assert_eq!(reversed.len(), want, "{name}: flipped count");
        assert_eq!(reversed, dirty::flipped_set(n, 0.05));
        assert!(
            d.surface.check_closed_manifold().is_err(),
            "{name}: still consistent"
        );
        println!("{name}: {} of {n} triangles flipped", reversed.len());
    }
}

/// Soup: each triangle on its own three vertices at the clean corners' exact coordinates, so
/// every edge is open; merging equal coordinates gives the clean surface back.
#[test]
fn corpus_soup_has_three_vertices_per_triangle() {
    for d in cases_of(Kind::Soup) {
        let name = &d.name;
        let n = d.clean.triangles.len();
        assert!(
            !d.stl,
            "{name}: .off (the STL reader merges equal coordinates)"
        );
        assert_eq!(d.surface.triangles.len(), n);
        assert_eq!(d.surface.vertices.len(), 3 * n, "{name}");
        for k in 0..n {
            assert_eq!(
                d.surface.corners(k),
                d.clean.corners(k),
                "{name}: triangle {k}"
            );
        }
        assert_eq!(
            corpus::edges_not_in_two(&d.surface.triangles),
            3 * n,
            "{name}"
        );
        let mut ids: HashMap<[u64; 3], u32> = HashMap::new();
        let mut welded = Surface::default();
        for k in 0..n {
            let t = d.surface.corners(k).map(|p| {
                *ids.entry(p.to_array().map(f64::to_bits))
                    .or_insert_with(|| {
                        welded.vertices.push(p);
                        welded.vertices.len() as u32 - 1
                    })
            });
            welded.triangles.push(t);
        }
        welded
            .check_closed_manifold()
            .unwrap_or_else(|e| panic!("{name}: welded: {e}"));
        assert_eq!(welded.vertices.len(), d.clean.vertices.len(), "{name}");
    }
}

/// Crack: a disk cut loose along a loop (two components, two boundary loops of the same
/// length), its loop moved in by about 0.2% of the diagonal; nothing crosses.
#[test]
fn corpus_crack_opens_a_thin_loop() {
    for d in cases_of(Kind::Crack) {
        let name = &d.name;
        assert!(corpus::edges_not_in_two(&d.surface.triangles) > 0, "{name}");
        let loops = dirty::boundary_loops(&d.surface).expect("simple loops");
        assert_eq!(loops.len(), 2, "{name}: two loops");
        assert_eq!(loops[0].len(), loops[1].len(), "{name}");
        assert_eq!(d.surface.topology().0, 2, "{name}: the disk is loose");
        assert_eq!(d.surface.triangles.len(), d.clean.triangles.len());
        // Each loop vertex's copy (same index order: copies are appended in loop order).
        let diag = d.clean.diagonal();
        let n_clean = d.clean.vertices.len() as u32;
        let (outer, inner) = if loops[0][0] < n_clean {
            (&loops[0], &loops[1])
        } else {
            (&loops[1], &loops[0])
        };
        assert!(outer.iter().all(|&v| v < n_clean) && inner.iter().all(|&v| v >= n_clean));
        let gaps: Vec<f64> = inner
            .iter()
            .map(|&v| {
                let p = d.surface.vertices[v as usize];
                outer
                    .iter()
                    .map(|&u| p.distance(d.surface.vertices[u as usize]))
                    .fold(f64::MAX, f64::min)
            })
            .collect();
        let (gmin, gmax) = gaps
            .iter()
            .fold((f64::MAX, f64::MIN), |(l, h), &g| (l.min(g), h.max(g)));
        println!(
            "{name}: loops of {}, gap {:.2e} to {:.2e} of the diagonal",
            outer.len(),
            gmin / diag,
            gmax / diag
        );
        assert!(
            gmin >= 1e-3 * diag && gmax <= 4e-3 * diag,
            "{name}: gap {gmin:.3e} to {gmax:.3e}, diagonal {diag:.3e}"
        );
        assert_eq!(
            dirty::count_crossings(&d.surface, 1),
            0,
            "{name}: crossings"
        );
    }
}

/// Fold: still a closed, consistently oriented manifold, but self-intersecting; winding
/// numbers 0 in the dent's tube, -1 in its tip, 1 in the body; the expected volume (where
/// w >= 1) lies between the divergence volume (w integrated: the tip counts negative) and the
/// clean volume.
#[test]
fn corpus_fold_intersects_itself() {
    for d in cases_of(Kind::Fold) {
        let name = &d.name;
        d.surface
            .check_closed_manifold()
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let crossings = dirty::count_crossings(&d.surface, 10);
        assert!(crossings >= 1, "{name}: no self-intersection");
        let (top, n, thickness) = dirty::fold_axis(&d.clean);
        let w = |p: DVec3| dirty::winding_number(&d.surface, p);
        let (in_tube, in_tip) = (top - n * (0.5 * thickness), top - n * (1.1 * thickness));
        let (lo, hi) = d.clean.bbox();
        let in_body = top - n * (0.5 * thickness) + DVec3::X * (0.25 * (hi.x - lo.x));
        assert_eq!(w(in_tube), 0, "{name}: tube");
        assert_eq!(w(in_tip), -1, "{name}: tip");
        assert_eq!(w(in_body), 1, "{name}: body");
        assert_eq!(w(hi + DVec3::ONE), 0, "{name}: outside");
        let divergence = d.surface.volume();
        // The share of the area not on the boundary of {w >= 1} (the dent's tip, the bottom
        // inside the tube): each triangle near the axis classified by its centroid, from the
        // winding numbers just off either side.
        let (mut off, mut total) = (0.0, 0.0);
        let eps = 1e-7 * d.clean.diagonal();
        for k in 0..d.surface.triangles.len() {
            let [a, b, c] = d.surface.corners(k);
            let cross = (b - a).cross(c - a);
            let area = cross.length() / 2.0;
            total += area;
            let g = (a + b + c) / 3.0;
            let axis_distance = (g - top).reject_from(n).length();
            if axis_distance < 0.2 {
                let normal = cross.normalize();
                let (inner, outer) = (w(g - normal * eps), w(g + normal * eps));
                if (inner >= 1) == (outer >= 1) {
                    off += area;
                }
            }
        }
        println!(
            "{name}: {crossings}+ crossings; {{w >= 1}} {:.6} ({:+.3e} from clean), divergence \
             {divergence:.6}; {:.2}% of the area off its boundary",
            d.expected_volume,
            rel(d.expected_volume, d.clean_volume),
            100.0 * off / total
        );
        assert!(
            off > 0.0 && off < 0.01 * total,
            "{name}: {off} of {total} off the boundary"
        );
        assert!(divergence < d.expected_volume && d.expected_volume < d.clean_volume);
        assert!(
            rel(d.expected_volume, d.clean_volume) > -0.05,
            "{name}: a thin fold"
        );
    }
}

/// Every case: a unique name, under 100,000 triangles, a file the crate's readers parse into
/// one facet per triangle.
#[test]
fn corpus_cases_parse_back() {
    let cases = dirty::corpus();
    let mut names: Vec<&str> = cases.iter().map(|d| d.name.as_str()).collect();
    names.sort_unstable();
    names.dedup();
    assert_eq!(names.len(), cases.len(), "unique names");
    let opts = slivermesh::io::ReadOptions {
        merge_coplanar: false,
    };
    for d in &cases {
        assert!(d.n_triangles() < 100_000, "{}", d.name);
        let text = d.file_text();
        let plc = if d.stl {
            slivermesh::io::stl::parse_stl(text.as_bytes(), &opts)
        } else {
            slivermesh::io::off::parse_off(&text, &opts)
        }
        .unwrap_or_else(|e| panic!("{}: parsing the written file: {e}", d.name));
        assert_eq!(plc.facets.len(), d.n_triangles(), "{}", d.name);
        println!(
            "{}: {} triangles, clean volume {:.6}, expected {:.6} ({:+.2e}), hole area {:.3e}",
            d.name,
            d.n_triangles(),
            d.clean_volume,
            d.expected_volume,
            rel(d.expected_volume, d.clean_volume),
            d.hole_area
        );
    }
}

/// The area-share measure of the repair tests on known cases: a cube against itself, and
/// against the same cube moved by 0.01 along x with the bound 0.005. Then the far part of the
/// cube is its x = 0 face, its x = 1 face less a band 0.005 wide along the face's edges (near
/// the moved cube's y and z faces, which run on to x = 1.01), and a strip 0.005 wide along the
/// edge x = 0 of each of the four other faces.
#[test]
fn corpus_area_share_helper_measures_known_cases() {
    let a = corpus::grid_box(DVec3::ZERO, DVec3::ONE, [8, 8, 8]);
    let same = area_share_within(&a, &TriangleTree::new(&a), 1e-9, 0.01);
    assert!((same - 1.0).abs() < 1e-12, "{same}");
    let mut b = a.clone();
    for p in &mut b.vertices {
        p.x += 0.01;
    }
    let moved = area_share_within(&a, &TriangleTree::new(&b), 0.005, 0.002);
    let w: f64 = 0.005;
    let far = 1.0 + (1.0 - (4.0 * w - 4.0 * w * w)) + 4.0 * w;
    let want = (6.0 - far) / 6.0;
    assert!((moved - want).abs() < 1e-3, "{moved} against {want}");
}

/// Keep mode preserves every input facet, which a dirty surface does not allow: `--repair`
/// there is refused with a message saying which mode it needs, and nothing is written.
#[test]
fn repair_in_keep_mode_is_refused() {
    let d = dirty::small_hole_sphere();
    let dir = scratch("repair-keep");
    let input = dir.0.join(d.file_name());
    std::fs::write(&input, d.file_text()).unwrap();
    let mesh = dir.0.join("out.mesh");
    let run = Command::new(env!("CARGO_BIN_EXE_slivermesh"))
        .args(["mesh", "--surface", "keep", "--repair", "-o"])
        .arg(&mesh)
        .arg(&input)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert_eq!(run.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("approximate surface mode"), "{stderr}");
    assert!(!mesh.exists());
}

/// A clean input is meshed as it is with `--repair`: the same mesh, byte for byte, and the
/// faces two solids share stay interfaces (two regions, not one solid).
#[test]
fn repair_leaves_clean_inputs_unchanged() {
    let dir = scratch("repair-clean");
    let blocks = common::corpus::two_touching_blocks_stl();
    let stl = dir.0.join(blocks.file_name());
    std::fs::write(&stl, blocks.file_text()).unwrap();
    let inputs = [common::models_dir().join("off/cube.off"), stl];
    for input in &inputs {
        let mesh_with = |repair: bool| {
            let out = dir.0.join(format!("out-{repair}.mesh"));
            let mut cmd = Command::new(env!("CARGO_BIN_EXE_slivermesh"));
            cmd.arg("mesh").arg(input).arg("-o").arg(&out);
            if repair {
                cmd.arg("--repair");
            }
            let run = cmd.output().unwrap();
            assert!(
                run.status.success(),
                "{}",
                String::from_utf8_lossy(&run.stderr)
            );
            std::fs::read(&out).unwrap()
        };
        let plain = mesh_with(false);
        assert!(
            plain == mesh_with(true),
            "{}: --repair changed the mesh",
            input.display()
        );
    }
}
