//! Finds libsogmm and links to it dynamically (-lsogmm, SONAME libsogmm.so.1).
//!
//! Where the library is found, in this order:
//! 1. `SOGMM_LIB_DIR`: a folder holding libsogmm.so (a CMake build's `capi/`
//!    folder, or an install's lib/). This is how ctest builds the crates.
//! 2. `pkg-config --libs-only-L sogmm` (the installed sogmm.pc), if pkg-config
//!    runs; the pkg-config program is called directly, so no crate is needed.
//! 3. Otherwise the linker's default paths.
//!
//! We link rather than dlopen: the C API has a versioned SONAME, so a missing
//! or incompatible library fails at load time with the loader's own message,
//! and no symbol-lookup code (libc or libloading) is needed. The safe crate
//! still checks sogmm_abi_version() at run time.
//!
//! The folder is published to dependents as DEP_SOGMM_LIB_DIR (`links`), so
//! that their build scripts can add an rpath for tests and examples.
use std::env;
use std::process::Command;

fn main() {
    println!("cargo:rerun-if-env-changed=SOGMM_LIB_DIR");
    println!("cargo:rerun-if-env-changed=PKG_CONFIG_PATH");
    let dir = env::var("SOGMM_LIB_DIR")
        .ok()
        .filter(|d| !d.is_empty())
        .or_else(pkg_config_dir);
    if let Some(dir) = &dir {
        println!("cargo:rustc-link-search=native={dir}");
        println!("cargo:lib_dir={dir}");
        // This crate's own tests load the library from there too.
        println!("cargo:rustc-link-arg-tests=-Wl,-rpath,{dir}");
    }
    println!("cargo:rustc-link-lib=dylib=sogmm");
}

/// The first -L folder pkg-config reports for sogmm, if any.
fn pkg_config_dir() -> Option<String> {
    let out = Command::new("pkg-config")
        .args(["--libs-only-L", "sogmm"])
        .output()
        .ok()?;
    if !out.status.success() {
        return None;
    }
    String::from_utf8(out.stdout)
        .ok()?
        .split_whitespace()
        .find_map(|t| t.strip_prefix("-L").map(str::to_owned))
}
