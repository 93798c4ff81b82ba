//! XDMF 3 + HDF5 writer (`X.xdmf` with its arrays in `X.h5` beside it), laid out as DOLFINx's
//! `XDMFFile.write_mesh` followed by two `write_meshtags` calls writes it, so that
//! `XDMFFile.read_mesh(name="mesh")` and `read_meshtags(mesh, name=...)` read it back.
//!
//! Written (`N` tets, `M` nodes, `F` boundary triangles; `k` = 4 and `f` = 3, or 10 and 6 for
//! ten-node tets):
//!
//! | Grid `Name` | XDMF | HDF5 dataset (type, shape) |
//! |---|---|---|
//! | [`MESH`] | Topology `Tetrahedron` / `Tetrahedron_10` | `/Mesh/mesh/topology` (Int64, N×k) |
//! | | Geometry `XYZ` | `/Mesh/mesh/geometry` (Float64, M×3) |
//! | [`CELL_TAGS`] | Topology as the mesh's | `/MeshTags/mesh_cells/topology` (hard link to `/Mesh/mesh/topology`) |
//! | | Attribute `mesh_cells`, Center `Cell` | `/MeshTags/mesh_cells/Values` (Int32, N×1): region attribute |
//! | [`FACET_TAGS`] | Topology `Triangle` / `Triangle_6` | `/MeshTags/mesh_facets/topology` (Int64, F×f) |
//! | | Attribute `mesh_facets`, Center `Cell` | `/MeshTags/mesh_facets/Values` (Int32, F×1): boundary marker |
//!
//! The names are those of DOLFINx's gmsh demo (`{mesh.name}_cells`, `{mesh.name}_facets`); the
//! HDF5 paths, the `<!DOCTYPE>`, `Version="3.0"`, the `xmlns:xi` declaration and the
//! `xi:include` of the mesh's Geometry in each tag grid are what DOLFINx writes. Beyond
//! DOLFINx, every DataItem states its `NumberType` and `Precision` (DOLFINx gives only the
//! topology's `NumberType`; its reader ignores both, while for other XDMF readers a DataItem
//! without them holds 4-byte floats). A tag grid
//! is left out when it would be empty (DOLFINx's reader rejects empty datasets).
//!
//! Node order: VTK's, as DOLFINx reads XDMF: a tet's corners, then for ten-node tets its
//! mid-edge nodes on edges 01, 12, 02, 03, 13, 23 ([`QuadraticNodes::tet_edges`]); a
//! triangle's corners, then its nodes on edges 01, 12, 20 ([`QuadraticNodes::boundary_edges`]).
//! Geometry: the corner vertices in mesh order, then the mid-edge nodes (node id
//! `vertices.len() + k`), so node ids are the mesh's own. DOLFINx reads the facet tags of a
//! second-order mesh as `Triangle_6`, which is what it writes for them.
//!
//! The XDMF names the HDF5 file by its file name only (DOLFINx itself opens `X.h5` beside
//! `X.xdmf`, whatever the XDMF says). The arrays need the cargo feature `hdf5` (the system's
//! libhdf5); without it [`write_xdmf`] fails with an error saying so.

use super::IoError;
use crate::mesh::{QuadraticNodes, TetMesh};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The mesh Grid's name (DOLFINx's default `name` of `read_mesh`).
pub const MESH: &str = "mesh";
/// The cell tags' Grid (and Attribute) name: each tet's region attribute.
pub const CELL_TAGS: &str = "mesh_cells";
/// The facet tags' Grid (and Attribute) name: each boundary triangle's marker.
pub const FACET_TAGS: &str = "mesh_facets";

/// True where this build can write `.xdmf` (the cargo feature `hdf5`).
pub const SUPPORTED: bool = cfg!(feature = "hdf5");

/// The message of the error [`write_xdmf`] returns in a build without the feature.
pub const UNSUPPORTED: &str = "built without HDF5 support; rebuild with --features hdf5";

/// The HDF5 file that goes with an XDMF file: the same path with extension `.h5`, where
/// DOLFINx looks for it.
pub fn h5_path(xdmf: &Path) -> PathBuf {
    xdmf.with_extension("h5")
}

