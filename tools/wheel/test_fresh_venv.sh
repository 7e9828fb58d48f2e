#!/usr/bin/env bash
# ctest wheel_fresh_venv: the repaired wheel installs and works on a clean
# machine. Builds the manylinux wheel around the Release build's libsogmm
# (build_wheel.sh --lib: no second compile), installs it with the extras of the
# README's example (progress, examples) and the pinned numpy, tqdm and Pillow
# from PyPI into a fresh venv outside the checkout, plus the Ray application's
# wheel without its dependencies (no Ray), then runs smoke_test.py and
# ray_package_check.py in an emptied environment (no build folder on PATH,
# LD_LIBRARY_PATH or PYTHONPATH, no SOGMM_LIBRARY_PATH, cwd outside the
# checkout): ldd finds libgomp inside the wheel (sogmm.libs/), the core wheel
# holds no Ray application and `python -m sogmm_ray` without Ray is one line.
# Exits 77 (skipped) only when PyPI cannot be reached.
#
# Usage: bash tools/wheel/test_fresh_venv.sh LIBSOGMM OUT_DIR
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
lib=$1 out=$2
PYTHON=${PYTHON:-python3}

# numpy, and tqdm and Pillow of the extras: the versions pinned for the project's tooling.
numpy_pin=$(grep -E '^numpy==' "$root/tools/requirements-dev.txt")
pins=$(grep -oE '^(numpy|tqdm|pillow)==[^ ]+' "$root/tools/requirements-dev.txt")
index=${PIP_INDEX_URL:-https://pypi.org/simple}
if ! "$PYTHON" - "$index/numpy/" 2>/dev/null <<'PY'
import sys, urllib.request
urllib.request.urlopen(sys.argv[1], timeout=20).read(1)
PY
then
  echo "SKIP: $index is unreachable (the test installs $numpy_pin from it)"
  exit 77
fi

SECONDS=0
bash "$here/build_wheel.sh" --lib "$lib" --out "$out"
echo "time: wheel build + repair ${SECONDS}s"
wheel=$(ls "$out"/sogmm-*-manylinux_*.whl)
ray_wheel=$(ls "$out"/sogmm_ray-*.whl)

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# The venv's own pip (ensurepip), no system site-packages.
"$PYTHON" -m venv "$tmp/venv"
vpy="$tmp/venv/bin/python"
echo "$pins" >"$tmp/constraints.txt"
"$vpy" -m pip install -q --disable-pip-version-check --only-binary=:all: -c "$tmp/constraints.txt" \
  "$wheel[progress,examples]"
"$vpy" -m pip install -q --disable-pip-version-check --no-deps "$ray_wheel"
echo "time: + venv and install ${SECONDS}s"

mkdir "$tmp/run"
cp "$here/smoke_test.py" "$here/ray_package_check.py" "$tmp/run/"
cd "$tmp/run"
env -i PATH=/usr/bin:/bin HOME="$tmp" LANG=C.UTF-8 OMP_NUM_THREADS=2 \
  "$vpy" -I smoke_test.py "$tmp/venv" "$root"
env -i PATH=/usr/bin:/bin HOME="$tmp" LANG=C.UTF-8 "$vpy" -I ray_package_check.py
echo "time: + smoke test ${SECONDS}s"
