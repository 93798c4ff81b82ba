//! Ten-node tets in every output format, read back by other programs: the files of
//! examples/p2_sample.rs (a 3x3x3 block of straight-sided tets, 3 regions, 6 boundary markers)
//! go to ctests/p2_readback.py, which reads them with meshio, the gmsh Python module and (to
//! check TetGen's -o2 node order) the tetgen binary, each where installed. Without python3 and
//! meshio the check is skipped with a note on stderr; the writers' own unit tests are in
//! src/io/tests/quadratic.rs.

mod common;

#[path = "../examples/p2_sample.rs"]
mod p2_sample;

use std::process::Command;

fn python_has_meshio() -> bool {
    Command::new("python3")
        .args(["-c", "import meshio, numpy"])
        .output()
        .is_ok_and(|o| o.status.success())
}

#[test]
fn other_readers_read_the_ten_node_files() {
    let dir = common::ScratchDir::new("p2", "writers");
    let mesh = p2_sample::block(3);
    let counts = p2_sample::write_sample(&dir.0, &mesh);
    assert!(counts.contains("\"tets\": 162"), "{counts}");
    if !python_has_meshio() {
        eprintln!("python3 cannot import meshio and numpy: the readback check is skipped");
        return;
    }
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("ctests/p2_readback.py");
    let out = Command::new("python3")
        .arg(&script)
        .arg(&dir.0)
        .output()
        .expect("running python3");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    eprintln!("{text}");
    assert!(out.status.success(), "p2_readback.py failed:\n{text}");
    assert!(!text.contains("FAIL"), "{text}");
}
