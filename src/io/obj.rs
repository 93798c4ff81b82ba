//! Wavefront `.obj` reader (polygonal geometry only), producing a [`PlcInput`] of polygon facets.
//!
//! Supported subset:
//! - `v x y z [w | r g b]`: vertices (extra fields ignored).
//! - `f i j k ...`: polygon faces of 3 or more corners; each corner is `i`, `i/t`, `i/t/n` or
//!   `i//n` (texture and normal indices are ignored). Indices are 1-based; a negative index
//!   counts back from the last vertex defined so far (`-1` is the latest). Positive indices may
//!   refer to vertices defined later in the file.
//! - `o name` and `g name ...`: the faces after them belong to that group (one group per
//!   distinct name, in order of first appearance; faces before any are a group of their own).
//!   When there are several groups and each is a closed surface (every edge of its faces used
//!   by two of them), the groups are solids (`super::solids`): a face two of them list is one
//!   interface facet, and each gets a region seed with attribute 1, 2, ... in group order.
//! - Ignored statements: `vt`, `vn`, `vp`, `s`, `mg`, `usemtl`, `mtllib`, `l`, `p`
//!   and the display attributes (`bevel`, `c_interp`, `d_interp`, `lod`, `maplib`, `usemap`,
//!   `shadow_obj`, `trace_obj`).
//! - `#` comments and blank lines anywhere.
//!
//! Each face becomes one facet with one polygon and marker = its 1-based face index; with
//! `ReadOptions::merge_coplanar` the facets are then merged by
//! [`crate::plc::coplanar::merge_coplanar_facets`], which renumbers the markers the same way.
//! Not supported (a named error): free-form geometry (`curv`, `surf`, `cstype`, ...), line
//! continuations (`\` at the end of a line).

use super::solids::Solids;
use super::text::{check_index, err_at, err_file, parse_i64, read_text, with_path, Lines};
use super::{IoError, ReadOptions};
use crate::plc::{Facet, PlcInput};
use std::path::Path;

/// Statements that carry nothing a domain needs.
const IGNORED: &[&str] = &[
    "vt",
    "vn",
    "vp",
    "s",
    "mg",
    "usemtl",
    "mtllib",
    "l",
    "p",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "maplib",
    "usemap",
    "shadow_obj",
    "trace_obj",
];

/// Reads an `.obj` file.
pub fn read_obj(path: &Path, options: &ReadOptions) -> Result<PlcInput, IoError> {
    let text = read_text(path)?;
    parse_obj(&text, options).map_err(|e| with_path(e, path))
}

/// A face corner's vertex index as written, with its line, resolved once all vertices are read.
struct Corner {
    line: usize,
    /// 1-based index, made positive (negative ones are resolved when read).
    index: i64,
}

