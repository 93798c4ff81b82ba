//! The text the CLI prints: the quality table, the terminal histogram of the per-tet minimum
//! dihedral angle, and both side by side for two meshes.

use super::measure::{MeshQuality, ABOVE_DEG, BELOW_DEG, MIN_BINS, MIN_BIN_DEG};

/// A float with `prec` decimals, "inf" for +∞ (rho and aspect of a zero-volume tet).
fn fixed(x: f64, prec: usize) -> String {
    if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.to_string()
    } else {
        format!("{x:.prec$}")
    }
}

/// A shape measure with four decimals, in exponent form when that would hide it (a near-flat
/// tet's sigma of 1e-12, its aspect of 1e14).
fn shape(x: f64) -> String {
    if x.is_finite() && x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
        format!("{x:.4e}")
    } else {
        fixed(x, 4)
    }
}

/// A length or volume with six significant digits, whatever the mesh's scale.
fn sig(x: f64) -> String {
    if x == 0.0 || (1e-2..1e6).contains(&x.abs()) {
        let decimals = (5 - x.abs().log10().floor().max(0.0) as i32).max(0) as usize;
        fixed(x, decimals)
    } else {
        format!("{x:.5e}")
    }
}

fn counts(c: &[usize; 4]) -> String {
    c.map(|n| n.to_string()).join(" / ")
}

fn thresholds(t: &[f64; 4]) -> String {
    t.map(|x| format!("{x}")).join("/")
}

/// The table's rows (label, value), in print order. Angles have two decimals.
pub fn rows(q: &MeshQuality) -> Vec<(String, String)> {
    let d2 = |x: f64| fixed(x, 2);
    let mut r: Vec<(String, String)> = Vec::new();
    let mut row = |k: &str, v: String| r.push((k.to_string(), v));
    row(
        "vertices (used / total)",
        format!("{} / {}", q.n_used_vertices, q.n_vertices),
    );
    row("tets", q.n_tets.to_string());
    row("boundary triangles", q.n_boundary_faces.to_string());
    row("regions", q.n_regions.to_string());
    row(
        "inverted / zero-volume tets",
        format!("{} / {}", q.n_inverted, q.n_zero_volume),
    );
    row("volume (signed sum)", sig(q.volume));
    row(
        "edge length min / max",
        format!("{} / {}", sig(q.shortest_edge), sig(q.longest_edge)),
    );
    row(
        "dihedral min / max (deg)",
        format!("{} / {}", d2(q.min_dihedral_deg), d2(q.max_dihedral_deg)),
    );
    row(
        "tet min dihedral p1/p5/p50",
        format!(
            "{} / {} / {}",
            d2(q.min_dihedral_p1_deg),
            d2(q.min_dihedral_p5_deg),
            d2(q.min_dihedral_median_deg)
        ),
    );
    row(
        "tet max dihedral p50/p95/p99",
        format!(
            "{} / {} / {}",
            d2(q.max_dihedral_median_deg),
            d2(q.max_dihedral_p95_deg),
            d2(q.max_dihedral_p99_deg)
        ),
    );
    row(
        &format!("tets below {} deg", thresholds(&BELOW_DEG)),
        counts(&q.tets_below_deg),
    );
    row(
        &format!("tets above {} deg", thresholds(&ABOVE_DEG)),
        counts(&q.tets_above_deg),
    );
    row(
        "rho R/L max / median",
        format!("{} / {}", shape(q.max_rho), shape(q.median_rho)),
    );
    row(
        "sigma V/L^3 min / median",
        format!("{} / {}", shape(q.min_sigma), shape(q.median_sigma)),
    );
    row(
        "aspect R/(3r) max / median",
        format!("{} / {}", shape(q.max_aspect), shape(q.median_aspect)),
    );
    row("worst tet (0-based)", q.worst_tet.to_string());
    r
}

/// The quality table of one mesh.
pub fn table(q: &MeshQuality) -> String {
    let rows = rows(q);
    let w = rows.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
    rows.iter()
        .map(|(k, v)| format!("  {k:<w$}  {v}\n"))
        .collect()
}

