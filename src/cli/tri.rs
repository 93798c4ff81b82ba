//! Triangulate a point set, measure it, report it: the body of `slivermesh delaunay` and of the
//! built-in demo.

use super::rss;
use serde::Serialize;
use slivermesh::delaunay::Delaunay;
use slivermesh::io::{self, CellField};
use slivermesh::{DVec3, TetMesh};
use std::path::Path;
use std::time::Instant;

/// What one triangulation run measured. Serialised as the `--stats-json` file.
///
/// `peak_rss_mb` is in 10^6 bytes (MB, not MiB) and `bytes_per_tet` is peak RSS bytes / finite
/// tets, both taken right after the triangulation (before any output mesh is built), the same
/// definitions `ctests/cgal_delaunay.cpp` uses. `kernel_bytes_per_tet` counts only the
/// triangulation's own arrays (`Delaunay::memory_bytes`).
#[derive(Debug, Clone, Serialize)]
pub struct Stats {
    pub n_points: usize,
    pub n_vertices: usize,
    pub n_duplicates: usize,
    pub n_tets: usize,
    /// Threads the triangulation ran on (`--threads`, 0 resolved to the core count).
    pub threads: usize,
    pub seconds: f64,
    pub points_per_second: f64,
    pub peak_rss_mb: Option<f64>,
    pub bytes_per_tet: Option<f64>,
    pub kernel_bytes: usize,
    pub kernel_bytes_per_tet: f64,
    /// Order-independent checksum of the set of finite tets (see [`tets_checksum`]), as 16 hex
    /// digits; equal checksums mean (with overwhelming probability) equal triangulations.
    pub tets_checksum: String,
    /// Seconds spent reading the point file (`slivermesh delaunay` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub read_seconds: Option<f64>,
}

/// Triangulates `points` on `threads` threads (0: all cores), timing only
/// `Delaunay::from_points_threads`. The triangulation (and `tets_checksum`) is the same for any
/// thread count.
pub fn triangulate(points: &[DVec3], threads: usize) -> Result<(Delaunay, Stats), String> {
    if points.is_empty() {
        return Err("no points to triangulate".into());
    }
    let t0 = Instant::now();
    let threads = slivermesh::delaunay::resolve_threads(threads);
    let (del, ins) = Delaunay::from_points_threads(points, threads).map_err(|e| e.to_string())?;
    let seconds = t0.elapsed().as_secs_f64();
    let peak = rss::peak_rss_bytes();
    let n_tets = del.num_finite_tets();
    let per_tet = |bytes: f64| {
        if n_tets > 0 {
            bytes / n_tets as f64
        } else {
            0.0
        }
    };
    let kernel_bytes = del.memory_bytes();
    let stats = Stats {
        n_points: points.len(),
        n_vertices: del.num_vertices(),
        n_duplicates: ins.duplicates,
        n_tets,
        threads,
        seconds,
        points_per_second: points.len() as f64 / seconds.max(1e-12),
        peak_rss_mb: peak.map(|b| b as f64 / 1e6),
        bytes_per_tet: peak.map(|b| per_tet(b as f64)),
        kernel_bytes,
        kernel_bytes_per_tet: per_tet(kernel_bytes as f64),
        tets_checksum: format!("{:016x}", tets_checksum(del.finite_tets())),
        read_seconds: None,
    };
    Ok((del, stats))
}

/// The short human summary printed by `slivermesh delaunay` and the demo.
pub fn summary(s: &Stats) -> String {
    let mut out = String::new();
    match s.read_seconds {
        Some(r) => out += &format!("points           {} (read in {r:.3} s)\n", s.n_points),
        None => out += &format!("points           {}\n", s.n_points),
    }
    out += &format!("vertices         {}\n", s.n_vertices);
    if s.n_duplicates > 0 {
        out += &format!("duplicates       {} (skipped)\n", s.n_duplicates);
    } else {
        out += "duplicates       0\n";
    }
    out += &format!("finite tets      {}\n", s.n_tets);
    out += &format!(
        "seconds          {:.3} (triangulation only, {} thread{})\n",
        s.seconds,
        s.threads,
        if s.threads == 1 { "" } else { "s" }
    );
    out += &format!("points/s         {:.0}\n", s.points_per_second);
    match (s.peak_rss_mb, s.bytes_per_tet) {
        (Some(mb), Some(bpt)) => {
            out += &format!("peak RSS         {mb:.1} MB\n");
            out += &format!("bytes/tet        {bpt:.1} (peak RSS / tets)\n");
        }
        _ => out += "peak RSS         unavailable (no /proc/self/status)\n",
    }
    out += &format!(
        "kernel bytes/tet {:.1} (triangulation arrays / tets)\n",
        s.kernel_bytes_per_tet
    );
    out
}

