//! STL reader (ASCII and binary), producing a [`PlcInput`] of triangle facets.
//!
//! Supported subset:
//! - Binary: 80-byte header, little-endian `u32` triangle count, 50-byte records (normal,
//!   three `f32` vertices, attribute word). Chosen when the file size is exactly
//!   `84 + 50·count`, or when the file does not start with `solid` and is at least that long
//!   (trailing bytes ignored). Normals and attribute words are ignored.
//! - ASCII: one or more `solid [name] ... endsolid [name]` blocks of
//!   `facet normal nx ny nz / outer loop / vertex x y z (3 or more) / endloop / endfacet`;
//!   keywords are case-insensitive and may be split across lines freely; normals are ignored.
//!
//! Vertices with exactly equal coordinates are merged (`-0` equals `0`); the first occurrence
//! keeps its coordinates and vertices are numbered in order of first appearance. Triangles
//! whose corners merge into fewer than three distinct vertices are dropped. Each remaining
//! triangle becomes a facet with marker = its 1-based facet index; with
//! `ReadOptions::merge_coplanar` the facets are merged by
//! [`crate::plc::coplanar::merge_coplanar_facets`], which renumbers markers the same way.
//! Binary coordinates that are not finite are an error naming the triangle.
//!
//! Several `solid` blocks are several solids (`super::solids`): a triangle listed by two of
//! them is one interface facet, and each solid gets a region seed with attribute 1, 2, ...
//! in file order.

use super::solids::Solids;
use super::text::{err_at, err_file, read_bytes, with_path, Tokens};
use super::{IoError, ReadOptions};
use crate::plc::{Facet, PlcInput};
use glam::DVec3;
use rustc_hash::FxHashMap;
use std::path::Path;

/// Reads an `.stl` file, ASCII or binary.
pub fn read_stl(path: &Path, options: &ReadOptions) -> Result<PlcInput, IoError> {
    let bytes = read_bytes(path)?;
    parse_stl(&bytes, options).map_err(|e| with_path(e, path))
}

/// Parses the bytes of an `.stl` file, ASCII or binary.
pub fn parse_stl(bytes: &[u8], options: &ReadOptions) -> Result<PlcInput, IoError> {
    let mut soup = Soup::default();
    let starts_solid = {
        let head: Vec<u8> = bytes
            .iter()
            .skip_while(|b| b.is_ascii_whitespace())
            .take(5)
            .map(|b| b.to_ascii_lowercase())
            .collect();
        head == b"solid"
    };
    let binary_count = (bytes.len() >= 84)
        .then(|| u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize);
    let exact_binary = binary_count.is_some_and(|n| binary_size(n) == Some(bytes.len()));
    if exact_binary || !starts_solid {
        parse_binary(bytes, &mut soup)?;
    } else {
        let text = String::from_utf8_lossy(bytes);
        parse_ascii(&text, &mut soup)?;
    }
    let mut solids = Solids {
        polygons: soup.triangles,
        solid_of: soup.solid_of,
    };
    let mut regions = vec![];
    if soup.n_solids > 1 {
        regions = solids.region_seeds(&soup.vertices, soup.n_solids);
        solids.merge_shared();
    }
    let mut plc = PlcInput {
        vertices: soup.vertices,
        regions,
        ..PlcInput::default()
    };
    plc.facets = solids
        .polygons
        .into_iter()
        .enumerate()
        .map(|(i, t)| Facet {
            polygons: vec![t],
            marker: i32::try_from(i + 1).unwrap_or(i32::MAX),
            ..Facet::default()
        })
        .collect();
    if options.merge_coplanar {
        crate::plc::coplanar::merge_coplanar_facets(&mut plc);
    }
    Ok(plc)
}

