//! Gmsh `.msh` version 4.1 ASCII writer, and a reader for the same subset (the binary form of
//! the same content: `super::gmsh_binary`).
//!
//! Written (valid per the MSH 4.1 specification; checked with gmsh 4.15 and meshio 5.3):
//! - `$MeshFormat` `4.1 0 8`.
//! - `$PhysicalNames`: `3 v "region_v"` for each distinct tet region attribute v and
//!   `2 m "marker_m"` for each distinct boundary marker m.
//! - `$Entities`: no points or curves; one surface per distinct boundary marker and one volume
//!   per distinct region attribute (tags 1, 2, ... in order of first appearance; at least one
//!   volume). Each entity has exactly one physical tag, the value itself, 0 included (gmsh
//!   reads a physical group 0; meshio needs every block to have a physical tag). Gmsh treats
//!   the sign of a physical tag as an orientation, so it folds a negative attribute or marker
//!   into its absolute value; this module's reader keeps the sign. Entities carry bounding
//!   boxes and no bounding sub-entities.
//! - `$Nodes`: one block on volume 1, node tags 1..n in vertex order.
//! - `$Elements`: one block per entity, tets (type 4) on volumes, triangles (type 2) on
//!   surfaces. Element tags: tet i is i+1, boundary triangle j is #tets + j + 1, so the order
//!   survives the grouping into blocks.
//!
//! Ten-node tets ([`format_msh_quadratic`]): the same sections, the node block holding the
//! corners and then the mid-edge nodes (tags 1..n in that order), the tets of type 11 with
//! gmsh's node order (corners, then edges 01, 12, 20, 30, 32, 31: the gmsh manual's
//! "Node ordering"), the boundary triangles of type 9 (corners, then edges 01, 12, 20).
//!
//! Read: ASCII 4.1 and 2.x (`$MeshFormat` 4.1 or 2.0-2.2, file type 0). 4.1: `$Entities`
//! supplies the first physical tag of each surface and volume (0 when it has none or
//! `$Entities` is absent); `$Nodes` blocks (parametric coordinates skipped); `$Elements`: tets
//! (4) and triangles (2) are kept, and so are the corners of 10-node tets (11) and 6-node
//! triangles (9), whose other nodes stay in the vertex list; all sorted by element tag; other
//! known element types are read past; nodes are ordered by tag. 2.x (still written by many
//! tools): `$Nodes` as `<id> <x> <y> <z>`, `$Elements` as `<id> <type> <#tags> <physical> ...`;
//! the first tag (the physical group) is the region or marker, 0 without tags.
//! `$PhysicalNames` and any other section are skipped. Not supported: binary files, MSH 4.0,
//! tets of order 3 and more (their elements are read past).

use super::elements::{Elements, GMSH_TET_ORDER, TRIANGLE_ORDER};
use super::text::{
    check_mesh, check_mesh_io, check_quadratic, check_quadratic_io, create, err_at, read_text,
    with_path, write_err, write_int_line, Tokens, F,
};
use super::IoError;
use crate::mesh::{QuadraticNodes, TetMesh};
use glam::DVec3;
use rustc_hash::FxHashMap;
use std::io::Write;
use std::path::Path;

