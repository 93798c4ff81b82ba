//! TetGen `.poly`, `.smesh` and `.node` readers, producing a [`PlcInput`].
//!
//! Supported subset (TetGen 1.5/1.6 file formats, 3D only):
//! - `#` comments anywhere, blank lines ignored; one record per line (a polygon's corner list
//!   may continue on the following lines, as TetGen allows).
//! - Part 1, nodes: `<#points> [dim=3] [#attributes] [#markers]`, then
//!   `<id> <x> <y> <z> [attributes...] [marker]`; attributes and markers are read past and
//!   ignored. The first id (0 or 1) sets the index base for the whole file; ids must then be
//!   consecutive. `#points = 0` means the nodes are in the `.node` file of the same name.
//! - Part 2, facets. `.poly`: `<#facets> [markers 0|1]`, each facet
//!   `<#polygons> [#holes] [marker]`, then its polygons `<#corners> <v1> ... <vk>` (k >= 1:
//!   TetGen allows segments and points inside facets) and its hole points `<id> <x> <y> <z>`.
//!   `.smesh`: `<#facets> [markers 0|1]`, each facet one polygon `<#corners> <v1> ... [marker]`.
//!   A facet without a marker (flag 0 or field missing) gets marker **1**.
//! - Part 3, volume holes: `<#holes>`, then `<id> <x> <y> <z>`.
//! - Part 4 (optional), regions: `<#regions>`, then `<id> <x> <y> <z> <attribute> [max volume]`.
//!   The attribute must be an integer (`2` or `2.0`). A maximum volume `v > 0` becomes
//!   `max_size = cbrt(6·sqrt(2)·v)`, the edge length of the regular tetrahedron of volume v;
//!   `v <= 0` or no value means no limit (`None`).
//!
//! Not supported: 2D files, `.poly` files with curved-boundary extensions, `.edge`/`.var`/`.mtr`
//! companions (TetGen's segment constraints, variable constraints, metrics).

use super::text::{
    err_at, parse_i64, parse_integral_i32, read_text, to_u32, with_path, Lines, Record,
};
use super::IoError;
use crate::plc::{Facet, PlcInput, Region};
use glam::DVec3;
use std::path::Path;

/// Vertices of a TetGen node list and the index base (0 or 1) its first id declared.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeList {
    pub vertices: Vec<DVec3>,
    pub base: usize,
}

/// Converts a TetGen region maximum volume to the `Region::max_size` edge-length scale:
/// the edge of the regular tetrahedron of volume `v` (V = a³ / (6·sqrt 2)). Non-positive or
/// non-finite volumes mean "no limit".
pub fn max_volume_to_size(v: f64) -> Option<f64> {
    if v > 0.0 && v.is_finite() {
        Some((v * 6.0 * std::f64::consts::SQRT_2).cbrt())
    } else {
        None
    }
}

/// Reads a TetGen `.poly` file (and its `.node` file when the node count is 0).
pub fn read_poly(path: &Path) -> Result<PlcInput, IoError> {
    read_tetgen_plc(path, false)
}

/// Reads a TetGen `.smesh` file (and its `.node` file when the node count is 0).
pub fn read_smesh(path: &Path) -> Result<PlcInput, IoError> {
    read_tetgen_plc(path, true)
}

/// Reads a TetGen `.node` file.
pub fn read_node(path: &Path) -> Result<NodeList, IoError> {
    let text = read_text(path)?;
    parse_node(&text).map_err(|e| with_path(e, path))
}

fn read_tetgen_plc(path: &Path, smesh: bool) -> Result<PlcInput, IoError> {
    let text = read_text(path)?;
    let node_path = path.with_extension("node");
    let mut load = || read_node(&node_path);
    let r = if smesh {
        parse_smesh(&text, &mut load)
    } else {
        parse_poly(&text, &mut load)
    };
    r.map_err(|e| with_path(e, path))
}

/// Parses the text of a `.node` file.
pub fn parse_node(text: &str) -> Result<NodeList, IoError> {
    let mut lines = Lines::new(text);
    let header = lines.next("node list header '<#points> 3 <#attributes> <#markers>'")?;
    // A .node file with 0 points is an empty point set (not a reference to another file).
    let nodes = parse_node_section(&mut lines, header)?.unwrap_or(NodeList {
        vertices: Vec::new(),
        base: 1,
    });
    lines.expect_end(&format!("the {} points declared", nodes.vertices.len()))?;
    Ok(nodes)
}

