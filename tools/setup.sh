#!/usr/bin/env bash
# Installs every dependency of SOGMM from Debian's packages (the library's own
# dependencies) and PyPI (Python tooling for tests, bindings and plots), then
# configures and builds the project into ./build.
#
# Usage: bash tools/setup.sh [--no-build]
# Environment: SOGMM_BUILD_DIR (default build), SOGMM_NATIVE=ON for -march=native.
set -euo pipefail
cd "$(dirname "$0")/.."

SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi

DEBIAN_PACKAGES=(
  build-essential cmake ninja-build pkg-config
  libeigen3-dev                                   # numerical core
  libopencv-core-dev libopencv-imgcodecs-dev libopencv-imgproc-dev  # image I/O (tools only)
  libzstd-dev zstd                                # .sogmm compression
  libpng-dev libjpeg62-turbo-dev                  # frame images: libsogmm decodes PNG/JPEG (format/)
  libflatbuffers-dev flatbuffers-compiler         # .sogmm container + flatc
  libgtest-dev googletest                         # C++ tests
  libnanoflann-dev                                # exact nearest neighbours (metrics)
  libcli11-dev nlohmann-json3-dev                 # CLI parsing, JSON
  liboctomap-dev                                  # optional OctoMap baseline in `sogmm bench`
  clang libclang-rt-14-dev libomp-14-dev          # fuzzing and sanitizers (clang's OpenMP)
  abigail-tools                                   # abidw/abidiff: ABI baseline check (tools/abi, ctest abi_*)
  python3 python3-pip python3-venv
  chromium                                        # headless browser of the viewer test (ctest viewer.browser)
)
# node >= 20 and npm for bindings/js (the JavaScript reader, the viewer); a
# machine's own newer node is kept.
{ command -v node && command -v npm; } >/dev/null || DEBIAN_PACKAGES+=(nodejs npm)
need_install=()
for p in "${DEBIAN_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || need_install+=("$p")
done
if [ ${#need_install[@]} -gt 0 ]; then
  echo "setup: installing Debian packages: ${need_install[*]}" >&2
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${need_install[@]}" >/dev/null
fi

# Python tooling, pinned. Installed into the interpreter that runs the tests.
PYTHON=${PYTHON:-python3}
"$PYTHON" -m pip install -q --disable-pip-version-check \
  -r tools/requirements-dev.txt 2>&1 | grep -v -i 'root user' || true

# Rust and Go bindings (ctest rust_*, go_*, matrix_*): they use the machine's
# cargo (Rust >= 1.70) and go (>= 1.21) when present and skip with a message
# otherwise. Neither fetches anything: the crates and the Go module have no
# dependencies (Cargo.lock lists only the two crates; there is no go.sum).
for tool in cargo go; do
  PATH="$PATH:$HOME/.cargo/bin:/usr/local/go/bin" command -v "$tool" >/dev/null ||
    echo "setup: $tool not found: the ctest $tool-based binding tests will be skipped" >&2
done

# The pinned npm packages of bindings/js (package-lock.json): zstddec, three,
# esbuild, playwright-core. Nothing downloads a browser: the test uses
# Debian's /usr/bin/chromium.
(cd bindings/js && npm ci --no-audit --no-fund --loglevel=error)

if [ "${1:-}" = "--no-build" ]; then exit 0; fi
BUILD_DIR=${SOGMM_BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DSOGMM_NATIVE="${SOGMM_NATIVE:-OFF}" >/dev/null
cmake --build "$BUILD_DIR" --parallel "$(nproc)"
