#!/usr/bin/env bash
# ctest consumer_rust: a Rust program in a folder outside the repository,
# depending on the `sogmm` crate by path with the `static` feature, built
# against this build's libsogmm.a and run with no environment variables.
# The build itself runs clean too: the library folder is passed as cargo
# configuration, and the target folder is the one rust_cargo_test uses, so the
# crates are not compiled twice. Offline: the crates need nothing from a registry.
# Usage: consumer_rust.sh <build> <source> <cargo> <cargo-target-dir>
. "$(dirname "$0")/common.sh"
cargo=$3 target=$4
if [ ! -x "$cargo" ]; then
  echo "SKIP: cargo not found (install it to run consumer_rust)"; exit 77
fi
cp -r "$SRC/tests/consumers/rust" "$work/src"
sed -i "s|\"../../../bindings/rust/sogmm\"|\"$SRC/bindings/rust/sogmm\"|" "$work/src/Cargo.toml"
tools "$cargo" build --offline --quiet --manifest-path "$work/src/Cargo.toml" --target-dir "$target" \
  --config "env.SOGMM_LIB_DIR='$BUILD/capi'"
check_runs "$target/debug/sogmm-consumer" static
