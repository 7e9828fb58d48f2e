//! Finds libsogmm and links to it: dynamically by default (-lsogmm, SONAME
//! libsogmm.so.2), statically with the `static` feature (libsogmm.a).
//!
//! Where the library is found, in this order:
//! 1. `SOGMM_LIB_DIR`: a folder holding libsogmm.so and libsogmm.a (a CMake
//!    build's `capi/` folder, or an install's lib/). This is how ctest builds
//!    the crates.
//! 2. `pkg-config --libs-only-L sogmm` (the installed sogmm.pc), if pkg-config
//!    runs; the pkg-config program is called directly, so no crate is needed.
//! 3. The `build/capi` folder of the checkout holding this crate (a path or git
//!    dependency on a tree built as the top-level README says), if it exists.
//! 4. Otherwise the linker's default paths.
//!
//! Dynamic: we link rather than dlopen, since the C API has a versioned
//! SONAME, so a missing or incompatible library fails at load time with the
//! loader's own message, and no symbol-lookup code is needed. The safe crate
//! still checks sogmm_abi_version() at run time. Cargo gives a dependency no
//! way to set its dependents' rpath, so their programs find libsogmm.so as the
//! system's loader does (an installed prefix, or their own rpath).
//!
//! Static: libsogmm.a holds the library, its C++ core and zstd, with only
//! sogmm_* global (capi/cmake/static_archive.cmake); it needs the C++ runtime
//! and OpenMP, which every Linux system has in its default paths. A program
//! then runs with nothing to find at load time.
//!
//! The folder is published to dependents as DEP_SOGMM_LIB_DIR (`links`), so
//! that their build scripts can add an rpath for tests and examples.
use std::env;
use std::path::Path;
use std::process::Command;

fn main() {
    println!("cargo:rerun-if-env-changed=SOGMM_LIB_DIR");
    println!("cargo:rerun-if-env-changed=PKG_CONFIG_PATH");
    let statically = env::var_os("CARGO_FEATURE_STATIC").is_some();
    let dir = env::var("SOGMM_LIB_DIR")
        .ok()
        .filter(|d| !d.is_empty())
        .or_else(pkg_config_dir)
        .or_else(checkout_build_dir);
    if let Some(dir) = &dir {
        println!("cargo:rustc-link-search=native={dir}");
        println!("cargo:lib_dir={dir}");
        // This crate's own tests load the library from there too.
        println!("cargo:rustc-link-arg-tests=-Wl,-rpath,{dir}");
        if statically {
            // A rebuilt archive must be linked again.
            println!("cargo:rerun-if-changed={dir}/libsogmm.a");
        }
    }
    if statically {
        println!("cargo:rustc-link-lib=static=sogmm");
        println!("cargo:rustc-link-lib=dylib=stdc++");
        println!("cargo:rustc-link-lib=dylib=gomp");
        // The library's image decoders (sogmm_frame_read): the system's
        // libpng and libjpeg, shared (Debian's static ones are not PIC).
        println!("cargo:rustc-link-lib=dylib=png16");
        println!("cargo:rustc-link-lib=dylib=jpeg");
    } else {
        println!("cargo:rustc-link-lib=dylib=sogmm");
    }
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

/// `<checkout>/build/capi`, this crate being `<checkout>/bindings/rust/sogmm-sys`.
fn checkout_build_dir() -> Option<String> {
    let manifest = env::var("CARGO_MANIFEST_DIR").ok()?;
    let dir = Path::new(&manifest).join("../../../build/capi").canonicalize().ok()?;
    dir.is_dir().then(|| dir.to_string_lossy().into_owned())
}
