//! Gives the shared library a SONAME that changes exactly when the ABI may break: for 0.x
//! releases libslivermesh.so.0.MINOR (a minor release may break it), from 1.0 on
//! libslivermesh.so.MAJOR. scripts/install.sh installs libslivermesh.so.MAJOR.MINOR.PATCH with
//! the SONAME and the unversioned name as symlinks to it.

fn soname(major: &str, minor: &str) -> String {
    if major == "0" {
        format!("libslivermesh.so.0.{minor}")
    } else {
        format!("libslivermesh.so.{major}")
    }
}

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    // Linux (ELF with GNU-compatible linkers) only: other targets keep cargo's defaults.
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() != Ok("linux") {
        return;
    }
    let major = std::env::var("CARGO_PKG_VERSION_MAJOR").expect("cargo sets the version");
    let minor = std::env::var("CARGO_PKG_VERSION_MINOR").expect("cargo sets the version");
    println!(
        "cargo:rustc-cdylib-link-arg=-Wl,-soname,{}",
        soname(&major, &minor)
    );
}
