//! Delaunay kernel benchmark: points per second and bytes per tet.
//!
//!     cargo bench --bench delaunay                 # full: uniform 1e5, 1e6, 4e6; grid, sphere 1e6
//!     cargo bench --bench delaunay -- quick        # uniform 1e5 only
//!     cargo bench --bench delaunay -- uniform:2e6 sphere:1e5   # any kind:n list
//!
//! (or set SLIVERMESH_BENCH to `quick`, `full` or such a list). Kinds: uniform, grid, sphere,
//! clustered, generated exactly as `slivermesh gen-points` does (seed 1), so figures are
//! comparable with `ctests/compare_delaunay.py`.
//!
//! Each case runs in a fresh child process (this binary re-executed with SLIVERMESH_BENCH_CASE)
//! so that its peak RSS (VmHWM) is its own. Peak RSS includes the input points (24 B each), as
//! the CGAL harness's does.

// The shared modules carry unit tests that are compiled out here.
#![allow(unused_imports)]

#[path = "../src/cli/gen.rs"]
#[allow(dead_code)]
mod gen;
#[path = "../src/cli/rss.rs"]
mod rss;

use gen::Kind;
use slivermesh::delaunay::Delaunay;
use std::process::Command;
use std::time::Instant;

const CASE_VAR: &str = "SLIVERMESH_BENCH_CASE";
const FULL: &str = "uniform:1e5 uniform:1e6 uniform:4e6 grid:1e6 sphere:1e6";
const QUICK: &str = "uniform:1e5";

fn parse_case(s: &str) -> Result<(Kind, usize), String> {
    let (k, n) = s
        .split_once(':')
        .ok_or_else(|| format!("bad case `{s}`: expected KIND:N, e.g. uniform:1e6"))?;
    let kind = Kind::from_name(k).ok_or_else(|| format!("bad case `{s}`: unknown kind `{k}`"))?;
    let n: f64 = n
        .parse()
        .map_err(|_| format!("bad case `{s}`: `{n}` is not a number"))?;
    if !(1.0..=1e9).contains(&n) {
        return Err(format!("bad case `{s}`: n must be in 1..=1e9"));
    }
    Ok((kind, n as usize))
}

/// Runs one case in this process and prints one tab-separated result line.
fn run_case(kind: Kind, n: usize) {
    let points = gen::generate(kind, n, 1);
    let t0 = Instant::now();
    let (del, ins) = match Delaunay::from_points(&points) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {}:{n}: {e}", kind.name());
            std::process::exit(1);
        }
    };
    let secs = t0.elapsed().as_secs_f64();
    let peak = rss::peak_rss_bytes().unwrap_or(0);
    let tets = del.num_finite_tets().max(1);
    println!(
        "RESULT\t{}\t{}\t{}\t{}\t{}\t{}\t{:.4}\t{:.3}\t{:.1}\t{:.1}",
        kind.name(),
        points.len(),
        del.num_vertices(),
        ins.duplicates,
        del.num_finite_tets(),
        del.memory_bytes(),
        secs,
        points.len() as f64 / secs / 1e6,
        peak as f64 / 1e6,
        peak as f64 / tets as f64,
    );
}

fn main() {
    if let Ok(case) = std::env::var(CASE_VAR) {
        match parse_case(&case) {
            Ok((kind, n)) => run_case(kind, n),
            Err(e) => {
                eprintln!("error: {e}");
                std::process::exit(2);
            }
        }
        return;
    }

    // `cargo bench` passes `--bench`; ignore flags, keep words.
    let words: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with('-'))
        .collect();
    let spec = if words.is_empty() {
        std::env::var("SLIVERMESH_BENCH").unwrap_or_else(|_| "full".into())
    } else {
        words.join(" ")
    };
    let spec = match spec.trim() {
        "quick" => QUICK.to_string(),
        "full" | "" => FULL.to_string(),
        other => other.to_string(),
    };
    let cases: Vec<&str> = spec.split([' ', ',']).filter(|s| !s.is_empty()).collect();
    for c in &cases {
        if let Err(e) = parse_case(c) {
            eprintln!("error: {e}");
            std::process::exit(2);
        }
    }

    let exe = std::env::current_exe().expect("current_exe");
    println!(
        "{:<10} {:>9} {:>9} {:>5} {:>10} {:>8} {:>8} {:>9} {:>10} {:>10}",
        "kind",
        "points",
        "vertices",
        "dups",
        "tets",
        "seconds",
        "Mpts/s",
        "peakRSS",
        "B/tet RSS",
        "B/tet kern"
    );
    let mut failed = false;
    for c in cases {
        let out = Command::new(&exe)
            .env(CASE_VAR, c)
            .output()
            .expect("spawn bench case");
        let stdout = String::from_utf8_lossy(&out.stdout);
        let line = stdout.lines().find(|l| l.starts_with("RESULT\t"));
        match (out.status.success(), line) {
            (true, Some(line)) => {
                let f: Vec<&str> = line.split('\t').collect();
                let tets: f64 = f[5].parse().unwrap_or(0.0);
                let kern: f64 = f[6].parse().unwrap_or(0.0);
                println!(
                    "{:<10} {:>9} {:>9} {:>5} {:>10} {:>8} {:>8} {:>8}M {:>10} {:>10.1}",
                    f[1],
                    f[2],
                    f[3],
                    f[4],
                    f[5],
                    f[7],
                    f[8],
                    f[9],
                    f[10],
                    kern / tets.max(1.0)
                );
            }
            _ => {
                failed = true;
                let stderr = String::from_utf8_lossy(&out.stderr);
                let why: Vec<&str> = stderr
                    .lines()
                    .filter(|l| !l.trim().is_empty() && !l.starts_with("note:"))
                    .take(3)
                    .collect();
                println!("{c:<10} FAILED ({}): {}", out.status, why.join(" | "));
            }
        }
    }
    if failed {
        std::process::exit(1);
    }
}