/// The quality tables of two meshes side by side, headed by their names.
pub fn compare_table(name_a: &str, a: &MeshQuality, name_b: &str, b: &MeshQuality) -> String {
    let (ra, rb) = (rows(a), rows(b));
    let w = ra.iter().map(|(k, _)| k.len()).max().unwrap_or(0);
    let wa = ra
        .iter()
        .map(|(_, v)| v.len())
        .chain([name_a.chars().count()])
        .max()
        .unwrap_or(0);
    let mut s = format!("  {:<w$}  {name_a:<wa$}  {name_b}\n", "");
    for ((k, va), (_, vb)) in ra.iter().zip(&rb) {
        s.push_str(&format!("  {k:<w$}  {va:<wa$}  {vb}\n"));
    }
    s
}

/// Bar of `len` characters out of `width` for a fraction `f` of the largest one; a non-zero
/// count always gets at least one character, so a few bad tets stay visible.
fn bar(count: usize, f: f64, width: usize) -> String {
    let len = if count == 0 {
        0
    } else {
        ((f * width as f64).round() as usize).clamp(1, width)
    };
    "#".repeat(len)
}

fn bin_label(i: usize) -> String {
    let lo = i as f64 * MIN_BIN_DEG;
    format!("{:>2}-{:<2}", lo, lo + MIN_BIN_DEG)
}

/// Terminal histogram of the per-tet minimum dihedral angle (5-degree bins, counts and bars).
pub fn histogram_text(q: &MeshQuality) -> String {
    let h = &q.min_dihedral_histogram;
    let last = last_bin(&[h]);
    let max = h.iter().copied().max().unwrap_or(0).max(1);
    let cw = h.iter().map(|c| c.to_string().len()).max().unwrap_or(1);
    let mut s = String::from("  tets by minimum dihedral angle (deg)\n");
    for (i, &c) in h.iter().enumerate().take(last + 1) {
        let b = bar(c, c as f64 / max as f64, 50);
        s.push_str(&format!("  {}  {c:>cw$} |{b}\n", bin_label(i)));
    }
    s
}

/// The last bin worth printing: empty bins beyond the largest used one are left out.
fn last_bin(hs: &[&[usize; MIN_BINS]]) -> usize {
    hs.iter()
        .filter_map(|h| h.iter().rposition(|&c| c > 0))
        .max()
        .unwrap_or(MIN_BINS - 1)
}

/// The two histograms side by side; bars show each mesh's share of its tets, on one scale.
pub fn compare_histogram_text(
    name_a: &str,
    a: &MeshQuality,
    name_b: &str,
    b: &MeshQuality,
) -> String {
    let (ha, hb) = (&a.min_dihedral_histogram, &b.min_dihedral_histogram);
    let last = last_bin(&[ha, hb]);
    let frac = |c: usize, q: &MeshQuality| c as f64 / q.n_tets.max(1) as f64;
    let max = ha
        .iter()
        .map(|&c| frac(c, a))
        .chain(hb.iter().map(|&c| frac(c, b)))
        .fold(0.0, f64::max);
    let max = if max > 0.0 { max } else { 1.0 };
    let cw = ha
        .iter()
        .chain(hb)
        .map(|c| c.to_string().len())
        .max()
        .unwrap_or(1);
    const W: usize = 28;
    let mut s = format!(
        "  tets by minimum dihedral angle (deg); bars: share of each mesh's tets\n  {:5}  {:>cw$}  {name_a:<W$} {:>cw$}  {name_b}\n",
        "", "", ""
    );
    for i in 0..=last {
        let (ca, cb) = (ha[i], hb[i]);
        let (ba, bb) = (bar(ca, frac(ca, a) / max, W), bar(cb, frac(cb, b) / max, W));
        s.push_str(&format!(
            "  {}  {ca:>cw$} |{ba:<W$} {cb:>cw$} |{bb}\n",
            bin_label(i)
        ));
    }
    s
}
