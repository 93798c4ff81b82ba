//! include/slivermesh.h must be what cbindgen makes of src/ffi today.
//!
//! The header is generated from the listed files only (not the whole crate), so a `pub const`
//! elsewhere in the crate never leaks into it and the order of the header follows this list.

use std::path::{Path, PathBuf};

/// The files that declare C items, in header order.
const HEADER_SOURCES: &[&str] = &[
    "status.rs",
    "callbacks.rs",
    "mesher.rs",
    "input.rs",
    "settings.rs",
    "run.rs",
    "mpi.rs",
    "output.rs",
    "quality.rs",
];

/// The files of src/ffi without C items.
const NOT_IN_HEADER: &[&str] = &["mod.rs", "guard.rs", "slices.rs", "header.rs", "tests.rs"];

const HOW: &str =
    "regenerate it with `SLIVERMESH_BLESS=1 cargo test --lib ffi::header` and commit it";

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Generates the header text from src/ffi with cbindgen.toml.
pub(crate) fn generate() -> String {
    let root = root();
    let config = cbindgen::Config::from_file(root.join("cbindgen.toml"))
        .unwrap_or_else(|e| panic!("cbindgen.toml: {e}"));
    let mut builder = cbindgen::Builder::new().with_config(config);
    for f in HEADER_SOURCES {
        builder = builder.with_src(root.join("src/ffi").join(f));
    }
    let mut out = Vec::new();
    builder
        .generate()
        .unwrap_or_else(|e| panic!("cbindgen failed: {e}"))
        .write(&mut out);
    String::from_utf8(out).expect("cbindgen wrote UTF-8")
}

#[test]
fn every_ffi_file_is_classified() {
    let dir = root().join("src/ffi");
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name().into_string().unwrap();
        assert!(
            HEADER_SOURCES.contains(&name.as_str()) || NOT_IN_HEADER.contains(&name.as_str()),
            "src/ffi/{name} is in neither HEADER_SOURCES nor NOT_IN_HEADER (src/ffi/header.rs)"
        );
    }
}

#[test]
fn header_is_current() {
    let path = root().join("include/slivermesh.h");
    let fresh = generate();
    if std::env::var_os("SLIVERMESH_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &fresh).unwrap();
        eprintln!("wrote {}", path.display());
        return;
    }
    let current = std::fs::read_to_string(&path).unwrap_or_default();
    if current != fresh {
        let line = current
            .lines()
            .zip(fresh.lines())
            .position(|(a, b)| a != b)
            .map_or(current.lines().count().min(fresh.lines().count()), |i| i)
            + 1;
        panic!(
            "{} is stale (first difference at line {line}): {HOW}",
            display(&path)
        );
    }
}

fn display(p: &Path) -> String {
    p.strip_prefix(root()).unwrap_or(p).display().to_string()
}

#[test]
fn header_declares_the_whole_contract() {
    let flat = generate().split_whitespace().collect::<Vec<_>>().join(" ");
    for decl in [
        "typedef struct sm_mesher sm_mesher;",
        "typedef int32_t sm_status;",
        "sm_mesher *sm_create(void);",
        "void sm_destroy(sm_mesher *m);",
        "sm_status sm_add_vertices(sm_mesher *m, const double *xyz, size_t n);",
        "sm_status sm_add_facet(sm_mesher *m, const uint32_t *ids, size_t n, int32_t marker);",
        "sm_status sm_add_facet_hole(sm_mesher *m, const uint32_t *ids, size_t n);",
        "sm_status sm_add_hole(sm_mesher *m, double x, double y, double z);",
        "typedef double (*sm_spacing_fn)(double x, double y, double z, void *user_data);",
        "sm_status sm_set_spacing_cb(sm_mesher *m, sm_spacing_fn f, void *user_data);",
        "typedef void (*sm_spacing_batch_fn)(size_t n, const double *xyz, double *out, void *user_data);",
        "sm_status sm_set_spacing_batch_cb(sm_mesher *m, sm_spacing_batch_fn f, void *user_data);",
        "sm_status sm_set_spacing_const(sm_mesher *m, double h);",
        "sm_status sm_set_param(sm_mesher *m, const char *name, double value);",
        "typedef int32_t (*sm_progress_fn)(double fraction, size_t n_vertices, void *user_data);",
        "sm_status sm_set_progress_cb(sm_mesher *m, sm_progress_fn f, void *user_data);",
        "sm_status sm_refine(sm_mesher *m);",
        "size_t sm_num_vertices(const sm_mesher *m);",
        "size_t sm_num_tets(const sm_mesher *m);",
        "size_t sm_num_boundary_faces(const sm_mesher *m);",
        "sm_status sm_get_vertices(const sm_mesher *m, double *xyz, size_t capacity);",
        "sm_status sm_get_quality(const sm_mesher *m, sm_quality *out);",
        "sm_status sm_write(const sm_mesher *m, const char *path);",
        "const char *sm_last_error(const sm_mesher *m);",
        "const char *sm_status_str(sm_status s);",
        "const char *sm_version(void);",
        "#define SM_OK 0",
        "#define SM_ERR_INTERNAL 11",
        "sm_status sm_add_region(sm_mesher *m, double x, double y, double z, int32_t attribute, double max_size);",
        "sm_status sm_get_tets(const sm_mesher *m, uint32_t *tets, int32_t *regions, size_t capacity);",
        "sm_status sm_get_boundary_faces(const sm_mesher *m, uint32_t *tris, int32_t *markers, size_t capacity);",
    ] {
        assert!(flat.contains(decl), "header lacks `{decl}`");
    }
}
