use super::*;

/// A unit tetrahedron as ASCII PLY with extra properties and an element to skip.
const TET: &str = "ply\nformat ascii 1.0\ncomment made by hand\nobj_info none\n\
    element vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
    property uchar red\nelement face 4\nproperty list uchar int vertex_indices\n\
    property int flags\nelement edge 1\nproperty int vertex1\nproperty int vertex2\n\
    end_header\n0 0 0 255\n1 0 0 0\n0 1 0 0\n0 0 1 0\n3 0 2 1 7\n3 0 1 3 7\n3 0 3 2 7\n\
    3 1 2 3 7\n0 1\n";

fn plain() -> ReadOptions {
    ReadOptions::default()
}

/// The same surface in binary, with the given byte order and a quad split into no triangles.
fn binary(big: bool) -> Vec<u8> {
    let fmt = if big { "big" } else { "little" };
    let mut b = format!(
        "ply\r\nformat binary_{fmt}_endian 1.0\r\nelement face 4\r\n\
         property list ushort uint vertex_index\r\nelement vertex 4\r\nproperty double x\r\n\
         property double y\r\nproperty double z\r\nproperty list uchar float normal\r\n\
         end_header\r\n"
    )
    .into_bytes();
    let u16b = |v: u16| {
        if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let u32b = |v: u32| {
        if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    let f64b = |v: f64| {
        if big {
            v.to_be_bytes()
        } else {
            v.to_le_bytes()
        }
    };
    for f in [[0u32, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]] {
        b.extend_from_slice(&u16b(3));
        for v in f {
            b.extend_from_slice(&u32b(v));
        }
    }
    for p in [
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
    ] {
        for c in p {
            b.extend_from_slice(&f64b(c));
        }
        b.push(1);
        b.extend_from_slice(&[0u8; 4]);
    }
    b
}

#[test]
fn ascii_and_binary_read_the_same_surface() {
    let a = parse_ply(TET.as_bytes(), &plain()).unwrap();
    assert_eq!(a.vertices.len(), 4);
    assert_eq!(a.vertices[3], DVec3::Z);
    let polys: Vec<_> = a.facets.iter().map(|f| f.polygons[0].clone()).collect();
    assert_eq!(
        polys,
        vec![vec![0, 2, 1], vec![0, 1, 3], vec![0, 3, 2], vec![1, 2, 3]]
    );
    assert_eq!(a.facets[3].marker, 4);
    for big in [false, true] {
        let b = parse_ply(&binary(big), &plain()).unwrap();
        assert_eq!(a, b, "big endian: {big}");
    }
}

#[test]
fn polygons_and_merging() {
    let cube = "ply\nformat ascii 1.0\nelement vertex 8\nproperty double x\nproperty double y\n\
        property double z\nelement face 6\nproperty list uchar uint vertex_indices\nend_header\n\
        0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 0 1\n1 0 1\n0 1 1\n1 1 1\n\
        4 0 2 3 1\n4 4 5 7 6\n4 0 1 5 4\n4 2 6 7 3\n4 0 4 6 2\n4 1 3 7 5\n";
    let p = parse_ply(cube.as_bytes(), &plain()).unwrap();
    assert_eq!(p.facets.len(), 6);
    assert!(p.facets.iter().all(|f| f.polygons[0].len() == 4));
    let merged = parse_ply(
        TET.as_bytes(),
        &ReadOptions {
            merge_coplanar: true,
        },
    )
    .unwrap();
    assert_eq!(merged.facets.len(), 4, "no two faces of a tet are coplanar");
}

fn expect_err(text: &str, line: Option<usize>, needle: &str) {
    let e = parse_ply(text.as_bytes(), &plain()).unwrap_err();
    assert_eq!(e.line, line, "{e}");
    assert!(e.message.contains(needle), "'{needle}' not in: {e}");
}

const HEAD: &str = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
    property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";

#[test]
fn malformed_ply_files() {
    expect_err("", Some(1), "expected 'end_header'");
    expect_err("PLY\n", Some(1), "expected 'ply' header");
    expect_err(
        "ply\nformat text 1.0\nend_header\n",
        Some(2),
        "unknown PLY format 'text'",
    );
    expect_err(
        "ply\nformat ascii 2.0\nend_header\n",
        Some(2),
        "version 1.0",
    );
    expect_err("ply\nend_header\n", Some(2), "no 'format' line");
    expect_err(
        "ply\nformat ascii 1.0\nproperty float x\n",
        Some(3),
        "before any 'element'",
    );
    expect_err(
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty real x\n",
        Some(4),
        "unknown property type 'real'",
    );
    expect_err(
        "ply\nformat ascii 1.0\nelement vertex -1\n",
        Some(3),
        "bad non-negative integer '-1'",
    );
    expect_err(
        "ply\nformat ascii 1.0\nvertex 3\n",
        Some(3),
        "unknown PLY header line",
    );
    expect_err(
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n0 0\n",
        Some(3),
        "no scalar property 'z'",
    );
    expect_err(
        "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar float vertex_indices\nend_header\n",
        Some(3),
        "integer type",
    );
    expect_err(
        "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n\
         property float z\nend_header\n",
        None,
        "no 'face' element",
    );
    let body = |b: &str| format!("{HEAD}{b}");
    expect_err(
        &body("0 0 0\n1 0 0\n"),
        Some(12),
        "expected 'x' of vertex 3 of 3",
    );
    expect_err(
        &body("0 0 0\n1 0 0\n0 1 q\n"),
        Some(12),
        "bad number 'q' for 'z' of vertex 3",
    );
    expect_err(
        &body("0 0 0\n1 0 0\n0 1 nan\n"),
        Some(12),
        "vertex 3 of 3 is not finite",
    );
    expect_err(
        &body("0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n"),
        Some(13),
        "vertex index 3 out of range",
    );
    expect_err(
        &body("0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n"),
        Some(13),
        "out of range",
    );
    expect_err(
        &body("0 0 0\n1 0 0\n0 1 0\n2 0 1\n"),
        Some(13),
        "at least 3",
    );
    expect_err(
        &body("0 0 0\n1 0 0\n0 1 0\n256 0 1 2\n"),
        Some(13),
        "does not fit its type uchar",
    );
    expect_err(
        &body("0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n5\n"),
        Some(14),
        "unexpected data after",
    );
}

#[test]
fn malformed_binary_ply() {
    let b = binary(false);
    let e = parse_ply(&b[..b.len() - 3], &plain()).unwrap_err();
    assert_eq!(e.line, None);
    assert!(
        e.message.contains("truncated") && e.message.contains("vertex 4 of 4"),
        "{e}"
    );
    let mut bad = binary(true);
    let at = bad.len() - 5 - 8; // z of the last vertex
    bad[at..at + 8].copy_from_slice(&f64::INFINITY.to_be_bytes());
    let e = parse_ply(&bad, &plain()).unwrap_err();
    assert!(e.message.contains("vertex 4 of 4 is not finite"), "{e}");
}

#[test]
fn truncated_ply_never_panics() {
    for data in [TET.as_bytes().to_vec(), binary(false), binary(true)] {
        for cut in 0..data.len() {
            let _ = parse_ply(&data[..cut], &plain());
        }
    }
}