/// Everything written, as flat row-major arrays.
#[derive(Debug)]
struct Arrays {
    /// Nodes per tet (4 or 10) and per boundary triangle (3 or 6).
    cell_nodes: usize,
    facet_nodes: usize,
    /// `tets × cell_nodes` node ids.
    topology: Vec<i64>,
    /// `nodes × 3` coordinates.
    geometry: Vec<f64>,
    /// `boundary × facet_nodes` node ids.
    facets: Vec<i64>,
    /// Region per tet and marker per boundary triangle (read by the HDF5 writer alone).
    #[cfg_attr(not(feature = "hdf5"), allow(dead_code))]
    regions: Vec<i32>,
    #[cfg_attr(not(feature = "hdf5"), allow(dead_code))]
    markers: Vec<i32>,
}

impl Arrays {
    fn n_cells(&self) -> usize {
        self.topology.len() / self.cell_nodes
    }
    fn n_nodes(&self) -> usize {
        self.geometry.len() / 3
    }
    fn n_facets(&self) -> usize {
        self.facets.len() / self.facet_nodes
    }
}

/// The arrays of a checked mesh (`text::check_mesh`) and, for ten-node tets, its mid-edge
/// nodes, whose consistency with the mesh is checked here.
fn arrays(mesh: &TetMesh, quadratic: Option<&QuadraticNodes>) -> Result<Arrays, String> {
    let nv = mesh.vertices.len();
    let mut geometry = Vec::with_capacity(3 * nv);
    for p in &mesh.vertices {
        geometry.extend([p.x, p.y, p.z]);
    }
    let Some(q) = quadratic else {
        return Ok(Arrays {
            cell_nodes: 4,
            facet_nodes: 3,
            topology: mesh.tets.iter().flatten().map(|&v| v as i64).collect(),
            geometry,
            facets: mesh.boundary.iter().flatten().map(|&v| v as i64).collect(),
            regions: mesh.tet_regions.clone(),
            markers: mesh.boundary_markers.clone(),
        });
    };
    if q.tet_edges.len() != mesh.tets.len() || q.boundary_edges.len() != mesh.boundary.len() {
        return Err(format!(
            "mid-edge nodes for {} tets and {} boundary triangles, but the mesh has {} and {}",
            q.tet_edges.len(),
            q.boundary_edges.len(),
            mesh.tets.len(),
            mesh.boundary.len()
        ));
    }
    let n_nodes = nv + q.points.len();
    if u32::try_from(n_nodes).is_err() {
        return Err(format!("{n_nodes} nodes exceed the 32-bit id range"));
    }
    let beyond = |ids: &[u32]| ids.iter().any(|&v| v as usize >= n_nodes);
    if let Some(i) = q.tet_edges.iter().position(|e| beyond(e)) {
        return Err(format!(
            "tet {i}'s mid-edge nodes {:?} go beyond the {n_nodes} nodes",
            q.tet_edges[i]
        ));
    }
    if let Some(i) = q.boundary_edges.iter().position(|e| beyond(e)) {
        return Err(format!(
            "boundary triangle {i}'s mid-edge nodes {:?} go beyond the {n_nodes} nodes",
            q.boundary_edges[i]
        ));
    }
    geometry.reserve(3 * q.points.len());
    for p in &q.points {
        geometry.extend([p.x, p.y, p.z]);
    }
    let mut topology = Vec::with_capacity(10 * mesh.tets.len());
    for (t, e) in mesh.tets.iter().zip(&q.tet_edges) {
        topology.extend(t.iter().chain(e).map(|&v| v as i64));
    }
    let mut facets = Vec::with_capacity(6 * mesh.boundary.len());
    for (t, e) in mesh.boundary.iter().zip(&q.boundary_edges) {
        facets.extend(t.iter().chain(e).map(|&v| v as i64));
    }
    Ok(Arrays {
        cell_nodes: 10,
        facet_nodes: 6,
        topology,
        geometry,
        facets,
        regions: mesh.tet_regions.clone(),
        markers: mesh.boundary_markers.clone(),
    })
}