/// Parses the text of an `.obj` file.
pub fn parse_obj(text: &str, options: &ReadOptions) -> Result<PlcInput, IoError> {
    let mut lines = Lines::new(text);
    let mut plc = PlcInput::default();
    let mut faces: Vec<Vec<Corner>> = Vec::new();
    let mut groups: Vec<String> = vec![String::new()];
    let (mut group, mut group_of) = (0u32, Vec::new());
    while let Some(mut r) = lines.next_opt() {
        let kw = r.word("a statement")?;
        match kw {
            "v" => plc.vertices.push(r.point()?),
            "g" | "o" => {
                let mut name = vec![];
                while let Some(w) = r.word_opt() {
                    name.push(w);
                }
                let name = name.join(" ");
                group = match groups.iter().position(|g| *g == name) {
                    Some(k) => k as u32,
                    None => {
                        groups.push(name);
                        groups.len() as u32 - 1
                    }
                };
            }
            "f" | "fo" => {
                let fname = format!("face {}", faces.len() + 1);
                let mut corners = Vec::new();
                while let Some(w) = r.word_opt() {
                    if w == "\\" {
                        return Err(err_at(
                            r.line,
                            "line continuations ('\\') are not supported",
                        ));
                    }
                    let v = w.split('/').next().unwrap_or(w);
                    let what = format!("{fname}: vertex index");
                    let i = parse_i64(v, r.line, &what)?;
                    let index = match i {
                        0 => return Err(err_at(r.line, format!("{what} 0 (indices start at 1)"))),
                        i if i < 0 => {
                            let n = plc.vertices.len() as i64;
                            if n + i < 0 {
                                return Err(err_at(
                                    r.line,
                                    format!(
                                        "{what} {i} reaches before the first vertex ({n} defined \
                                         so far)"
                                    ),
                                ));
                            }
                            n + i + 1
                        }
                        i => i,
                    };
                    corners.push(Corner {
                        line: r.line,
                        index,
                    });
                }
                if corners.len() < 3 {
                    return Err(err_at(
                        r.line,
                        format!("{fname} has {} corners (at least 3 needed)", corners.len()),
                    ));
                }
                faces.push(corners);
                group_of.push(group);
            }
            kw if IGNORED.contains(&kw) => {}
            "cstype" | "deg" | "bmat" | "step" | "curv" | "curv2" | "surf" | "parm" | "trim"
            | "hole" | "scrv" | "sp" | "end" | "con" => {
                return Err(err_at(
                    r.line,
                    format!("free-form geometry ('{kw}') is not supported: polygons only"),
                ));
            }
            _ => {
                return Err(err_at(r.line, format!("unknown OBJ statement '{kw}'")));
            }
        }
    }
    let nv = plc.vertices.len();
    super::text::to_u32(nv, 1, "number of vertices")?;
    let mut polygons = Vec::with_capacity(faces.len());
    for (i, corners) in faces.iter().enumerate() {
        let what = format!("face {}: vertex index", i + 1);
        polygons.push(
            corners
                .iter()
                .map(|c| check_index(c.index, c.line, 1, nv, &what))
                .collect::<Result<Vec<u32>, IoError>>()?,
        );
    }
    let mut solids = Solids {
        polygons,
        solid_of: group_of,
    };
    let used: Vec<u32> = {
        let mut u = solids.solid_of.clone();
        u.sort_unstable();
        u.dedup();
        u
    };
    if used.len() > 1 && used.iter().all(|&g| solids.is_closed(g)) {
        // Groups renumbered 0, 1, ... in order, leaving out the empty ones.
        for g in &mut solids.solid_of {
            *g = used.binary_search(g).unwrap_or(0) as u32;
        }
        plc.regions = solids.region_seeds(&plc.vertices, used.len());
        solids.merge_shared();
    }
    plc.facets.reserve(solids.polygons.len());
    for (i, poly) in solids.polygons.into_iter().enumerate() {
        plc.facets.push(Facet {
            polygons: vec![poly],
            marker: i32::try_from(i + 1).unwrap_or(i32::MAX),
            ..Facet::default()
        });
    }
    if plc.facets.is_empty() {
        return Err(err_file("no faces ('f' statements) in the file"));
    }
    if options.merge_coplanar {
        crate::plc::coplanar::merge_coplanar_facets(&mut plc);
    }
    Ok(plc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    const TET: &str =
        "# a tetrahedron\nmtllib x.mtl\no tet\nv 0 0 0\nv 1 0 0\nv 0 1 0 0.5 0.5 0.5\n\
        v 0 0 1\nvt 0 0\nvn 0 0 1\ng side\nusemtl red\ns off\nf 1 3 2\nf 1/1 2/1 4/1\n\
        f -4//1 -1//1 -2//1\nf 2/1/1 3/1/1 4/1/1\n";

    #[test]
    fn reads_vertices_faces_and_index_forms() {
        let p = parse_obj(TET, &ReadOptions::default()).unwrap();
        assert_eq!(p.vertices.len(), 4);
        assert_eq!(p.vertices[2], DVec3::new(0.0, 1.0, 0.0));
        let polys: Vec<_> = p.facets.iter().map(|f| f.polygons[0].clone()).collect();
        assert_eq!(
            polys,
            vec![vec![0, 2, 1], vec![0, 1, 3], vec![0, 3, 2], vec![1, 2, 3]]
        );
        assert_eq!(p.facets[3].marker, 4);
    }

    #[test]
    fn polygons_forward_references_and_merging() {
        // A unit cube: quads, faces before the vertices they use.
        let cube = "f 1 2 4 3\nf 5 7 8 6\nf 1 5 6 2\nf 3 4 8 7\nf 1 3 7 5\nf 2 6 8 4\n\
            v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n";
        let p = parse_obj(cube, &ReadOptions::default()).unwrap();
        assert_eq!(p.facets.len(), 6);
        assert!(p.facets.iter().all(|f| f.polygons[0].len() == 4));
        let tris = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\nf 1 2 5\n";
        let merged = parse_obj(
            tris,
            &ReadOptions {
                merge_coplanar: true,
            },
        )
        .unwrap();
        assert_eq!(merged.facets.len(), 2, "the two z = 0 triangles merge");
    }

    /// Two unit cubes as two groups sharing the quad x = 1: one interface facet, regions 1
    /// and 2 in group order, each seeded in its own cube. A group that is not closed (an open
    /// box as one group) leaves the file one surface without regions.
    #[test]
    fn closed_groups_are_solids() {
        let mut text = String::new();
        for x in 0..3 {
            for y in 0..2 {
                for z in 0..2 {
                    text += &format!("v {x} {y} {z}\n");
                }
            }
        }
        // Vertex (x, y, z) has index 4x + 2y + z + 1.
        let v = |x: usize, y: usize, z: usize| 4 * x + 2 * y + z + 1;
        let cube = |x0: usize| {
            let x1 = x0 + 1;
            [
                [v(x0, 0, 0), v(x0, 0, 1), v(x0, 1, 1), v(x0, 1, 0)],
                [v(x1, 0, 0), v(x1, 1, 0), v(x1, 1, 1), v(x1, 0, 1)],
                [v(x0, 0, 0), v(x1, 0, 0), v(x1, 0, 1), v(x0, 0, 1)],
                [v(x0, 1, 0), v(x0, 1, 1), v(x1, 1, 1), v(x1, 1, 0)],
                [v(x0, 0, 0), v(x0, 1, 0), v(x1, 1, 0), v(x1, 0, 0)],
                [v(x0, 0, 1), v(x1, 0, 1), v(x1, 1, 1), v(x0, 1, 1)],
            ]
            .map(|f| format!("f {} {} {} {}\n", f[0], f[1], f[2], f[3]))
            .concat()
        };
        let two = format!("{text}g left\n{}g right\n{}", cube(0), cube(1));
        let plc = parse_obj(&two, &ReadOptions::default()).unwrap();
        assert_eq!(plc.facets.len(), 11, "the common quad once");
        let checked = crate::plc::validate(&plc).unwrap();
        assert_eq!(checked.region_attributes(), vec![1, 2]);
        assert!(plc.regions[0].point.x < 1.0 && plc.regions[1].point.x > 1.0);
        let open: String = cube(0).lines().skip(1).map(|l| format!("{l}\n")).collect();
        let one = format!("{text}g open\n{open}g right\n{}", cube(1));
        assert!(parse_obj(&one, &ReadOptions::default())
            .unwrap()
            .regions
            .is_empty());
    }

    fn expect_err(text: &str, line: usize, needle: &str) {
        let e = parse_obj(text, &ReadOptions::default()).unwrap_err();
        assert_eq!(e.line, Some(line), "{e}");
        assert!(e.message.contains(needle), "'{needle}' not in: {e}");
    }

    #[test]
    fn malformed_obj_files() {
        for text in ["", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"] {
            let e = parse_obj(text, &ReadOptions::default()).unwrap_err();
            assert!(e.line.is_none() && e.message.contains("no faces"), "{e}");
        }
        expect_err("v 0 0\n", 1, "expected z coordinate");
        expect_err("v 0 0 x\n", 1, "bad number 'x'");
        expect_err("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", 4, "at least 3");
        expect_err(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 0\n",
            4,
            "indices start at 1",
        );
        expect_err("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n", 5, "out of range");
        expect_err(
            "v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n",
            3,
            "before the first",
        );
        expect_err(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 a/2 3\n",
            4,
            "bad integer 'a'",
        );
        expect_err("v 0 0 0\nf 1 1 \\\n 1\n", 2, "continuations");
        expect_err("v 0 0 0\ncurv 0 1 1 2\n", 2, "free-form");
        expect_err("v 0 0 0\nvx 1\n", 2, "unknown OBJ statement 'vx'");
    }

    #[test]
    fn truncated_obj_never_panics() {
        let opts = ReadOptions {
            merge_coplanar: true,
        };
        for cut in 0..TET.len() {
            let _ = parse_obj(&TET[..cut], &opts);
        }
    }
}