/// Builds the output mesh of a plain triangulation: every input point is a vertex (duplicates
/// included, unreferenced), tets are the finite tets, regions 0, no boundary.
pub fn to_mesh(points: &[DVec3], del: &Delaunay) -> TetMesh {
    let tets: Vec<[u32; 4]> = del.finite_tets().collect();
    TetMesh {
        vertices: points.to_vec(),
        tet_regions: vec![0; tets.len()],
        tets,
        boundary: Vec::new(),
        boundary_markers: Vec::new(),
    }
}

/// Writes the mesh to `path` (format by extension).
pub fn write(path: &Path, points: &[DVec3], del: &Delaunay) -> Result<(), String> {
    let mesh = to_mesh(points, del);
    let fields: [CellField; 0] = [];
    io::write_mesh(path, &mesh, &fields).map_err(|e| e.to_string())
}

/// Writes `stats` as pretty JSON.
pub fn write_stats_json(path: &Path, stats: &Stats) -> Result<(), String> {
    let mut text = serde_json::to_string_pretty(stats).map_err(|e| e.to_string())?;
    text.push('\n');
    std::fs::write(path, text).map_err(|e| format!("{}: cannot write: {e}", path.display()))
}

/// SplitMix64 finaliser.
fn mix(mut x: u64) -> u64 {
    x ^= x >> 30;
    x = x.wrapping_mul(0xbf58_476d_1ce4_e5b9);
    x ^= x >> 27;
    x = x.wrapping_mul(0x94d0_49bb_1331_11eb);
    x ^ (x >> 31)
}

/// Order-independent checksum of a set of tets: each tet's ids are sorted and hashed with
/// SplitMix64 (`h = mix(a); h = mix(h ^ b); h = mix(h ^ c); h = mix(h ^ d)`), and the hashes
/// are summed mod 2^64. `ctests/cgal_delaunay.cpp` computes the same function, so the two
/// triangulations can be compared tet by tet without writing them out.
pub fn tets_checksum(tets: impl Iterator<Item = [u32; 4]>) -> u64 {
    tets.fold(0u64, |acc, mut t| {
        t.sort_unstable();
        let mut h = mix(t[0] as u64);
        for &v in &t[1..] {
            h = mix(h ^ v as u64);
        }
        acc.wrapping_add(h)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn checksum_ignores_order_and_orientation() {
        let a = [[0, 1, 2, 3], [1, 2, 3, 4], [7, 5, 9, 8]];
        let b = [[9, 8, 7, 5], [4, 3, 2, 1], [1, 0, 3, 2]];
        assert_eq!(tets_checksum(a.into_iter()), tets_checksum(b.into_iter()));
        let c = [[0, 1, 2, 3], [1, 2, 3, 5], [7, 5, 9, 8]];
        assert_ne!(tets_checksum(a.into_iter()), tets_checksum(c.into_iter()));
        assert_eq!(tets_checksum(std::iter::empty()), 0);
    }

    #[test]
    fn checksum_known_value() {
        // Pinned so the C++ side (ctests/cgal_delaunay.cpp) can be checked against it.
        assert_eq!(
            format!("{:016x}", tets_checksum([[0u32, 1, 2, 3]].into_iter())),
            KNOWN_0123
        );
    }
    const KNOWN_0123: &str = "a55bdf37c08724b5"; // also computed independently in Python

    #[test]
    fn summary_mentions_every_figure() {
        let s = Stats {
            n_points: 10,
            n_vertices: 9,
            n_duplicates: 1,
            n_tets: 20,
            threads: 2,
            seconds: 0.5,
            points_per_second: 20.0,
            peak_rss_mb: Some(3.0),
            bytes_per_tet: Some(150000.0),
            kernel_bytes: 2000,
            kernel_bytes_per_tet: 100.0,
            tets_checksum: "0".into(),
            read_seconds: Some(0.25),
        };
        let text = summary(&s);
        for needle in [
            "10",
            "9",
            "1 (skipped)",
            "20",
            "0.500",
            "2 threads",
            "3.0 MB",
            "150000.0",
            "100.0",
        ] {
            assert!(text.contains(needle), "{needle} missing from\n{text}");
        }
    }
}