/// Parses the text of a `.poly` file; `external_nodes` loads the `.node` file when needed.
pub fn parse_poly(
    text: &str,
    external_nodes: &mut dyn FnMut() -> Result<NodeList, IoError>,
) -> Result<PlcInput, IoError> {
    parse(text, false, external_nodes)
}

/// Parses the text of a `.smesh` file; `external_nodes` loads the `.node` file when needed.
pub fn parse_smesh(
    text: &str,
    external_nodes: &mut dyn FnMut() -> Result<NodeList, IoError>,
) -> Result<PlcInput, IoError> {
    parse(text, true, external_nodes)
}

/// Reads the node list after its header; `None` when the header declares 0 points.
fn parse_node_section(lines: &mut Lines, mut header: Record) -> Result<Option<NodeList>, IoError> {
    let n = header.usize("number of points")?;
    if let Some(dim) = header.usize_opt("dimension")? {
        if dim != 3 {
            return Err(err_at(
                header.line,
                format!("dimension must be 3, found {dim}"),
            ));
        }
    }
    header.usize_opt("number of point attributes")?;
    header.usize_opt("number of point boundary markers (0 or 1)")?;
    if n == 0 {
        return Ok(None);
    }
    to_u32(n, header.line, "number of points")?;
    let mut vertices = Vec::with_capacity(super::text::cap(n));
    let mut base = 0;
    for i in 0..n {
        let mut r = lines.next(&format_args!("point {} of {n}", i + 1))?;
        let id = r.i64("point id")?;
        if i == 0 {
            if id != 0 && id != 1 {
                return Err(err_at(
                    r.line,
                    format!("first point id must be 0 or 1 (it sets the index base), found {id}"),
                ));
            }
            base = id as usize;
        } else if id != (base + i) as i64 {
            return Err(err_at(
                r.line,
                format!(
                    "point id {id} out of sequence: expected {} (ids must be consecutive)",
                    base + i
                ),
            ));
        }
        vertices.push(r.point()?);
        // Attributes and boundary marker, if any, are ignored.
    }
    Ok(Some(NodeList { vertices, base }))
}

/// Reads `count` vertex indices of a polygon, continuing on following lines if needed.
fn polygon_indices<'a>(
    lines: &mut Lines<'a>,
    rec: &mut Record<'a>,
    count: usize,
    nodes: &NodeList,
    what: &str,
) -> Result<Vec<u32>, IoError> {
    let n = nodes.vertices.len();
    let mut poly = Vec::with_capacity(super::text::cap(count));
    while poly.len() < count {
        let (line, w) = match rec.word_opt() {
            Some(w) => (rec.line, w),
            None => {
                *rec = lines.next(&format!("{} more corner(s) of {what}", count - poly.len()))?;
                continue;
            }
        };
        let v = parse_i64(w, line, what)?;
        poly.push(super::text::check_index(
            v,
            line,
            nodes.base,
            n,
            &format_args!("{what}: vertex index"),
        )?);
    }
    Ok(poly)
}

/// Reads `<id> <x> <y> <z>` point records (holes).
fn id_points(lines: &mut Lines, count: usize, what: &str) -> Result<Vec<DVec3>, IoError> {
    let mut pts = Vec::with_capacity(super::text::cap(count));
    for i in 0..count {
        let mut r = lines.next(&format!("{what} {} of {count}", i + 1))?;
        r.i64(&format!("{what} id"))?;
        pts.push(r.point()?);
    }
    Ok(pts)
}

