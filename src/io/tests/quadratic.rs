//! Ten-node tets through `write_output`, every format: the files are taken apart here by small
//! parsers of their own (not the crate's readers), and every mid-edge node of every tet and
//! boundary triangle must sit at the midpoint of the corner pair the format's documented node
//! order names. The expected pairs are written out per format below, from the formats' own
//! documentation, not from `io::elements`, so a wrong permutation there fails here.

use super::roundtrip::sample_mesh;
use super::TempDir;
use crate::io::{read_mesh, write_output, CellField};
use crate::mesh::{QuadraticNodes, TetMesh};
use glam::DVec3;
use std::path::Path;

/// Corner pairs of nodes 4..10 of a ten-node tet, per format.
const VTK_TET: [(usize, usize); 6] = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)];
/// Gmsh manual, "Node ordering", tetrahedron10: 4=01, 5=12, 6=20, 7=30, 8=32, 9=31.
const GMSH_TET: [(usize, usize); 6] = [(0, 1), (1, 2), (2, 0), (3, 0), (3, 2), (3, 1)];
/// `tetgen -o2` (observed with TetGen 1.5.0 on a unit tet, and tetgen.cxx's tables).
const TETGEN_TET: [(usize, usize); 6] = [(2, 3), (0, 3), (0, 1), (1, 2), (1, 3), (0, 2)];
/// Six-node triangles: gmsh type 9 and MEDIT `TrianglesP2`.
const TRI: [(usize, usize); 3] = [(0, 1), (1, 2), (2, 0)];
/// TetGen `-o2` `.face`: the edges opposite corners 0, 1, 2.
const TETGEN_TRI: [(usize, usize); 3] = [(1, 2), (2, 0), (0, 1)];

/// What a parser found in a file: node positions, tets and triangles as 0-based node lists
/// (with their region or marker where the format stores one per element).
#[derive(Default, Debug)]
struct Parsed {
    nodes: Vec<DVec3>,
    tets: Vec<(Vec<u32>, Option<i32>)>,
    tris: Vec<(Vec<u32>, Option<i32>)>,
}

fn quadratic_sample() -> (TetMesh, QuadraticNodes) {
    let m = sample_mesh(2);
    let q = QuadraticNodes::straight(&m);
    (m, q)
}

/// Checks a parsed file against the mesh: node count and corner positions, the tets (corners,
/// regions) and triangles (corners, markers) as multisets, and every mid-edge node at the
/// midpoint of its corner pair.
fn check(
    what: &str,
    m: &TetMesh,
    q: &QuadraticNodes,
    p: &Parsed,
    tet_pairs: &[(usize, usize); 6],
    tri_pairs: Option<&[(usize, usize); 3]>,
) {
    let bits = |v: DVec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
    assert_eq!(p.nodes.len(), q.n_nodes(m), "{what}: node count");
    for (i, (a, b)) in m.vertices.iter().zip(&p.nodes).enumerate() {
        assert_eq!(bits(*a), bits(*b), "{what}: corner node {i}");
    }
    let mid =
        |t: &[u32], (i, j): (usize, usize)| (p.nodes[t[i] as usize] + p.nodes[t[j] as usize]) * 0.5;
    assert_eq!(p.tets.len(), m.tets.len(), "{what}: tet count");
    for (k, (t, _)) in p.tets.iter().enumerate() {
        assert_eq!(t.len(), 10, "{what}: tet {k} has {} nodes", t.len());
        for (e, &pair) in tet_pairs.iter().enumerate() {
            assert_eq!(
                bits(p.nodes[t[4 + e] as usize]),
                bits(mid(t, pair)),
                "{what}: tet {k} {t:?}: node {} is not the midpoint of corners {pair:?}",
                4 + e
            );
        }
    }
    let mut want: Vec<([u32; 4], Option<i32>)> = m
        .tets
        .iter()
        .zip(&m.tet_regions)
        .map(|(t, &r)| (*t, Some(r)))
        .collect();
    let mut got: Vec<([u32; 4], Option<i32>)> = p
        .tets
        .iter()
        .map(|(t, r)| ([t[0], t[1], t[2], t[3]], *r))
        .collect();
    if got.iter().all(|g| g.1.is_none()) {
        want.iter_mut().for_each(|w| w.1 = None);
    }
    want.sort_unstable();
    got.sort_unstable();
    assert_eq!(want, got, "{what}: tets and regions");
    let Some(tri_pairs) = tri_pairs else {
        assert!(p.tris.is_empty(), "{what}: no triangles expected");
        return;
    };
    assert_eq!(p.tris.len(), m.boundary.len(), "{what}: triangle count");
    for (k, (t, _)) in p.tris.iter().enumerate() {
        assert_eq!(t.len(), 6, "{what}: triangle {k} has {} nodes", t.len());
        for (e, &pair) in tri_pairs.iter().enumerate() {
            assert_eq!(
                bits(p.nodes[t[3 + e] as usize]),
                bits(mid(t, pair)),
                "{what}: triangle {k} {t:?}: node {} is not the midpoint of {pair:?}",
                3 + e
            );
        }
    }
    let mut want: Vec<([u32; 3], Option<i32>)> = m
        .boundary
        .iter()
        .zip(&m.boundary_markers)
        .map(|(t, &r)| (*t, Some(r)))
        .collect();
    let mut got: Vec<([u32; 3], Option<i32>)> = p
        .tris
        .iter()
        .map(|(t, r)| ([t[0], t[1], t[2]], *r))
        .collect();
    if got.iter().all(|g| g.1.is_none()) {
        want.iter_mut().for_each(|w| w.1 = None);
    }
    want.sort_unstable();
    got.sort_unstable();
    assert_eq!(want, got, "{what}: triangles and markers");
}