/// Triangles with exactly-equal vertices merged.
#[derive(Default)]
struct Soup {
    vertices: Vec<DVec3>,
    ids: FxHashMap<[u64; 3], u32>,
    triangles: Vec<Vec<u32>>,
    /// The `solid` block (0-based) each triangle was read in, and the current one.
    solid_of: Vec<u32>,
    solid: u32,
    n_solids: usize,
}

impl Soup {
    fn vertex(&mut self, p: DVec3) -> Result<u32, IoError> {
        // +0.0 normalises -0.0 so that equal coordinates share a key.
        let key = [
            (p.x + 0.0).to_bits(),
            (p.y + 0.0).to_bits(),
            (p.z + 0.0).to_bits(),
        ];
        if let Some(&id) = self.ids.get(&key) {
            return Ok(id);
        }
        let id = u32::try_from(self.vertices.len())
            .map_err(|_| err_file("more than 2^32-1 distinct vertices"))?;
        self.vertices.push(p);
        self.ids.insert(key, id);
        Ok(id)
    }

    /// Adds a polygon, dropping repeated consecutive corners; fewer than 3 left: dropped.
    fn polygon(&mut self, pts: &[DVec3]) -> Result<(), IoError> {
        let mut poly: Vec<u32> = Vec::with_capacity(pts.len());
        for &p in pts {
            let id = self.vertex(p)?;
            if poly.last() != Some(&id) {
                poly.push(id);
            }
        }
        while poly.len() > 1 && poly.first() == poly.last() {
            poly.pop();
        }
        let mut sorted = poly.clone();
        sorted.sort_unstable();
        sorted.dedup();
        if poly.len() >= 3 && sorted.len() == poly.len() {
            self.triangles.push(poly);
            self.solid_of.push(self.solid);
        }
        Ok(())
    }
}

/// Size of a binary STL with `n` triangles (`None` on overflow).
fn binary_size(n: usize) -> Option<usize> {
    n.checked_mul(50)?.checked_add(84)
}

fn parse_binary(bytes: &[u8], soup: &mut Soup) -> Result<(), IoError> {
    if bytes.len() < 84 {
        return Err(err_file(format!(
            "not an ASCII STL (no 'solid') and too short for a binary STL: {} bytes, the \
             header alone is 84",
            bytes.len()
        )));
    }
    let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
    let need = binary_size(n).unwrap_or(usize::MAX);
    if bytes.len() < need {
        return Err(err_file(format!(
            "binary STL header declares {n} triangles ({need} bytes) but the file has {} \
             bytes: wrong count or truncated file",
            bytes.len()
        )));
    }
    let f = |o: usize| f32::from_le_bytes([bytes[o], bytes[o + 1], bytes[o + 2], bytes[o + 3]]);
    for t in 0..n {
        let rec = 84 + 50 * t;
        let mut pts = [DVec3::ZERO; 3];
        for (k, p) in pts.iter_mut().enumerate() {
            let o = rec + 12 + 12 * k;
            *p = DVec3::new(f(o) as f64, f(o + 4) as f64, f(o + 8) as f64);
            if !p.is_finite() {
                return Err(err_file(format!(
                    "binary STL triangle {} (byte offset {o}): vertex {} is not finite",
                    t + 1,
                    k + 1
                )));
            }
        }
        soup.polygon(&pts)?;
    }
    Ok(())
}

fn expect_kw(tok: &mut Tokens, kw: &str) -> Result<(), IoError> {
    let (line, w) = tok.next(&format!("'{kw}'"))?;
    if w.eq_ignore_ascii_case(kw) {
        Ok(())
    } else {
        Err(err_at(line, format!("expected '{kw}', found '{w}'")))
    }
}

