//! What `--region-size` and `--marker-size` share in their tests: running the binary, and the
//! errors for an ID the input does not have and for malformed values.

use std::process::{Command, Output};

/// Runs the `slivermesh` binary with `args`.
pub fn run(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_slivermesh"))
        .args(args)
        .output()
        .unwrap()
}

/// `option` (`--region-size` or `--marker-size`) with an ID two_materials.poly does not have
/// fails in both surface modes naming it as `noun` ("region", "marker") and listing the input's
/// IDs; malformed or non-positive values are refused naming the option.
pub fn check_unknown_ids_and_bad_values(option: &str, noun: &str) {
    let input = super::models_dir().join("poly/two_materials.poly");
    let input = input.to_str().unwrap();
    let out = std::env::temp_dir().join(format!(
        "slivermesh{option}-err-{}.mesh",
        std::process::id()
    ));
    let out = out.to_str().unwrap();
    for mode in ["keep", "approximate"] {
        let o = run(&["mesh", input, "-o", out, "--surface", mode, option, "7:0.1"]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert!(
            err.contains(&format!("{noun} 7")) && err.contains(&format!("its {noun}s: 1, 2")),
            "{mode}: {err}"
        );
    }
    for bad in ["2:0", "2:-1", "2:inf", "2:nan", "2", "x:1"] {
        let o = run(&["mesh", input, "-o", out, option, bad]);
        let err = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success());
        assert!(err.contains(option), "{bad}: {err}");
    }
}
