//! Tests across formats: every model in models/ reads, every writer round-trips, and no reader
//! panics on damaged input.

mod fuzz;
mod models;
mod quadratic;
mod roundtrip;
mod surface;
#[cfg(feature = "hdf5")]
mod xdmf;

use std::path::{Path, PathBuf};

/// The test models, kept in the repository (`models/`, see its README).
pub(crate) fn models_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("models")
}

/// A model file by its path under the models directory (e.g. `poly/cube.poly`).
pub(crate) fn model(rel: &str) -> PathBuf {
    models_dir().join(rel)
}

/// All files with extension `ext` in a models subdirectory, sorted.
pub(crate) fn models_in(sub: &str, ext: &str) -> Vec<PathBuf> {
    let dir = models_dir().join(sub);
    let mut out: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().and_then(|e| e.to_str()) == Some(ext))
        .collect();
    out.sort();
    out
}

/// A fresh empty directory under the system temp dir, removed when dropped.
pub(crate) struct TempDir(pub PathBuf);

impl TempDir {
    pub(crate) fn new(tag: &str) -> Self {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static COUNTER: AtomicUsize = AtomicUsize::new(0);
        let n = COUNTER.fetch_add(1, Ordering::Relaxed);
        let dir =
            std::env::temp_dir().join(format!("slivermesh-io-{tag}-{}-{n}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    pub(crate) fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}