fn parse(
    text: &str,
    smesh: bool,
    external_nodes: &mut dyn FnMut() -> Result<NodeList, IoError>,
) -> Result<PlcInput, IoError> {
    let mut lines = Lines::new(text);
    let header = lines.next("node list header '<#points> 3 <#attributes> <#markers>'")?;
    let nodes = match parse_node_section(&mut lines, header)? {
        Some(n) => n,
        None => external_nodes()?,
    };

    // Part 2: facets.
    let mut r = lines.next("facet list header '<#facets> <markers 0|1>'")?;
    let nf = r.usize("number of facets")?;
    let has_markers = r.usize_opt("facet marker flag (0 or 1)")?.unwrap_or(0) != 0;
    let mut facets = Vec::with_capacity(super::text::cap(nf));
    for fi in 0..nf {
        let fname = format!("facet {}", fi + 1);
        let mut facet = Facet {
            marker: 1,
            ..Facet::default()
        };
        if smesh {
            let mut r = lines.next(&fname)?;
            let k = r.usize(&format!("number of corners of {fname}"))?;
            if k == 0 {
                return Err(err_at(r.line, format!("{fname} has 0 corners")));
            }
            facet
                .polygons
                .push(polygon_indices(&mut lines, &mut r, k, &nodes, &fname)?);
            if has_markers {
                if let Some(m) = r.i32_opt(&format!("boundary marker of {fname}"))? {
                    facet.marker = m;
                }
            }
        } else {
            let mut r = lines.next(&fname)?;
            let npoly = r.usize(&format!("number of polygons of {fname}"))?;
            let nholes = r
                .usize_opt(&format!("number of holes of {fname}"))?
                .unwrap_or(0);
            if has_markers {
                if let Some(m) = r.i32_opt(&format!("boundary marker of {fname}"))? {
                    facet.marker = m;
                }
            }
            if npoly == 0 {
                return Err(err_at(r.line, format!("{fname} has 0 polygons")));
            }
            for pi in 0..npoly {
                let pname = format!("polygon {} of {fname}", pi + 1);
                let mut r = lines.next(&pname)?;
                let k = r.usize(&format!("number of corners of {pname}"))?;
                if k == 0 {
                    return Err(err_at(r.line, format!("{pname} has 0 corners")));
                }
                facet
                    .polygons
                    .push(polygon_indices(&mut lines, &mut r, k, &nodes, &pname)?);
            }
            facet.hole_points = id_points(&mut lines, nholes, &format!("hole of {fname}"))?;
        }
        facets.push(facet);
    }

    // Part 3: volume holes.
    let mut r = lines.next("volume hole list header '<#holes>'")?;
    let nh = r.usize("number of holes")?;
    let holes = id_points(&mut lines, nh, "volume hole")?;

    // Part 4 (optional): regions.
    let mut regions = Vec::new();
    if let Some(mut r) = lines.next_opt() {
        let nr = r.usize("number of regions")?;
        regions.reserve(super::text::cap(nr));
        for i in 0..nr {
            let mut r = lines.next(&format!("region {} of {nr}", i + 1))?;
            r.i64("region id")?;
            let point = r.point()?;
            let w = r.word("region attribute")?;
            let attribute = parse_integral_i32(w, r.line, "region attribute")?;
            let max_size = r
                .f64_opt("region maximum volume")?
                .and_then(max_volume_to_size);
            regions.push(Region {
                point,
                attribute,
                max_size,
            });
        }
        lines.expect_end(&format!("the {nr} regions declared"))?;
    }

    Ok(PlcInput {
        vertices: nodes.vertices,
        facets,
        holes,
        regions,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn no_node() -> Result<NodeList, IoError> {
        Err(super::super::text::err_file("no .node file in this test"))
    }

    fn poly(text: &str) -> Result<PlcInput, IoError> {
        parse_poly(text, &mut no_node)
    }

    fn smesh(text: &str) -> Result<PlcInput, IoError> {
        parse_smesh(text, &mut no_node)
    }

    const TET: &str = "4 3 0 0\n0 0 0 0\n1 1 0 0\n2 0 1 0\n3 0 0 1\n";

    #[test]
    fn zero_based_poly_with_markers_holes_and_regions() {
        let text = format!(
            "{TET}4 1\n1 0 5\n3 0 2 1\n1 0 6\n3 0 1 3\n1 0 7\n3 1 2 3\n1 0\n3 0 3 2\n\
             1\n0 5 5 5\n1\n0 0.1 0.1 0.1 -3 0.5\n"
        );
        let p = poly(&text).unwrap();
        assert_eq!(p.vertices.len(), 4);
        assert_eq!(p.facets[0].polygons, vec![vec![0, 2, 1]]);
        assert_eq!(p.facets[0].marker, 5);
        assert_eq!(p.facets[3].marker, 1, "missing marker defaults to 1");
        assert_eq!(p.holes, vec![DVec3::splat(5.0)]);
        assert_eq!(p.regions[0].attribute, -3);
        let s = p.regions[0].max_size.unwrap();
        let vol = s * s * s / (6.0 * std::f64::consts::SQRT_2);
        assert!((vol - 0.5).abs() < 1e-12);
    }

    #[test]
    fn polygon_may_wrap_lines_and_smesh_reads_markers() {
        let text = format!("{TET}1 0\n1\n3 0\n 2\n1\n0\n");
        let p = poly(&text).unwrap();
        assert_eq!(p.facets[0].polygons, vec![vec![0, 2, 1]]);
        let s = smesh(&format!("{TET}2 1\n3 0 1 2 4\n3 0 1 3\n0\n")).unwrap();
        assert_eq!(s.facets[0].marker, 4);
        assert_eq!(s.facets[1].marker, 1);
        assert!(s.regions.is_empty());
    }

    #[test]
    fn external_node_file_is_used_when_count_is_zero() {
        let mut load = || parse_node("3 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n");
        let p = parse_poly("0 3 0 0\n1 0\n1\n3 1 2 3\n0\n", &mut load).unwrap();
        assert_eq!(p.vertices.len(), 3);
        assert_eq!(p.facets[0].polygons, vec![vec![0, 1, 2]]);
        let e = poly("0 3 0 0\n1 0\n1\n3 1 2 3\n0\n").unwrap_err();
        assert!(e.message.contains("no .node"), "{e}");
    }

    fn expect_err(text: &str, line: usize, needle: &str) {
        let e = poly(text).unwrap_err();
        assert_eq!(e.line, Some(line), "{e}");
        assert!(e.message.contains(needle), "'{needle}' not in: {e}");
    }

    #[test]
    fn malformed_poly_files() {
        expect_err("", 1, "unexpected end of file");
        expect_err("4 2 0 0\n", 1, "dimension must be 3");
        expect_err("2 3\n5 0 0 0\n", 2, "first point id must be 0 or 1");
        expect_err("2 3\n1 0 0 0\n3 0 0 0\n", 3, "out of sequence");
        expect_err("2 3\n1 0 0 0\n2 0 zero 0\n", 3, "bad number 'zero'");
        expect_err("2 3\n1 0 0 0\n2 0 0\n", 3, "expected z coordinate");
        expect_err(
            "2 3\n1 0 0 0\n",
            3,
            "unexpected end of file: expected point 2",
        );
        expect_err(
            &format!("{TET}1 0\n1\n3 0 1 4\n0\n"),
            8,
            "facet 1: vertex index 4 out of range (valid: 0..=3)",
        );
        expect_err(&format!("{TET}1 0\n1\n3 0 -1 2\n0\n"), 8, "out of range");
        expect_err(&format!("{TET}2 0\n1\n3 0 1 2\n"), 9, "expected facet 2");
        expect_err(&format!("{TET}1 0\n1\n3 0 1\n"), 9, "more corner");
        expect_err(&format!("{TET}1 0\n0\n0\n"), 7, "0 polygons");
        expect_err(
            &format!("{TET}1 0\n1 1\n3 0 1 2\n0 1 1\n0\n"),
            9,
            "expected z",
        );
        expect_err(&format!("{TET}1 0\n1\n3 0 1 2\n"), 9, "volume hole list");
        expect_err(
            &format!("{TET}0\n0\n1\n0 0 0 0 1.5\n"),
            9,
            "must be an integer",
        );
        expect_err(&format!("{TET}0\n0\n2\n0 0 0 0 1\n"), 10, "region 2 of 2");
        expect_err(&format!("{TET}x\n"), 6, "bad non-negative integer 'x'");
        expect_err(
            &format!("{TET}0\n0\n1\n0 0 0 0 1\n1 0 0 0 1\n"),
            10,
            "unexpected data after the 1 regions",
        );
        let e = parse_node("1 3\n1 0 0 0\n2 0 0 0\n").unwrap_err();
        assert_eq!(e.line, Some(3), "{e}");
        assert!(e.message.contains("after the 1 points"), "{e}");
    }

    #[test]
    fn truncated_poly_never_panics() {
        let text = format!(
            "{TET}2 1\n2 1 5\n3 0 2 1\n2 1 3\n0 0.1 0.1 0\n1 0 6\n3 0 1 3\n1\n0 5 5 5\n\
             1\n0 0.1 0.1 0.1 -3 0.5\n"
        );
        assert!(poly(&text).is_ok());
        for cut in 0..text.len() {
            let _ = poly(&text[..cut]);
            let _ = smesh(&text[..cut]);
        }
    }
}