fn text(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

fn num<T: std::str::FromStr>(w: &str) -> T
where
    T::Err: std::fmt::Debug,
{
    w.parse().unwrap_or_else(|e| panic!("'{w}': {e:?}"))
}

/// Gmsh 4.1 ASCII: `$Nodes` and `$Elements`; the region or marker is the entity's physical tag.
fn parse_msh_ascii(t: &str) -> (Parsed, Vec<i32>) {
    let mut p = Parsed::default();
    let mut types = Vec::new();
    let physical = parse_msh_entities(t);
    let nodes = t.split("$Nodes\n").nth(1).unwrap();
    let mut w = nodes.split_whitespace();
    let mut next = || w.next().unwrap();
    let blocks: usize = num(next());
    let n: usize = num(next());
    next();
    next();
    p.nodes = vec![DVec3::ZERO; n];
    for _ in 0..blocks {
        next();
        next();
        next();
        let k: usize = num(next());
        let tags: Vec<usize> = (0..k).map(|_| num(next())).collect();
        for tag in tags {
            p.nodes[tag - 1] = DVec3::new(num(next()), num(next()), num(next()));
        }
    }
    let elements = t.split("$Elements\n").nth(1).unwrap();
    let mut w = elements.split_whitespace();
    let mut next = || w.next().unwrap();
    let blocks: usize = num(next());
    for _ in 0..3 {
        next();
    }
    for _ in 0..blocks {
        let dim: usize = num(next());
        let entity: usize = num(next());
        let ty: i32 = num(next());
        types.push(ty);
        let k = match ty {
            11 => 10,
            9 => 6,
            _ => panic!("element type {ty}"),
        };
        let n: usize = num(next());
        for _ in 0..n {
            next();
            let ids: Vec<u32> = (0..k).map(|_| num::<u32>(next()) - 1).collect();
            let r = Some(physical[&(dim, entity)]);
            if dim == 3 {
                p.tets.push((ids, r));
            } else {
                p.tris.push((ids, r));
            }
        }
    }
    (p, types)
}

/// The physical tag of each (dimension, entity tag) of an ASCII `$Entities` section.
fn parse_msh_entities(t: &str) -> std::collections::HashMap<(usize, usize), i32> {
    let body = t.split("$Entities\n").nth(1).unwrap();
    let mut w = body.split_whitespace();
    let mut next = || w.next().unwrap();
    let counts: Vec<usize> = (0..4).map(|_| num(next())).collect();
    assert_eq!(&counts[..2], &[0, 0]);
    let mut out = std::collections::HashMap::new();
    for (dim, &n) in counts.iter().enumerate().skip(2) {
        for _ in 0..n {
            let tag: usize = num(next());
            for _ in 0..6 {
                next();
            }
            assert_eq!(next(), "1", "one physical tag");
            out.insert((dim, tag), num(next()));
            assert_eq!(next(), "0", "no bounding entities");
        }
    }
    out
}

/// Gmsh 4.1 binary (the layout of `gmsh_binary`'s module doc); regions and markers are not
/// decoded here (the ASCII parser checks them; the entity records have the same content).
fn parse_msh_binary(b: &[u8]) -> (Parsed, Vec<i32>) {
    let find = |s: &[u8]| b.windows(s.len()).position(|w| w == s).unwrap() + s.len();
    let mut o;
    let u64_at = |o: &mut usize| {
        let v = u64::from_le_bytes(b[*o..*o + 8].try_into().unwrap());
        *o += 8;
        v as usize
    };
    let i32_at = |o: &mut usize| {
        let v = i32::from_le_bytes(b[*o..*o + 4].try_into().unwrap());
        *o += 4;
        v
    };
    let f64_at = |o: &mut usize| {
        let v = f64::from_le_bytes(b[*o..*o + 8].try_into().unwrap());
        *o += 8;
        v
    };
    let mut p = Parsed::default();
    o = find(b"$Nodes\n");
    let blocks = u64_at(&mut o);
    let n = u64_at(&mut o);
    u64_at(&mut o);
    u64_at(&mut o);
    p.nodes = vec![DVec3::ZERO; n];
    for _ in 0..blocks {
        i32_at(&mut o);
        i32_at(&mut o);
        assert_eq!(i32_at(&mut o), 0, "no parametric coordinates");
        let k = u64_at(&mut o);
        let tags: Vec<usize> = (0..k).map(|_| u64_at(&mut o)).collect();
        for tag in tags {
            p.nodes[tag - 1] = DVec3::new(f64_at(&mut o), f64_at(&mut o), f64_at(&mut o));
        }
    }
    assert_eq!(&b[o..o + 10], b"\n$EndNodes");
    o = find(b"$Elements\n");
    let blocks = u64_at(&mut o);
    for _ in 0..3 {
        u64_at(&mut o);
    }
    let mut types = Vec::new();
    for _ in 0..blocks {
        let dim = i32_at(&mut o);
        i32_at(&mut o);
        let ty = i32_at(&mut o);
        types.push(ty);
        let k = match ty {
            11 => 10,
            9 => 6,
            _ => panic!("element type {ty}"),
        };
        let n = u64_at(&mut o);
        for _ in 0..n {
            u64_at(&mut o);
            let ids: Vec<u32> = (0..k).map(|_| u64_at(&mut o) as u32 - 1).collect();
            if dim == 3 {
                p.tets.push((ids, None));
            } else {
                p.tris.push((ids, None));
            }
        }
    }
    assert_eq!(&b[o..], b"\n$EndElements\n");
    (p, types)
}

/// The body of the ASCII `DataArray` named `name`.
fn vtu_array<'a>(t: &'a str, name: &str) -> &'a str {
    let start = t.find(&format!("Name=\"{name}\"")).unwrap();
    let body = &t[start..];
    let body = &body[body.find('>').unwrap() + 1..];
    &body[..body.find("</DataArray>").unwrap()]
}