/// Writes `mesh` as a gmsh 4.1 ASCII `.msh` file.
pub fn write_msh(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    check_mesh(mesh, &[]).map_err(|e| with_path(e, path))?;
    let mut w = create(path)?;
    format_msh(&mut w, mesh)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// Writes `mesh` with its mid-edge nodes as a gmsh 4.1 ASCII `.msh` file of ten-node tets.
pub fn write_msh_quadratic(
    path: &Path,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
) -> Result<(), IoError> {
    check_mesh(mesh, &[]).map_err(|e| with_path(e, path))?;
    check_quadratic(mesh, quadratic).map_err(|e| with_path(e, path))?;
    let mut w = create(path)?;
    format_msh_quadratic(&mut w, mesh, quadratic)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// An entity of the written file: its value (region or marker) and element ids.
pub(super) struct Entity {
    pub value: i32,
    pub elements: Vec<usize>,
}

/// Groups element ids by value, in order of first appearance.
fn group(values: &[i32]) -> Vec<Entity> {
    let mut index: FxHashMap<i32, usize> = FxHashMap::default();
    let mut out: Vec<Entity> = Vec::new();
    for (i, &v) in values.iter().enumerate() {
        let k = *index.entry(v).or_insert_with(|| {
            out.push(Entity {
                value: v,
                elements: Vec::new(),
            });
            out.len() - 1
        });
        out[k].elements.push(i);
    }
    out
}

/// Bounding box of the nodes of some elements (tets when `tets`, else boundary triangles; of
/// all nodes when there are none).
pub(super) fn bbox(el: &Elements, tets: bool, ids: &[usize]) -> [f64; 6] {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    let mut add = |p: DVec3| {
        lo = lo.min(p);
        hi = hi.max(p);
    };
    if ids.is_empty() {
        el.nodes().for_each(&mut add);
    }
    for &i in ids {
        if tets {
            el.tet(i)[..el.tet_nodes()]
                .iter()
                .for_each(|&v| add(el.position(v)));
        } else {
            el.triangle(i)[..el.triangle_nodes()]
                .iter()
                .for_each(|&v| add(el.position(v)));
        }
    }
    if lo.x > hi.x {
        return [0.0; 6];
    }
    [lo.x, lo.y, lo.z, hi.x, hi.y, hi.z]
}

/// Gmsh element types of the tets and the boundary triangles: 4 and 2, or 11 (10-node tet)
/// and 9 (6-node triangle).
pub(super) fn element_types(el: &Elements) -> (i32, i32) {
    if el.is_quadratic() {
        (11, 9)
    } else {
        (4, 2)
    }
}

fn write_entity<W: Write>(w: &mut W, tag: usize, b: [f64; 6], value: i32) -> std::io::Result<()> {
    write!(w, "{tag}")?;
    for x in b {
        write!(w, " {}", F(x))?;
    }
    writeln!(w, " 1 {value} 0")
}

/// The volume entities (one per region attribute, at least one) and surface entities (one per
/// boundary marker) of `mesh`, in order of first appearance.
pub(super) fn entities(mesh: &TetMesh) -> (Vec<Entity>, Vec<Entity>) {
    let mut volumes = group(&mesh.tet_regions);
    if volumes.is_empty() {
        volumes.push(Entity {
            value: 0,
            elements: Vec::new(),
        });
    }
    (volumes, group(&mesh.boundary_markers))
}

/// `$PhysicalNames` (ASCII in both forms): `region_v` per volume, `marker_m` per surface.
pub(super) fn write_physical_names<W: Write>(
    w: &mut W,
    volumes: &[Entity],
    surfaces: &[Entity],
) -> std::io::Result<()> {
    let names: Vec<(u8, i32)> = volumes
        .iter()
        .map(|e| (3, e.value))
        .chain(surfaces.iter().map(|e| (2, e.value)))
        .collect();
    if !names.is_empty() {
        writeln!(w, "$PhysicalNames\n{}", names.len())?;
        for (dim, v) in names {
            let kind = if dim == 3 { "region" } else { "marker" };
            writeln!(w, "{dim} {v} \"{kind}_{v}\"")?;
        }
        writeln!(w, "$EndPhysicalNames")?;
    }
    Ok(())
}

/// Writes `mesh` in gmsh 4.1 ASCII format to any writer.
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_msh<W: Write>(w: &mut W, mesh: &TetMesh) -> std::io::Result<()> {
    check_mesh_io(mesh, &[])?;
    format_elements(w, &Elements::new(mesh, None))
}

/// Writes `mesh` with the mid-edge nodes `quadratic` as ten-node tets (type 11) and six-node
/// boundary triangles (type 9) in gmsh 4.1 ASCII format; otherwise as [`format_msh`].
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_msh_quadratic<W: Write>(
    w: &mut W,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
) -> std::io::Result<()> {
    check_mesh_io(mesh, &[])?;
    check_quadratic_io(mesh, quadratic)?;
    format_elements(w, &Elements::new(mesh, Some(quadratic)))
}

fn format_elements<W: Write>(w: &mut W, el: &Elements) -> std::io::Result<()> {
    let mesh = el.mesh;
    let (nv, nt, nb) = (el.n_nodes(), mesh.tets.len(), mesh.boundary.len());
    let (volumes, surfaces) = entities(mesh);
    let (tet_type, tri_type) = element_types(el);
    writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;
    write_physical_names(w, &volumes, &surfaces)?;

    writeln!(w, "$Entities\n0 0 {} {}", surfaces.len(), volumes.len())?;
    for (k, e) in surfaces.iter().enumerate() {
        write_entity(w, k + 1, bbox(el, false, &e.elements), e.value)?;
    }
    for (k, e) in volumes.iter().enumerate() {
        write_entity(w, k + 1, bbox(el, true, &e.elements), e.value)?;
    }
    writeln!(w, "$EndEntities")?;

    writeln!(w, "$Nodes")?;
    if nv == 0 {
        writeln!(w, "0 0 0 0")?;
    } else {
        writeln!(w, "1 {nv} 1 {nv}\n3 1 0 {nv}")?;
        for i in 1..=nv {
            writeln!(w, "{i}")?;
        }
        for p in el.nodes() {
            writeln!(w, "{} {} {}", F(p.x), F(p.y), F(p.z))?;
        }
    }
    writeln!(w, "$EndNodes")?;

    let blocks = volumes.iter().filter(|e| !e.elements.is_empty()).count() + surfaces.len();
    let ne = nt + nb;
    writeln!(w, "$Elements")?;
    if ne == 0 {
        writeln!(w, "0 0 0 0")?;
    } else {
        writeln!(w, "{blocks} {ne} 1 {ne}")?;
    }
    let mut line = Vec::new();
    let mut ids: Vec<i64> = Vec::with_capacity(11);
    for (k, e) in volumes.iter().enumerate() {
        if e.elements.is_empty() {
            continue;
        }
        writeln!(w, "3 {} {tet_type} {}", k + 1, e.elements.len())?;
        for &i in &e.elements {
            ids.clear();
            ids.push(i as i64 + 1);
            ids.extend(el.tet_in(i, &GMSH_TET_ORDER).map(|v| i64::from(v) + 1));
            write_int_line(w, &mut line, &ids)?;
        }
    }
    for (k, e) in surfaces.iter().enumerate() {
        writeln!(w, "2 {} {tri_type} {}", k + 1, e.elements.len())?;
        for &j in &e.elements {
            ids.clear();
            ids.push((nt + j) as i64 + 1);
            ids.extend(el.triangle_in(j, &TRIANGLE_ORDER).map(|v| i64::from(v) + 1));
            write_int_line(w, &mut line, &ids)?;
        }
    }
    writeln!(w, "$EndElements")
}

/// Reads a gmsh 4.1 ASCII `.msh` file.
pub fn read_msh(path: &Path) -> Result<TetMesh, IoError> {
    let text = read_text(path)?;
    parse_msh(&text).map_err(|e| with_path(e, path))
}

/// Number of nodes of gmsh element types that may appear beside tets and triangles.
fn nodes_per_element(ty: i64) -> Option<usize> {
    Some(match ty {
        15 => 1,
        1 => 2,
        2 | 8 => 3,
        3 | 4 => 4,
        7 => 5,
        6 | 9 => 6,
        5 | 16 => 8,
        10 => 9,
        11 => 10,
        19 => 13,
        18 => 15,
        17 => 20,
        _ => return None,
    })
}

/// Reads the token `$End<name>` (after a section body).
fn expect_end(tok: &mut Tokens, name: &str) -> Result<(), IoError> {
    let end = format!("$End{name}");
    let (l, w) = tok.next(&format!("'{end}'"))?;
    if w == end {
        Ok(())
    } else {
        Err(err_at(
            l,
            format!("expected '{end}', found '{w}' (is a count in the section wrong?)"),
        ))
    }
}

/// First physical tags of the entities of one dimension, by entity tag.
type Physicals = FxHashMap<i64, i32>;

fn parse_entities(tok: &mut Tokens) -> Result<(Physicals, Physicals), IoError> {
    let counts = [
        tok.usize("number of points")?,
        tok.usize("number of curves")?,
        tok.usize("number of surfaces")?,
        tok.usize("number of volumes")?,
    ];
    let (mut surf, mut vol) = (Physicals::default(), Physicals::default());
    for (dim, &n) in counts.iter().enumerate() {
        for _ in 0..n {
            let (l, w) = tok.next("entity tag")?;
            let tag = super::text::parse_i64(w, l, "entity tag")?;
            let coords = if dim == 0 { 3 } else { 6 };
            for _ in 0..coords {
                tok.f64("entity coordinate")?;
            }
            let np = tok.usize("number of physical tags")?;
            let mut first = 0;
            for k in 0..np {
                let p = tok.i32("physical tag")?;
                if k == 0 {
                    first = p;
                }
            }
            if dim > 0 {
                let nb = tok.usize("number of bounding entities")?;
                for _ in 0..nb {
                    tok.i32("bounding entity tag")?;
                }
            }
            match dim {
                2 => {
                    surf.insert(tag, first);
                }
                3 => {
                    vol.insert(tag, first);
                }
                _ => {}
            }
        }
    }
    Ok((surf, vol))
}

/// Parses the text of a gmsh 4.1 ASCII `.msh` file.
pub fn parse_msh(text: &str) -> Result<TetMesh, IoError> {
    let mut tok = Tokens::new(text);
    let (mut seen_format, mut v2) = (false, false);
    let (mut surf, mut vol) = (Physicals::default(), Physicals::default());
    let mut nodes: Vec<(i64, usize, DVec3)> = Vec::new();
    // (element tag, line, node tags, (entity dimension, entity tag))
    let mut tets: Vec<ElementRecord<4>> = Vec::new();
    let mut tris: Vec<ElementRecord<3>> = Vec::new();
    while let Some((line, w)) = tok.next_opt() {
        let Some(name) = w.strip_prefix('$') else {
            return Err(err_at(
                line,
                format!("expected a section ($Name), found '{w}'"),
            ));
        };
        if !seen_format && name != "MeshFormat" {
            return Err(err_at(line, "expected '$MeshFormat' first"));
        }
        match name {
            "MeshFormat" => {
                let (l, v) = tok.next("version")?;
                v2 = matches!(v, "2" | "2.0" | "2.1" | "2.2");
                if v != "4.1" && !v2 {
                    return Err(err_at(
                        l,
                        format!("unsupported MSH version '{v}': only 4.1 and 2.x are supported"),
                    ));
                }
                let (l, ft) = tok.next("file type")?;
                if ft != "0" {
                    return Err(err_at(l, "binary .msh files are not supported"));
                }
                tok.usize("data size")?;
                expect_end(&mut tok, name)?;
                seen_format = true;
            }
            "Entities" => {
                (surf, vol) = parse_entities(&mut tok)?;
                expect_end(&mut tok, name)?;
            }
            "Nodes" if v2 => {
                for _ in 0..tok.usize("number of nodes")? {
                    let (l, t) = tok.raw_index("node tag")?;
                    nodes.push((t, l, tok.point()?));
                }
                expect_end(&mut tok, name)?;
            }
            "Elements" if v2 => {
                parse_v2_elements(&mut tok, &mut tets, &mut tris, &mut surf, &mut vol)?;
                expect_end(&mut tok, name)?;
            }
            "Nodes" => {
                let blocks = tok.usize("number of node blocks")?;
                tok.usize("number of nodes")?;
                tok.usize("minimum node tag")?;
                tok.usize("maximum node tag")?;
                for _ in 0..blocks {
                    let dim = tok.usize("entity dimension")?;
                    tok.i32("entity tag")?;
                    let param = tok.usize("parametric flag")?;
                    let n = tok.usize("number of nodes in block")?;
                    let mut tags = Vec::with_capacity(super::text::cap(n));
                    for _ in 0..n {
                        tags.push(tok.raw_index("node tag")?);
                    }
                    for (l, t) in tags {
                        let p = tok.point()?;
                        if param != 0 {
                            for _ in 0..dim {
                                tok.f64("parametric coordinate")?;
                            }
                        }
                        nodes.push((t, l, p));
                    }
                }
                expect_end(&mut tok, name)?;
            }
            "Elements" => {
                let blocks = tok.usize("number of element blocks")?;
                tok.usize("number of elements")?;
                tok.usize("minimum element tag")?;
                tok.usize("maximum element tag")?;
                for _ in 0..blocks {
                    let dim = tok.usize("entity dimension")?;
                    let (l, w) = tok.next("entity tag")?;
                    let entity = (dim, super::text::parse_i64(w, l, "entity tag")?);
                    let (l, w) = tok.next("element type")?;
                    let ty = super::text::parse_i64(w, l, "element type")?;
                    let k = nodes_per_element(ty)
                        .ok_or_else(|| err_at(l, format!("unknown element type {ty}")))?;
                    let n = tok.usize("number of elements in block")?;
                    for _ in 0..n {
                        let (l, tag) = tok.raw_index("element tag")?;
                        let mut ids = [0i64; 20];
                        for id in ids.iter_mut().take(k) {
                            *id = tok.raw_index("element node tag")?.1;
                        }
                        match ty {
                            4 | 11 => tets.push((tag, l, [ids[0], ids[1], ids[2], ids[3]], entity)),
                            2 | 9 => tris.push((tag, l, [ids[0], ids[1], ids[2]], entity)),
                            _ => {}
                        }
                    }
                }
                expect_end(&mut tok, name)?;
            }
            _ => {
                // Skip an unknown or unneeded section ($PhysicalNames, $Periodic, data...).
                let end = format!("$End{name}");
                loop {
                    let (_, w) = tok.next(&format!("'{end}'"))?;
                    if w == end {
                        break;
                    }
                }
            }
        }
    }
    if !seen_format {
        return Err(err_at(1, "no '$MeshFormat' section: not a .msh file"));
    }

    nodes.sort_by_key(|n| n.0);
    if let Some(w) = nodes.windows(2).find(|w| w[0].0 == w[1].0) {
        return Err(err_at(w[1].1, format!("duplicate node tag {}", w[1].0)));
    }
    super::text::to_u32(nodes.len(), 1, "number of nodes")?;
    let index: FxHashMap<i64, u32> = nodes
        .iter()
        .enumerate()
        .map(|(i, n)| (n.0, i as u32))
        .collect();
    let lookup = |tag: i64, line: usize| {
        index
            .get(&tag)
            .copied()
            .ok_or_else(|| err_at(line, format!("element refers to unknown node tag {tag}")))
    };
    // First physical tag of an element's entity; 0 when it has none.
    let physical = |(dim, tag): (usize, i64)| {
        let map = match dim {
            2 => &surf,
            3 => &vol,
            _ => return 0,
        };
        map.get(&tag).copied().unwrap_or(0)
    };
    let mut mesh = TetMesh {
        vertices: nodes.iter().map(|n| n.2).collect(),
        ..TetMesh::default()
    };
    tets.sort_by_key(|t| t.0);
    for (_, l, t, e) in &tets {
        let mut ids = [0u32; 4];
        for (d, &s) in ids.iter_mut().zip(t) {
            *d = lookup(s, *l)?;
        }
        mesh.tets.push(ids);
        mesh.tet_regions.push(physical(*e));
    }
    tris.sort_by_key(|t| t.0);
    for (_, l, t, e) in &tris {
        let mut ids = [0u32; 3];
        for (d, &s) in ids.iter_mut().zip(t) {
            *d = lookup(s, *l)?;
        }
        mesh.boundary.push(ids);
        mesh.boundary_markers.push(physical(*e));
    }
    Ok(mesh)
}

/// MSH 2.x `$Elements`: the first tag (physical group) becomes the element's entity, mapped
/// to itself, so regions and markers come out as with 4.1's entities.
fn parse_v2_elements(
    tok: &mut Tokens,
    tets: &mut Vec<ElementRecord<4>>,
    tris: &mut Vec<ElementRecord<3>>,
    surf: &mut Physicals,
    vol: &mut Physicals,
) -> Result<(), IoError> {
    for _ in 0..tok.usize("number of elements")? {
        let (l, tag) = tok.raw_index("element tag")?;
        let (lt, w) = tok.next("element type")?;
        let ty = super::text::parse_i64(w, lt, "element type")?;
        let k = nodes_per_element(ty)
            .ok_or_else(|| err_at(lt, format!("unknown element type {ty}")))?;
        let mut physical = 0;
        for i in 0..tok.usize("number of tags")? {
            let t = tok.i32("element tag value")?;
            if i == 0 {
                physical = t;
            }
        }
        let mut ids = [0i64; 20];
        for id in ids.iter_mut().take(k) {
            *id = tok.raw_index("element node tag")?.1;
        }
        let p = i64::from(physical);
        match ty {
            4 | 11 => {
                vol.insert(p, physical);
                tets.push((tag, l, [ids[0], ids[1], ids[2], ids[3]], (3, p)));
            }
            2 | 9 => {
                surf.insert(p, physical);
                tris.push((tag, l, [ids[0], ids[1], ids[2]], (2, p)));
            }
            _ => {}
        }
    }
    Ok(())
}

/// (element tag, line, node tags, (entity dimension, entity tag)) of one parsed element.
type ElementRecord<const N: usize> = (i64, usize, [i64; N], (usize, i64));

#[cfg(test)]
mod tests {
    use super::*;

    fn two_tets() -> TetMesh {
        TetMesh {
            vertices: vec![
                DVec3::ZERO,
                DVec3::X,
                DVec3::Y,
                DVec3::Z,
                DVec3::new(1.0, 1.0, 1.0),
            ],
            tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]],
            tet_regions: vec![0, 5],
            boundary: vec![[0, 2, 1], [1, 2, 4], [0, 1, 3]],
            boundary_markers: vec![3, 0, 3],
        }
    }

    fn text(m: &TetMesh) -> String {
        let mut out = Vec::new();
        format_msh(&mut out, m).unwrap();
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn round_trip_keeps_order_regions_and_markers() {
        let m = two_tets();
        let t = text(&m);
        assert!(
            t.contains(
                "$PhysicalNames\n4\n3 0 \"region_0\"\n3 5 \"region_5\"\n\
                 2 3 \"marker_3\"\n2 0 \"marker_0\"\n"
            ),
            "{t}"
        );
        assert_eq!(parse_msh(&t).unwrap(), m);
    }

    fn expect_err(text: &str, line: usize, needle: &str) {
        let e = parse_msh(text).unwrap_err();
        assert_eq!(e.line, Some(line), "{e}");
        assert!(e.message.contains(needle), "'{needle}' not in: {e}");
    }

    #[test]
    fn malformed_msh_files() {
        let good = text(&two_tets());
        let line = |pat: &str| good[..good.find(pat).unwrap()].matches('\n').count() + 1;
        expect_err("", 1, "not a .msh");
        expect_err(
            "$MeshFormat\n3.0 0 8\n$EndMeshFormat\n",
            2,
            "only 4.1 and 2.x",
        );
        expect_err("$MeshFormat\n4.1 1 8\n$EndMeshFormat\n", 2, "binary");
        expect_err("$Nodes\n", 1, "'$MeshFormat' first");
        expect_err("$MeshFormat\n4.1 0 8\n", 3, "unexpected end");
        expect_err(
            &good.replace("\n4 2 3 5\n", "\n4 2 3 9\n"),
            line("\n4 2 3 5\n") + 1,
            "unknown node tag 9",
        );
        expect_err(
            &good.replace("3 1 4 1\n", "3 1 99 1\n"),
            line("3 1 4 1\n"),
            "unknown element type 99",
        );
        expect_err(
            &good.replace("$EndNodes", "$EndNode"),
            line("$EndNodes"),
            "expected '$EndNodes'",
        );
        expect_err(
            &good.replace("3 1 0 5\n", "3 1 0 4\n"),
            line("\n0 0 1\n") + 1,
            "expected '$EndNodes', found '1' (is a count",
        );
        expect_err(
            &good.replace("\n2\n3\n", "\n2\n2\n"),
            line("\n2\n3\n") + 2,
            "duplicate node tag 2",
        );
        expect_err(
            &good.replace("\n0 1 0\n", "\n0 one 0\n"),
            line("\n0 1 0\n") + 1,
            "bad number 'one'",
        );
    }

    /// `two_tets` as gmsh 2.2 writes it (one physical tag and one elementary tag per element,
    /// a point element, node ids not in order, the second tet inverted on purpose).
    const TWO_TETS_V22: &str = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n\
        $PhysicalNames\n1\n3 5 \"v\"\n$EndPhysicalNames\n$Nodes\n5\n\
        2 1 0 0\n1 0 0 0\n3 0 1 0\n4 0 0 1\n5 1 1 1\n$EndNodes\n\
        $Elements\n6\n1 15 2 0 1 1\n2 2 2 3 1 1 3 2\n3 2 2 0 1 2 3 5\n4 2 2 3 1 1 2 4\n\
        5 4 0 1 2 3 4\n6 4 2 5 2 3 2 4 5\n$EndElements\n";

    #[test]
    fn reads_msh_2_2() {
        let m = parse_msh(TWO_TETS_V22).unwrap();
        let mut want = two_tets();
        want.tets[1] = [2, 1, 3, 4];
        assert_eq!(m, want);
        let e =
            parse_msh(&TWO_TETS_V22.replace("6 4 2 5 2 3 2 4 5", "6 4 2 5 2 3 2 4 9")).unwrap_err();
        assert_eq!(e.line, Some(23), "{e}");
        assert!(e.message.contains("unknown node tag 9"), "{e}");
        for cut in 0..TWO_TETS_V22.len() {
            let _ = parse_msh(&TWO_TETS_V22[..cut]);
        }
    }

    #[test]
    fn truncated_msh_never_panics() {
        let good = text(&two_tets());
        for cut in 0..good.len() {
            let _ = parse_msh(&good[..cut]);
        }
    }
}
