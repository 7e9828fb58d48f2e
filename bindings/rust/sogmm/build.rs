//! Tests and examples of this crate load libsogmm from the folder sogmm-sys
//! linked against (DEP_SOGMM_LIB_DIR, from its `links = "sogmm"` build
//! script), so `cargo test` needs no LD_LIBRARY_PATH. Libraries depending on
//! this crate are unaffected: their binaries find libsogmm as they choose.
fn main() {
    println!("cargo:rerun-if-env-changed=DEP_SOGMM_LIB_DIR");
    if let Ok(dir) = std::env::var("DEP_SOGMM_LIB_DIR") {
        println!("cargo:rustc-link-arg-tests=-Wl,-rpath,{dir}");
        println!("cargo:rustc-link-arg-examples=-Wl,-rpath,{dir}");
    }
}