/// XML-escapes text and attribute values.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c => out.push(c),
        }
    }
    out
}

/// One `<DataItem>` of an HDF5 dataset.
fn data_item(x: &mut String, indent: &str, h5: &str, dims: [usize; 2], ty: (&str, u8), at: &str) {
    let _ = writeln!(
        x,
        "{indent}<DataItem Dimensions=\"{} {}\" NumberType=\"{}\" Precision=\"{}\" \
         Format=\"HDF\">{h5}:{at}</DataItem>",
        dims[0], dims[1], ty.0, ty.1
    );
}

const INT64: (&str, u8) = ("Int", 8);
const INT32: (&str, u8) = ("Int", 4);
const FLOAT64: (&str, u8) = ("Float", 8);

/// The `<Topology>` element of `n` entities of `nodes` nodes each.
fn topology(x: &mut String, h5: &str, kind: &str, n: usize, nodes: usize, at: &str) {
    let _ = writeln!(
        x,
        "      <Topology TopologyType=\"{kind}\" NumberOfElements=\"{n}\" \
         NodesPerElement=\"{nodes}\">"
    );
    data_item(x, "        ", h5, [n, nodes], INT64, at);
    x.push_str("      </Topology>\n");
}

/// A tag Grid: the mesh's Geometry by reference, a Topology and the values as a cell Attribute.
fn tags_grid(x: &mut String, h5: &str, name: &str, kind: &str, n: usize, nodes: usize) {
    let _ = writeln!(x, "    <Grid Name=\"{name}\" GridType=\"Uniform\">");
    let _ = writeln!(
        x,
        "      <xi:include xpointer=\"xpointer(/Xdmf/Domain/Grid[@Name='{MESH}']/Geometry)\" />"
    );
    topology(x, h5, kind, n, nodes, &format!("/MeshTags/{name}/topology"));
    let _ = writeln!(
        x,
        "      <Attribute Name=\"{name}\" AttributeType=\"Scalar\" Center=\"Cell\">"
    );
    data_item(
        x,
        "        ",
        h5,
        [n, 1],
        INT32,
        &format!("/MeshTags/{name}/Values"),
    );
    x.push_str("      </Attribute>\n");
    x.push_str("    </Grid>\n");
}

/// The XDMF document for `a`, its DataItems naming the HDF5 file `h5_name`.
fn xdmf_text(h5_name: &str, a: &Arrays) -> String {
    let h5 = escape(h5_name);
    let (cell, facet) = if a.cell_nodes == 10 {
        ("Tetrahedron_10", "Triangle_6")
    } else {
        ("Tetrahedron", "Triangle")
    };
    let mut x = String::new();
    x.push_str("<?xml version=\"1.0\"?>\n");
    x.push_str("<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n");
    // DOLFINx's namespace string, kept as DOLFINx writes it.
    x.push_str("<Xdmf Version=\"3.0\" xmlns:xi=\"https://www.w3.org/2001/XInclude\">\n");
    x.push_str("  <Domain>\n");
    let _ = writeln!(x, "    <Grid Name=\"{MESH}\" GridType=\"Uniform\">");
    let (n, k) = (a.n_cells(), a.cell_nodes);
    topology(&mut x, &h5, cell, n, k, "/Mesh/mesh/topology");
    x.push_str("      <Geometry GeometryType=\"XYZ\">\n");
    data_item(
        &mut x,
        "        ",
        &h5,
        [a.n_nodes(), 3],
        FLOAT64,
        "/Mesh/mesh/geometry",
    );
    x.push_str("      </Geometry>\n");
    x.push_str("    </Grid>\n");
    if n > 0 {
        tags_grid(&mut x, &h5, CELL_TAGS, cell, n, k);
    }
    if a.n_facets() > 0 {
        tags_grid(&mut x, &h5, FACET_TAGS, facet, a.n_facets(), a.facet_nodes);
    }
    x.push_str("  </Domain>\n");
    x.push_str("</Xdmf>\n");
    x
}

