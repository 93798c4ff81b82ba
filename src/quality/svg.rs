//! The histogram picture: all dihedral angles of a mesh (1-degree bins, 0-180), the 5, 10, 15
//! and 20 degree lines, and a legend with the figures that matter; a second mesh is drawn as an
//! outline over the first. Plain SVG 1.1 text, no scripts, byte-identical for the same input.

use super::measure::{MeshQuality, BELOW_DEG};
use std::fmt::Write;

/// One mesh of the picture: its name, [`super::dihedral_histogram`] and figures.
pub struct SvgSeries<'a> {
    pub name: &'a str,
    pub bins: &'a [usize],
    pub quality: &'a MeshQuality,
}

const W: f64 = 900.0;
const H: f64 = 480.0;
const LEFT: f64 = 72.0;
const RIGHT: f64 = 24.0;
const TOP: f64 = 44.0;
const BOTTOM: f64 = 52.0;
/// Fill of the first mesh's bars, stroke of the second mesh's outline.
const COLOURS: [&str; 2] = ["#4c78a8", "#e45756"];
/// One colour per threshold line, darkest for 5 degrees.
const LINE_COLOURS: [&str; 4] = ["#7a0019", "#b2182b", "#d6604d", "#f4a582"];

/// Escapes text for XML content and attribute values.
fn esc(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            // Control characters are not allowed in XML 1.0.
            c if (c as u32) < 0x20 && c != '\t' => o.push(' '),
            c => o.push(c),
        }
    }
    o
}

/// A "nice" tick step (1, 2 or 5 times a power of ten) for about five ticks up to `max`, at
/// least `min_step`.
fn tick_step(max: f64, min_step: f64) -> f64 {
    let raw = (max / 5.0).max(min_step);
    let p = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * p)
        .find(|&s| s >= raw * (1.0 - 1e-12))
        .unwrap_or(10.0 * p)
}