fn parse_ascii(text: &str, soup: &mut Soup) -> Result<(), IoError> {
    let mut tok = Tokens::new(text);
    let mut solids = 0usize;
    while let Some((line, w)) = tok.next_opt() {
        if !w.eq_ignore_ascii_case("solid") {
            return Err(err_at(line, format!("expected 'solid', found '{w}'")));
        }
        tok.skip_line(); // the solid's name
        soup.solid = solids as u32;
        solids += 1;
        loop {
            let (line, w) = tok.next("'facet' or 'endsolid'")?;
            if w.eq_ignore_ascii_case("endsolid") {
                tok.skip_line();
                break;
            }
            if !w.eq_ignore_ascii_case("facet") {
                return Err(err_at(
                    line,
                    format!("expected 'facet' or 'endsolid', found '{w}'"),
                ));
            }
            expect_kw(&mut tok, "normal")?;
            for what in ["normal x", "normal y", "normal z"] {
                let (l, w) = tok.next(what)?;
                // Normals are ignored but must be numbers (some writers emit nan: accepted).
                w.parse::<f64>()
                    .map_err(|_| err_at(l, format!("bad number '{w}' for {what}")))?;
            }
            expect_kw(&mut tok, "outer")?;
            expect_kw(&mut tok, "loop")?;
            let mut pts = Vec::with_capacity(3);
            loop {
                let (line, w) = tok.next("'vertex' or 'endloop'")?;
                if w.eq_ignore_ascii_case("endloop") {
                    if pts.len() < 3 {
                        return Err(err_at(
                            line,
                            format!("facet has {} vertices, at least 3 needed", pts.len()),
                        ));
                    }
                    break;
                }
                if !w.eq_ignore_ascii_case("vertex") {
                    return Err(err_at(
                        line,
                        format!("expected 'vertex' or 'endloop', found '{w}'"),
                    ));
                }
                pts.push(tok.point()?);
            }
            expect_kw(&mut tok, "endfacet")?;
            soup.polygon(&pts)?;
        }
    }
    if solids == 0 {
        return Err(err_at(1, "empty ASCII STL: no 'solid'"));
    }
    soup.n_solids = solids;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit tetrahedron as ASCII STL.
    pub(crate) const TET_ASCII: &str = "solid tet\n\
        facet normal 0 0 -1\n outer loop\n  vertex 0 0 0\n  vertex 0 1 0\n  vertex 1 0 0\n endloop\nendfacet\n\
        facet normal 0 -1 0\n outer loop\n  vertex 0 0 0\n  vertex 1 0 0\n  vertex 0 0 1\n endloop\nendfacet\n\
        facet normal -1 0 0\n outer loop\n  vertex 0 0 0\n  vertex 0 0 1\n  vertex 0 1 0\n endloop\nendfacet\n\
        facet normal 1 1 1\n outer loop\n  vertex 1 0 0\n  vertex 0 1 0\n  vertex -0 0 1\n endloop\nendfacet\n\
        endsolid tet\n";

    fn binary(tris: &[[[f32; 3]; 3]], declared: u32) -> Vec<u8> {
        let mut b = b"solid but actually binary".to_vec();
        b.resize(80, b' ');
        b.extend_from_slice(&declared.to_le_bytes());
        for t in tris {
            b.extend_from_slice(&[0u8; 12]);
            for p in t {
                for c in p {
                    b.extend_from_slice(&c.to_le_bytes());
                }
            }
            b.extend_from_slice(&[0u8; 2]);
        }
        b
    }

    const TET_TRIS: [[[f32; 3]; 3]; 4] = [
        [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
        [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        [[0.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]],
        [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    ];

    #[test]
    fn ascii_and_binary_give_the_same_merged_surface() {
        let a = parse_stl(TET_ASCII.as_bytes(), &ReadOptions::default()).unwrap();
        assert_eq!(a.vertices.len(), 4, "equal vertices merged, -0 == 0");
        assert_eq!(a.facets.len(), 4);
        assert_eq!(a.facets[3].marker, 4);
        let b = parse_stl(&binary(&TET_TRIS, 4), &ReadOptions::default()).unwrap();
        assert_eq!(a, b);
    }

    /// Two solids sharing a face: the face is read once (an interface), and each solid gets
    /// a region seed, attribute 1 and 2 in file order, that the validator places in it.
    #[test]
    fn two_solids_share_their_common_face_and_get_regions() {
        let solid = |name: &str, tris: &[[[f64; 3]; 3]]| {
            let mut s = format!("solid {name}\n");
            for t in tris {
                s += "facet normal 0 0 0\nouter loop\n";
                for p in t {
                    s += &format!("vertex {} {} {}\n", p[0], p[1], p[2]);
                }
                s += "endloop\nendfacet\n";
            }
            s + &format!("endsolid {name}\n")
        };
        let (o, x, y, z, w) = (
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [1.0, 1.0, 1.0],
        );
        // Outward: the corner tet, and the one beyond its slanted face.
        let a = solid("corner", &[[o, y, x], [o, x, z], [o, z, y], [x, y, z]]);
        let b = solid("beyond", &[[x, z, y], [x, y, w], [y, z, w], [z, x, w]]);
        let plc = parse_stl((a + &b).as_bytes(), &ReadOptions::default()).unwrap();
        assert_eq!(plc.facets.len(), 7, "the common face once");
        let attributes: Vec<i32> = plc.regions.iter().map(|r| r.attribute).collect();
        assert_eq!(attributes, vec![1, 2]);
        let checked = crate::plc::validate(&plc).unwrap();
        assert_eq!(checked.region_attributes(), vec![1, 2]);
        let volumes: Vec<f64> = checked
            .input_regions()
            .volumes
            .iter()
            .map(|v| v.1)
            .collect();
        assert!((volumes[0] - 1.0 / 6.0).abs() < 1e-12 && (volumes[1] - 1.0 / 3.0).abs() < 1e-12);
        assert!((checked.input_regions().interface_area - 3f64.sqrt() / 2.0).abs() < 1e-12);
    }

    #[test]
    fn degenerate_triangles_are_dropped() {
        let mut tris = TET_TRIS.to_vec();
        tris.push([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]);
        let b = parse_stl(&binary(&tris, 5), &ReadOptions::default()).unwrap();
        assert_eq!(b.facets.len(), 4);
    }

    fn expect_err(bytes: &[u8], line: Option<usize>, needle: &str) {
        let e = parse_stl(bytes, &ReadOptions::default()).unwrap_err();
        assert_eq!(e.line, line, "{e}");
        assert!(e.message.contains(needle), "'{needle}' not in: {e}");
    }

    #[test]
    fn malformed_stl_files() {
        expect_err(b"hello", None, "too short");
        expect_err(b"sol", None, "too short");
        let mut b = binary(&TET_TRIS, 4);
        b[0] = b'x';
        expect_err(&b[..200], None, "declares 4 triangles");
        let mut nan = binary(&TET_TRIS, 4);
        nan[84 + 12..84 + 16].copy_from_slice(&f32::NAN.to_le_bytes());
        expect_err(&nan, None, "triangle 1");
        expect_err(
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\n",
            Some(5),
            "unexpected end",
        );
        expect_err(
            b"solid x\nfacet normal 0 0 1\nouter ring\n",
            Some(3),
            "expected 'loop'",
        );
        expect_err(
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 q\n",
            Some(4),
            "bad number 'q'",
        );
        expect_err(
            b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nendloop\n",
            Some(6),
            "at least 3",
        );
        expect_err(b"solid x\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n", Some(9), "'facet' or 'endsolid'");
        expect_err(b"solid x\nendsolid x\nfacet\n", Some(3), "expected 'solid'");
    }

    #[test]
    fn truncated_stl_never_panics() {
        let t = TET_ASCII.as_bytes();
        for cut in 0..t.len() {
            let _ = parse_stl(&t[..cut], &ReadOptions::default());
        }
        let b = binary(&TET_TRIS, 4);
        for cut in 0..b.len() {
            let _ = parse_stl(&b[..cut], &ReadOptions::default());
        }
    }
}