fn err(path: &Path, message: impl Into<String>) -> IoError {
    IoError {
        path: path.display().to_string(),
        line: None,
        message: message.into(),
    }
}

/// Writes `mesh` (of ten-node tets when `quadratic` is given) as `path` (`X.xdmf`) and
/// [`h5_path`] (`X.h5`). `mesh` must be consistent (`io::write_mesh` checks it first).
///
/// Fails without writing anything in a build without the `hdf5` feature, and for a file name
/// that is not UTF-8 or holds a `:` (DOLFINx splits `file:dataset` at every `:`).
pub fn write_xdmf(
    path: &Path,
    mesh: &TetMesh,
    quadratic: Option<&QuadraticNodes>,
) -> Result<(), IoError> {
    if !SUPPORTED {
        return Err(err(path, UNSUPPORTED));
    }
    let h5 = h5_path(path);
    let h5_name = match h5.file_name().and_then(|n| n.to_str()) {
        Some(n) if !n.contains(':') => n.to_string(),
        _ => {
            return Err(err(
                path,
                "the file name must be UTF-8 without ':' (XDMF names its HDF5 file as \
                 'file:dataset')",
            ))
        }
    };
    let a = arrays(mesh, quadratic).map_err(|m| err(path, format!("cannot write: {m}")))?;
    write_h5(&h5, &a)?;
    std::fs::write(path, xdmf_text(&h5_name, &a))
        .map_err(|e| err(path, format!("cannot write file: {e}")))
}

#[cfg(feature = "hdf5")]
fn write_h5(h5: &Path, a: &Arrays) -> Result<(), IoError> {
    use hdf5::H5Type;
    fn dataset<T: H5Type>(
        g: &hdf5::Group,
        name: &str,
        data: &[T],
        dims: [usize; 2],
    ) -> hdf5::Result<()> {
        g.new_dataset::<T>()
            .shape(dims)
            .create(name)?
            .write_raw(data)
    }
    let write = || -> hdf5::Result<()> {
        let file = hdf5::File::create(h5)?;
        let mesh = file.create_group("Mesh")?.create_group(MESH)?;
        let (n, k) = (a.n_cells(), a.cell_nodes);
        dataset(&mesh, "topology", &a.topology, [n, k])?;
        dataset(&mesh, "geometry", &a.geometry, [a.n_nodes(), 3])?;
        let tags = file.create_group("MeshTags")?;
        if n > 0 {
            let cells = tags.create_group(CELL_TAGS)?;
            // The same array as the mesh's topology: one dataset under both of DOLFINx's paths.
            file.link_hard(
                &format!("/Mesh/{MESH}/topology"),
                &format!("/MeshTags/{CELL_TAGS}/topology"),
            )?;
            dataset(&cells, "Values", &a.regions, [n, 1])?;
        }
        let f = a.n_facets();
        if f > 0 {
            let facets = tags.create_group(FACET_TAGS)?;
            dataset(&facets, "topology", &a.facets, [f, a.facet_nodes])?;
            dataset(&facets, "Values", &a.markers, [f, 1])?;
        }
        file.close()
    };
    write().map_err(|e| err(h5, format!("cannot write HDF5 file: {e}")))
}