/// The picture of one or two meshes (the first as bars, the second as an outline). One mesh is
/// drawn in angle counts; two are drawn in shares of their angles (%), so meshes of different
/// sizes compare.
pub fn svg(title: &str, series: &[SvgSeries]) -> String {
    let (pw, ph) = (W - LEFT - RIGHT, H - TOP - BOTTOM);
    let share = series.len() > 1;
    let values: Vec<Vec<f64>> = series
        .iter()
        .map(|s| {
            let total = s.bins.iter().sum::<usize>().max(1) as f64;
            let scale = if share { 100.0 / total } else { 1.0 };
            s.bins.iter().map(|&c| c as f64 * scale).collect()
        })
        .collect();
    let max = values.iter().flatten().copied().fold(0.0, f64::max);
    let step = tick_step(max.max(1e-9), if share { 1e-3 } else { 1.0 });
    let ymax = (max / step).ceil().max(1.0) * step;
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    let x = |deg: f64| LEFT + deg / 180.0 * pw;
    let y = |count: f64| TOP + ph - count / ymax * ph;
    let mut s = String::new();
    let o = &mut s;
    // Writing to a String cannot fail.
    let _ = writeln!(o, r#"<?xml version="1.0" encoding="UTF-8"?>"#);
    let _ = writeln!(
        o,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" viewBox="0 0 {W} {H}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(o, r#"<rect width="{W}" height="{H}" fill="white"/>"#);
    let _ = writeln!(
        o,
        r#"<text x="{}" y="24" text-anchor="middle" font-size="15" font-weight="bold">{}</text>"#,
        W / 2.0,
        esc(title)
    );
    // Axes, grid and ticks.
    for i in 0..=(ymax / step).round() as usize {
        let k = i as f64 * step;
        let yy = y(k);
        let _ = writeln!(
            o,
            "<line x1=\"{LEFT}\" y1=\"{yy:.1}\" x2=\"{:.1}\" y2=\"{yy:.1}\" stroke=\"#e0e0e0\"/>\n<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">{k:.decimals$}</text>",
            LEFT + pw,
            LEFT - 6.0,
            yy + 4.0
        );
    }
    for deg in (0..=180).step_by(10) {
        let xx = x(deg as f64);
        let _ = writeln!(
            o,
            "<line x1=\"{xx:.1}\" y1=\"{:.1}\" x2=\"{xx:.1}\" y2=\"{:.1}\" stroke=\"black\"/>\n<text x=\"{xx:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{deg}</text>",
            TOP + ph,
            TOP + ph + 5.0,
            TOP + ph + 18.0
        );
    }
    let _ = writeln!(
        o,
        "<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">dihedral angle (degrees), 1-degree bins</text>",
        LEFT + pw / 2.0,
        H - 12.0
    );
    let _ = writeln!(
        o,
        "<text transform=\"translate(18 {:.1}) rotate(-90)\" text-anchor=\"middle\">{}</text>",
        TOP + ph / 2.0,
        if share {
            "share of each mesh's angles (%)"
        } else {
            "angles (6 per tet)"
        }
    );
    // First mesh: bars; a non-empty bin is at least a pixel tall so lone bad angles show.
    if let Some(first) = series.first() {
        let _ = writeln!(o, r#"<g id="bars" fill="{}">"#, COLOURS[0]);
        for (i, &c) in first.bins.iter().enumerate().filter(|(_, &c)| c > 0) {
            let h = (ph - (y(values[0][i]) - TOP)).max(1.0);
            let _ = writeln!(
                o,
                "<rect class=\"bar\" x=\"{:.2}\" y=\"{:.2}\" width=\"{:.2}\" height=\"{h:.2}\"><title>{i}-{} deg: {c}</title></rect>",
                x(i as f64),
                TOP + ph - h,
                pw / 180.0,
                i + 1
            );
        }
        let _ = writeln!(o, "</g>");
    }
    // Second mesh: a step outline.
    if series.len() > 1 {
        let mut pts = format!("{:.2},{:.2}", x(0.0), y(0.0));
        for (i, &v) in values[1].iter().enumerate() {
            let yy = y(v);
            let _ = write!(
                pts,
                " {:.2},{yy:.2} {:.2},{yy:.2}",
                x(i as f64),
                x(i as f64 + 1.0)
            );
        }
        let _ = write!(pts, " {:.2},{:.2}", x(180.0), y(0.0));
        let _ = writeln!(
            o,
            r#"<polyline id="outline" points="{pts}" fill="none" stroke="{}" stroke-width="1.5"/>"#,
            COLOURS[1]
        );
    }
    // The threshold lines, labelled above the plot.
    for (k, &deg) in BELOW_DEG.iter().enumerate() {
        let xx = x(deg);
        let _ = writeln!(
            o,
            "<line class=\"threshold\" x1=\"{xx:.2}\" y1=\"{TOP}\" x2=\"{xx:.2}\" y2=\"{:.1}\" stroke=\"{}\" stroke-width=\"1.2\" stroke-dasharray=\"5,3\"/>\n<text x=\"{xx:.2}\" y=\"{:.1}\" text-anchor=\"middle\" font-size=\"10\" fill=\"{}\">{deg}°</text>",
            TOP + ph,
            LINE_COLOURS[k],
            TOP - 4.0,
            LINE_COLOURS[k]
        );
    }
    let _ = writeln!(
        o,
        "<line x1=\"{LEFT}\" y1=\"{TOP}\" x2=\"{LEFT}\" y2=\"{:.1}\" stroke=\"black\"/>\n<line x1=\"{LEFT}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"black\"/>",
        TOP + ph,
        TOP + ph,
        LEFT + pw,
        TOP + ph
    );
    legend(o, series, LEFT + pw - 8.0, TOP + 18.0);
    let _ = writeln!(o, "</svg>");
    s
}

/// Right-aligned legend lines at (`right`, `top`): per mesh its name and key figures.
fn legend(o: &mut String, series: &[SvgSeries], right: f64, top: f64) {
    let mut yy = top;
    for (k, sr) in series.iter().enumerate() {
        let q = sr.quality;
        let below = q.tets_below_deg.map(|n| n.to_string()).join(" / ");
        let swatch = if k == 0 {
            format!(
                r#"<rect x="{:.1}" y="{:.1}" width="12" height="10" fill="{}"/>"#,
                right - 14.0,
                yy - 9.0,
                COLOURS[0]
            )
        } else {
            format!(
                r#"<line x1="{:.1}" y1="{:.1}" x2="{:.1}" y2="{:.1}" stroke="{}" stroke-width="2"/>"#,
                right - 14.0,
                yy - 4.0,
                right - 2.0,
                yy - 4.0,
                COLOURS[1]
            )
        };
        let lines = [
            format!("{}: {} tets", esc(sr.name), q.n_tets),
            format!(
                "dihedral min {:.2}°, max {:.2}°",
                q.min_dihedral_deg, q.max_dihedral_deg
            ),
            format!("tets below 5 / 10 / 15 / 20°: {below}"),
            format!(
                "inverted / zero volume: {} / {}",
                q.n_inverted, q.n_zero_volume
            ),
        ];
        let _ = writeln!(o, "{swatch}");
        for (i, l) in lines.iter().enumerate() {
            let weight = if i == 0 { " font-weight=\"bold\"" } else { "" };
            let _ = writeln!(
                o,
                "<text class=\"legend\" x=\"{:.1}\" y=\"{yy:.1}\" text-anchor=\"end\"{weight}>{l}</text>",
                right - 20.0
            );
            yy += 16.0;
        }
        yy += 8.0;
    }
}