/// `.vtu` ASCII: points, cells by offsets, cell types and the `region` array.
fn parse_vtu_ascii(t: &str) -> (Parsed, Vec<u8>, Vec<f64>) {
    let nums =
        |name: &str| -> Vec<f64> { vtu_array(t, name).split_whitespace().map(num).collect() };
    let pts = nums("Points");
    let conn = nums("connectivity");
    let offsets = nums("offsets");
    let types: Vec<u8> = nums("types").iter().map(|&x| x as u8).collect();
    let regions = nums("region");
    let mut p = Parsed {
        nodes: pts
            .chunks(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect(),
        ..Parsed::default()
    };
    let mut start = 0;
    for (k, &end) in offsets.iter().enumerate() {
        let end = end as usize;
        let ids = conn[start..end].iter().map(|&x| x as u32).collect();
        p.tets.push((ids, Some(regions[k] as i32)));
        start = end;
    }
    (p, types, nums("quality"))
}

/// `.vtu` binary appended: the arrays by their `offset` attributes, in document order.
fn parse_vtu_binary(b: &[u8]) -> (Parsed, Vec<u8>, Vec<f64>) {
    let start = b.windows(2).position(|w| w == b"\n_").unwrap() + 2;
    let head = String::from_utf8_lossy(&b[..start]).to_string();
    let arrays: Vec<(String, usize)> = head
        .split("<DataArray ")
        .skip(1)
        .map(|s| {
            let name = s.split("Name=\"").nth(1).unwrap();
            let name = name[..name.find('"').unwrap()].to_string();
            let off = s.split("offset=\"").nth(1).unwrap();
            (name, num(&off[..off.find('"').unwrap()]))
        })
        .collect();
    let raw = |name: &str| -> &[u8] {
        let o = start + arrays.iter().find(|a| a.0 == name).unwrap().1;
        let n = u64::from_le_bytes(b[o..o + 8].try_into().unwrap()) as usize;
        &b[o + 8..o + 8 + n]
    };
    let f64s = |name: &str| -> Vec<f64> {
        raw(name)
            .chunks(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    };
    let i64s = |name: &str| -> Vec<i64> {
        raw(name)
            .chunks(8)
            .map(|c| i64::from_le_bytes(c.try_into().unwrap()))
            .collect()
    };
    let pts = f64s("Points");
    let conn = i64s("connectivity");
    let offsets = i64s("offsets");
    let regions: Vec<i32> = raw("region")
        .chunks(4)
        .map(|c| i32::from_le_bytes(c.try_into().unwrap()))
        .collect();
    let mut p = Parsed {
        nodes: pts
            .chunks(3)
            .map(|c| DVec3::new(c[0], c[1], c[2]))
            .collect(),
        ..Parsed::default()
    };
    let mut s = 0;
    for (k, &end) in offsets.iter().enumerate() {
        let ids = conn[s..end as usize].iter().map(|&x| x as u32).collect();
        p.tets.push((ids, Some(regions[k])));
        s = end as usize;
    }
    (p, raw("types").to_vec(), f64s("quality"))
}

/// MEDIT `.mesh`: `Vertices`, `TetrahedraP2`, `TrianglesP2` and the two ordering keywords.
fn parse_medit(t: &str) -> (Parsed, Vec<String>) {
    let words: Vec<&str> = t.split_whitespace().collect();
    let mut p = Parsed::default();
    let mut keywords = Vec::new();
    let mut i = 0;
    while i < words.len() {
        let kw = words[i];
        i += 1;
        let width = match kw {
            "MeshVersionFormatted" | "Dimension" => {
                i += 1;
                continue;
            }
            "End" => break,
            "Vertices" => 4,
            "TetrahedraP2" => 11,
            "TrianglesP2" => 7,
            "TetrahedraP2Ordering" => 4,
            "TrianglesP2Ordering" => 3,
            _ => panic!("unexpected keyword {kw}"),
        };
        keywords.push(kw.to_string());
        let n: usize = num(words[i]);
        i += 1;
        for r in words[i..i + n * width].chunks(width) {
            match kw {
                "Vertices" => p.nodes.push(DVec3::new(num(r[0]), num(r[1]), num(r[2]))),
                "TetrahedraP2" | "TrianglesP2" => {
                    let ids = r[..width - 1].iter().map(|w| num::<u32>(w) - 1).collect();
                    let e = (ids, Some(num(r[width - 1])));
                    if kw == "TetrahedraP2" {
                        p.tets.push(e);
                    } else {
                        p.tris.push(e);
                    }
                }
                _ => keywords.push(r.join(" ")),
            }
        }
        i += n * width;
    }
    (p, keywords)
}

/// Abaqus `.inp`: `*NODE`, the `*ELEMENT` blocks (type and `ELSET=REGION_<r>`), the surfaces.
fn parse_inp(t: &str) -> (Parsed, Vec<String>, usize) {
    let mut p = Parsed::default();
    let mut types = Vec::new();
    let mut surface_faces = 0;
    let mut section = String::new();
    let mut region = 0;
    for line in t.lines() {
        if let Some(head) = line.strip_prefix('*') {
            section = head.to_string();
            if let Some(rest) = head.strip_prefix("ELEMENT, TYPE=") {
                let (ty, set) = rest.split_once(", ELSET=REGION_").unwrap();
                types.push(ty.to_string());
                region = match set.strip_prefix('M') {
                    Some(v) => -num::<i32>(v),
                    None => num(set),
                };
            }
            continue;
        }
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if section.starts_with("NODE") {
            assert_eq!(num::<usize>(f[0]), p.nodes.len() + 1);
            p.nodes.push(DVec3::new(num(f[1]), num(f[2]), num(f[3])));
        } else if section.starts_with("ELEMENT") {
            let ids = f[1..].iter().map(|w| num::<u32>(w) - 1).collect();
            p.tets.push((ids, Some(region)));
        } else if section.starts_with("SURFACE") {
            surface_faces += 1;
        }
    }
    (p, types, surface_faces)
}

/// TetGen `.node`/`.ele`/`.face` (1-based, as written).
fn parse_tetgen(stem: &Path) -> (Parsed, usize) {
    let rows = |ext: &str| -> Vec<Vec<String>> {
        text(&stem.with_extension(ext))
            .lines()
            .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
            .map(|l| l.split_whitespace().map(String::from).collect())
            .collect()
    };
    let mut p = Parsed::default();
    let node = rows("node");
    for r in &node[1..] {
        p.nodes.push(DVec3::new(num(&r[1]), num(&r[2]), num(&r[3])));
    }
    let ele = rows("ele");
    let per_tet: usize = num(&ele[0][1]);
    for r in &ele[1..] {
        let ids = r[1..1 + per_tet]
            .iter()
            .map(|w| num::<u32>(w) - 1)
            .collect();
        p.tets.push((ids, Some(num(&r[1 + per_tet]))));
    }
    for r in &rows("face")[1..] {
        let ids = r[1..r.len() - 1]
            .iter()
            .map(|w| num::<u32>(w) - 1)
            .collect();
        p.tris.push((ids, Some(num(&r[r.len() - 1]))));
    }
    (p, per_tet)
}

#[test]
fn gmsh_ascii_and_binary_ten_node_tets() {
    let (m, q) = quadratic_sample();
    let dir = TempDir::new("p2msh");
    let a = dir.path("a.msh");
    write_output(&a, &m, Some(&q), &[], false).unwrap();
    let (p, types) = parse_msh_ascii(&text(&a));
    assert!(types.iter().all(|&t| t == 11 || t == 9), "{types:?}");
    assert!(types.contains(&11) && types.contains(&9), "{types:?}");
    check("msh", &m, &q, &p, &GMSH_TET, Some(&TRI));

    let b = dir.path("b.msh");
    write_output(&b, &m, Some(&q), &[], true).unwrap();
    let bytes = std::fs::read(&b).unwrap();
    assert!(bytes.starts_with(b"$MeshFormat\n4.1 1 8\n"));
    let (pb, types_b) = parse_msh_binary(&bytes);
    assert_eq!(types, types_b);
    check("binary msh", &m, &q, &pb, &GMSH_TET, Some(&TRI));
    assert_eq!(p.tets.iter().map(|t| &t.0).collect::<Vec<_>>(), {
        pb.tets.iter().map(|t| &t.0).collect::<Vec<_>>()
    });

    // The crate's reader keeps the corners of the type-11 and type-9 elements.
    let back = read_mesh(&a).unwrap();
    assert_eq!(back.vertices.len(), q.n_nodes(&m));
    assert_eq!(back.tets, m.tets);
    assert_eq!(back.tet_regions, m.tet_regions);
    assert_eq!(back.boundary, m.boundary);
    assert_eq!(back.boundary_markers, m.boundary_markers);
}

#[test]
fn vtu_ascii_and_binary_quadratic_tetra() {
    let (m, q) = quadratic_sample();
    let quality: Vec<f64> = (0..m.tets.len()).map(|i| i as f64 / 3.0).collect();
    let fields = [CellField {
        name: "quality",
        values: &quality,
    }];
    let dir = TempDir::new("p2vtu");
    let a = dir.path("a.vtu");
    write_output(&a, &m, Some(&q), &fields, false).unwrap();
    let t = text(&a);
    assert!(t.contains(&format!(
        "<Piece NumberOfPoints=\"{}\" NumberOfCells=\"{}\">",
        q.n_nodes(&m),
        m.tets.len()
    )));
    let (p, types, qa) = parse_vtu_ascii(&t);
    assert!(types.iter().all(|&t| t == 24), "VTK_QUADRATIC_TETRA");
    assert_eq!(qa, quality);
    check("vtu", &m, &q, &p, &VTK_TET, None);

    let b = dir.path("b.vtu");
    write_output(&b, &m, Some(&q), &fields, true).unwrap();
    let (pb, types_b, qb) = parse_vtu_binary(&std::fs::read(&b).unwrap());
    assert!(types_b.iter().all(|&t| t == 24));
    assert_eq!(types_b.len(), m.tets.len());
    assert_eq!(qb, quality);
    check("binary vtu", &m, &q, &pb, &VTK_TET, None);
}

#[test]
fn medit_tetrahedra_p2() {
    let (m, q) = quadratic_sample();
    let dir = TempDir::new("p2mesh");
    let a = dir.path("a.mesh");
    write_output(&a, &m, Some(&q), &[], false).unwrap();
    let (p, keywords) = parse_medit(&text(&a));
    check("mesh", &m, &q, &p, &VTK_TET, Some(&TRI));
    // The ordering keywords state the same order as barycentric multi-indices.
    let tet_ordering: Vec<&str> = keywords
        .iter()
        .skip_while(|k| *k != "TetrahedraP2Ordering")
        .skip(1)
        .take(10)
        .map(String::as_str)
        .collect();
    let mut want = vec!["2 0 0 0", "0 2 0 0", "0 0 2 0", "0 0 0 2"];
    let rows: Vec<String> = VTK_TET
        .iter()
        .map(|&(i, j)| {
            let mut b = [0; 4];
            b[i] = 1;
            b[j] = 1;
            b.map(|x| x.to_string()).join(" ")
        })
        .collect();
    want.extend(rows.iter().map(String::as_str));
    assert_eq!(tet_ordering, want);
    let tri_ordering: Vec<&str> = keywords
        .iter()
        .skip_while(|k| *k != "TrianglesP2Ordering")
        .skip(1)
        .take(6)
        .map(String::as_str)
        .collect();
    assert_eq!(
        tri_ordering,
        ["2 0 0", "0 2 0", "0 0 2", "1 1 0", "0 1 1", "1 0 1"]
    );
    // The crate's reader keeps the corners.
    let back = read_mesh(&a).unwrap();
    assert_eq!(back.vertices.len(), q.n_nodes(&m));
    assert_eq!(back.tets, m.tets);
    assert_eq!(back.tet_regions, m.tet_regions);
    assert_eq!(back.boundary, m.boundary);
    assert_eq!(back.boundary_markers, m.boundary_markers);
}

#[test]
fn abaqus_c3d10() {
    let (m, q) = quadratic_sample();
    let dir = TempDir::new("p2inp");
    let a = dir.path("a.inp");
    write_output(&a, &m, Some(&q), &[], false).unwrap();
    let (p, types, faces) = parse_inp(&text(&a));
    assert!(
        !types.is_empty() && types.iter().all(|t| t == "C3D10"),
        "{types:?}"
    );
    check("inp", &m, &q, &p, &VTK_TET, None);
    // Same surfaces as the four-node file.
    let lin = dir.path("lin.inp");
    write_output(&lin, &m, None, &[], false).unwrap();
    let lin_text = text(&lin);
    let surfaces = |t: &str| t[t.find("*SURFACE").unwrap()..].to_string();
    assert_eq!(surfaces(&text(&a)), surfaces(&lin_text));
    assert_eq!(faces, m.boundary.len());
}

#[test]
fn tetgen_o2() {
    let (m, q) = quadratic_sample();
    let dir = TempDir::new("p2tetgen");
    let a = dir.path("a.ele");
    write_output(&a, &m, Some(&q), &[], false).unwrap();
    let (p, per_tet) = parse_tetgen(&a);
    assert_eq!(per_tet, 10);
    check("tetgen", &m, &q, &p, &TETGEN_TET, Some(&TETGEN_TRI));
    // The crate's reader keeps the corners, reading past the faces' mid-edge nodes.
    let back = read_mesh(&a).unwrap();
    assert_eq!(back.vertices.len(), q.n_nodes(&m));
    assert_eq!(back.tets, m.tets);
    assert_eq!(back.tet_regions, m.tet_regions);
    assert_eq!(back.boundary, m.boundary);
    assert_eq!(back.boundary_markers, m.boundary_markers);
}

/// Without `quadratic`, `write_output` writes the four-node files of `write_mesh_in`.
#[test]
fn linear_output_is_unchanged() {
    let m = sample_mesh(2);
    let dir = TempDir::new("p2lin");
    for (name, binary) in [
        ("a.msh", false),
        ("b.msh", true),
        ("c.vtu", false),
        ("d.vtu", true),
        ("e.mesh", false),
        ("f.inp", false),
        ("g.ele", false),
    ] {
        let (x, y) = (dir.path(&format!("x{name}")), dir.path(&format!("y{name}")));
        write_output(&x, &m, None, &[], binary).unwrap();
        crate::io::write_mesh_in(&y, &m, &[], binary).unwrap();
        assert_eq!(
            std::fs::read(&x).unwrap(),
            std::fs::read(&y).unwrap(),
            "{name}"
        );
    }
    for name in ["xa.msh", "xe.mesh", "xg.ele"] {
        assert_eq!(read_mesh(&dir.path(name)).unwrap(), m, "{name}");
    }
}

#[test]
fn mismatched_quadratic_nodes_are_refused() {
    let (m, q) = quadratic_sample();
    let dir = TempDir::new("p2bad");
    let mut short = q.clone();
    short.tet_edges.pop();
    let mut tris = q.clone();
    tris.boundary_edges.push([0, 0, 0]);
    let mut far = q.clone();
    far.tet_edges[3][2] = q.n_nodes(&m) as u32;
    let mut far_tri = q.clone();
    far_tri.boundary_edges[1][0] = u32::MAX;
    let cases = [
        (short, "tets but"),
        (tris, "boundary triangles but"),
        (far, "tet 3"),
        (far_tri, "boundary triangle 1"),
    ];
    for (bad, needle) in &cases {
        for (name, binary) in [
            ("a.msh", false),
            ("b.msh", true),
            ("c.vtu", false),
            ("d.vtu", true),
            ("e.mesh", false),
            ("f.inp", false),
            ("g.ele", false),
        ] {
            let path = dir.path(name);
            let e = write_output(&path, &m, Some(bad), &[], binary).unwrap_err();
            assert!(e.message.contains(needle), "{name}: {e}");
            assert!(e.path.ends_with(name), "{e}");
            assert!(!path.exists(), "nothing written for {name}");
        }
    }
    // The cell-field lengths are checked as for four-node tets.
    let one = [1.0];
    let f = [CellField {
        name: "quality",
        values: &one,
    }];
    let e = write_output(&dir.path("a.vtu"), &m, Some(&q), &f, true).unwrap_err();
    assert!(e.message.contains("cell field 'quality'"), "{e}");
    // The format_* functions refuse them too.
    let mut sink = Vec::new();
    let bad = &cases[2].0;
    assert!(crate::io::gmsh::format_msh_quadratic(&mut sink, &m, bad).is_err());
    assert!(crate::io::gmsh_binary::format_msh_binary_quadratic(&mut sink, &m, bad).is_err());
    assert!(crate::io::vtu::format_vtu_quadratic(&mut sink, &m, bad, &[]).is_err());
    assert!(crate::io::vtu_binary::format_vtu_binary_quadratic(&mut sink, &m, bad, &[]).is_err());
    assert!(crate::io::medit::format_medit_quadratic(&mut sink, &m, bad).is_err());
    assert!(crate::io::abaqus::format_inp_quadratic(&mut sink, &m, bad).is_err());
    let (mut x, mut y) = (Vec::new(), Vec::new());
    assert!(
        crate::io::tetgen::format_tetgen_quadratic(&mut sink, &mut x, &mut y, &m, bad).is_err()
    );
}
