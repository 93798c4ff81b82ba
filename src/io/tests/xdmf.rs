//! `.xdmf` + `.h5` (feature `hdf5`): the arrays read back through the hdf5 crate, the XDMF
//! naming them (the layout itself is tested without HDF5 in `io::xdmf`).

use super::roundtrip::sample_mesh;
use super::TempDir;
use crate::io::xdmf::{h5_path, CELL_TAGS, FACET_TAGS};
use crate::io::{write_mesh, write_output};
use crate::mesh::{QuadraticNodes, TetMesh};
use hdf5::types::{FloatSize, IntSize, TypeDescriptor};
use std::path::Path;

/// A dataset's shape, element type and values.
fn read<T: hdf5::H5Type>(f: &hdf5::File, at: &str) -> (Vec<usize>, TypeDescriptor, Vec<T>) {
    let d = f.dataset(at).unwrap_or_else(|e| panic!("{at}: {e}"));
    let ty = d.dtype().unwrap().to_descriptor().unwrap();
    (d.shape(), ty, d.read_raw::<T>().unwrap())
}

fn ids<const K: usize>(rows: &[[u32; K]]) -> Vec<i64> {
    rows.iter().flatten().map(|&v| v as i64).collect()
}

/// Checks `X.h5` against the mesh (and its mid-edge nodes) and that `X.xdmf` names it.
fn check(xdmf: &Path, m: &TetMesh, q: Option<&QuadraticNodes>) {
    let text = std::fs::read_to_string(xdmf).unwrap();
    let h5 = h5_path(xdmf);
    let name = h5.file_name().unwrap().to_str().unwrap();
    assert!(
        text.contains(&format!(">{name}:/Mesh/mesh/topology<")),
        "{text}"
    );
    assert!(!text.contains(&*h5.parent().unwrap().to_string_lossy()));
    let f = hdf5::File::open(&h5).unwrap();
    let (n, nf) = (m.tets.len(), m.boundary.len());
    let i64t = TypeDescriptor::Integer(IntSize::U8);
    let i32t = TypeDescriptor::Integer(IntSize::U4);

    let (topology, facets, points) = match q {
        None => (ids(&m.tets), ids(&m.boundary), m.vertices.clone()),
        Some(q) => {
            let cat = |a: &[u32], b: &[u32]| -> Vec<i64> {
                a.iter().chain(b).map(|&v| v as i64).collect()
            };
            let t = m.tets.iter().zip(&q.tet_edges).flat_map(|(a, b)| cat(a, b));
            let b = m
                .boundary
                .iter()
                .zip(&q.boundary_edges)
                .flat_map(|(a, b)| cat(a, b));
            let p = m.vertices.iter().chain(&q.points).copied().collect();
            (t.collect(), b.collect(), p)
        }
    };
    let (k, kf) = (topology.len() / n, facets.len() / nf);

    let (shape, ty, t) = read::<i64>(&f, "/Mesh/mesh/topology");
    assert_eq!((shape, ty), (vec![n, k], i64t.clone()));
    assert_eq!(t, topology);
    let (shape, ty, x) = read::<f64>(&f, "/Mesh/mesh/geometry");
    assert_eq!(
        (shape, ty),
        (vec![points.len(), 3], TypeDescriptor::Float(FloatSize::U8))
    );
    let bits: Vec<u64> = points
        .iter()
        .flat_map(|p| [p.x, p.y, p.z])
        .map(f64::to_bits)
        .collect();
    assert_eq!(x.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), bits);

    let (shape, ty, t) = read::<i64>(&f, &format!("/MeshTags/{CELL_TAGS}/topology"));
    assert_eq!((shape, ty, t), (vec![n, k], i64t.clone(), topology));
    let (shape, ty, v) = read::<i32>(&f, &format!("/MeshTags/{CELL_TAGS}/Values"));
    assert_eq!(
        (shape, ty, v),
        (vec![n, 1], i32t.clone(), m.tet_regions.clone())
    );
    let (shape, ty, t) = read::<i64>(&f, &format!("/MeshTags/{FACET_TAGS}/topology"));
    assert_eq!((shape, ty, t), (vec![nf, kf], i64t, facets));
    let (shape, ty, v) = read::<i32>(&f, &format!("/MeshTags/{FACET_TAGS}/Values"));
    assert_eq!(
        (shape, ty, v),
        (vec![nf, 1], i32t, m.boundary_markers.clone())
    );
}

#[test]
fn xdmf_h5_holds_the_mesh_regions_and_markers() {
    let m = sample_mesh(3);
    assert!(m.tet_regions.iter().any(|&r| r < 0) && m.boundary_markers.contains(&-7));
    let dir = TempDir::new("xdmf");
    let p = dir.path("m.xdmf");
    write_mesh(&p, &m, &[]).unwrap_or_else(|e| panic!("{e}"));
    check(&p, &m, None);
    // Written again over itself, and through an upper-case extension.
    write_mesh(&p, &m, &[]).unwrap();
    check(&p, &m, None);
    let p = dir.path("Upper.XDMF");
    write_output(&p, &m, None, &[], true).unwrap();
    assert!(dir.path("Upper.h5").exists());
    check(&p, &m, None);
}

#[test]
fn xdmf_h5_holds_ten_node_tets() {
    let m = sample_mesh(2);
    let q = QuadraticNodes::straight(&m);
    let dir = TempDir::new("xdmf10");
    let p = dir.path("q.xdmf");
    write_output(&p, &m, Some(&q), &[], false).unwrap_or_else(|e| panic!("{e}"));
    check(&p, &m, Some(&q));
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.contains("TopologyType=\"Tetrahedron_10\""));
    assert!(text.contains("TopologyType=\"Triangle_6\""));
    // A mid-edge node sits where QuadraticNodes put it.
    let f = hdf5::File::open(h5_path(&p)).unwrap();
    let x = f
        .dataset("/Mesh/mesh/geometry")
        .unwrap()
        .read_raw::<f64>()
        .unwrap();
    let e = q.tet_edges[0][3] as usize;
    let want = q.position(&m, e as u32);
    assert_eq!(&x[3 * e..3 * e + 3], &[want.x, want.y, want.z]);

    // Inconsistent mid-edge nodes are refused, not written.
    let mut bad = q.clone();
    bad.tet_edges.pop();
    let p = dir.path("bad.xdmf");
    assert!(write_output(&p, &m, Some(&bad), &[], false).is_err());
    assert!(!p.exists() && !h5_path(&p).exists());
}

#[test]
fn xdmf_refuses_a_colon_in_the_file_name() {
    let dir = TempDir::new("xdmfcolon");
    let p = dir.path("a:b.xdmf");
    let e = write_mesh(&p, &sample_mesh(1), &[]).unwrap_err();
    assert!(e.message.contains("':'"), "{e}");
}