#[cfg(not(feature = "hdf5"))]
fn write_h5(h5: &Path, _: &Arrays) -> Result<(), IoError> {
    Err(err(h5, UNSUPPORTED))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn two_tets() -> TetMesh {
        TetMesh {
            vertices: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.0, 0.0, 1.0),
                DVec3::new(1.0, 1.0, 1.0),
            ],
            tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]],
            tet_regions: vec![3, -1],
            boundary: vec![[0, 2, 1]],
            boundary_markers: vec![9],
        }
    }

    /// (Name, TopologyType, NodesPerElement, the Topology's DataItem text) of each Grid.
    fn grids(text: &str) -> Vec<(String, String, String, String)> {
        let doc = roxmltree::Document::parse_with_options(
            text,
            roxmltree::ParsingOptions {
                allow_dtd: true,
                ..Default::default()
            },
        )
        .unwrap();
        let root = doc.root_element();
        assert_eq!(root.tag_name().name(), "Xdmf");
        assert_eq!(root.attribute("Version"), Some("3.0"));
        let domain = root.first_element_child().unwrap();
        domain
            .children()
            .filter(|n| n.has_tag_name("Grid"))
            .map(|g| {
                let t = g.children().find(|n| n.has_tag_name("Topology")).unwrap();
                let d = t.first_element_child().unwrap();
                (
                    g.attribute("Name").unwrap().to_string(),
                    t.attribute("TopologyType").unwrap().to_string(),
                    t.attribute("NodesPerElement").unwrap().to_string(),
                    d.text().unwrap().to_string(),
                )
            })
            .collect()
    }

    #[test]
    fn layout_follows_dolfinx() {
        let m = two_tets();
        let a = arrays(&m, None).unwrap();
        let text = xdmf_text("a&b.h5", &a);
        let g = grids(&text);
        let names: Vec<&str> = g.iter().map(|g| g.0.as_str()).collect();
        assert_eq!(names, [MESH, CELL_TAGS, FACET_TAGS]);
        assert_eq!(g[0].1, "Tetrahedron");
        assert_eq!(g[0].3, "a&b.h5:/Mesh/mesh/topology");
        assert_eq!(g[1].1, "Tetrahedron");
        assert_eq!(g[1].3, "a&b.h5:/MeshTags/mesh_cells/topology");
        assert_eq!((g[2].1.as_str(), g[2].2.as_str()), ("Triangle", "3"));
        assert!(text.contains("<Geometry GeometryType=\"XYZ\">"));
        assert!(text.contains("Dimensions=\"5 3\" NumberType=\"Float\" Precision=\"8\""));
        assert!(text.contains("xpointer=\"xpointer(/Xdmf/Domain/Grid[@Name='mesh']/Geometry)\""));
        assert_eq!(a.topology, [0, 1, 2, 3, 1, 2, 3, 4]);
        assert_eq!(a.facets, [0, 2, 1]);

        // No boundary triangles: no facet grid.
        let bare = TetMesh {
            boundary: vec![],
            boundary_markers: vec![],
            ..m
        };
        let g = grids(&xdmf_text("x.h5", &arrays(&bare, None).unwrap()));
        assert_eq!(g.len(), 2);
    }

    #[test]
    fn ten_node_layout_appends_mid_edge_nodes() {
        let m = two_tets();
        let q = QuadraticNodes::straight(&m);
        let a = arrays(&m, Some(&q)).unwrap();
        assert_eq!(a.n_nodes(), 5 + q.points.len());
        assert_eq!(&a.topology[..4], &[0, 1, 2, 3]);
        assert_eq!(a.topology[4..10], q.tet_edges[0].map(|v| v as i64));
        assert_eq!(a.facets.len(), 6);
        let g = grids(&xdmf_text("x.h5", &a));
        assert_eq!((g[0].1.as_str(), g[0].2.as_str()), ("Tetrahedron_10", "10"));
        assert_eq!((g[1].1.as_str(), g[1].2.as_str()), ("Tetrahedron_10", "10"));
        assert_eq!((g[2].1.as_str(), g[2].2.as_str()), ("Triangle_6", "6"));

        let mut bad = q.clone();
        bad.tet_edges.pop();
        assert!(arrays(&m, Some(&bad)).is_err());
        let mut bad = q;
        bad.boundary_edges[0][1] = 1000;
        assert!(arrays(&m, Some(&bad)).unwrap_err().contains("beyond"));
    }

    #[cfg(not(feature = "hdf5"))]
    #[test]
    fn without_the_feature_says_how_to_get_it() {
        let dir = crate::io::tests::TempDir::new("xdmf-off");
        let p = dir.path("m.xdmf");
        let e = crate::io::write_mesh(&p, &two_tets(), &[]).unwrap_err();
        assert!(e.message.contains("--features hdf5"), "{e}");
        assert!(!p.exists() && !h5_path(&p).exists());
    }
}
