#!/usr/bin/env python3
"""Cross-language matrix test: a model written by each of C, Python, Rust and
Go is read by every one of them, and every reader must produce bitwise-equal
arrays.

Protocol (each participant implements it with its own binding):
  write <points.f32> <out.sogmm>: fit the points (little-endian float32 rows
      x, y, z, gray) with bandwidth 0.05, seed 16, 1 thread; save, default options.
  read <in.sogmm> <query.f32> <out.bin>: load; dump weights, means,
      covariances, 256 samples (seed 2024, dims 4), gray regression mean and
      variance at the query's (x, y, z) rows as float32, then the 3-D
      log-density there as float64, little-endian, concatenated.
  frame <depth.png> <color image> <out.sogmm>: read the RGB-D frame with the
      library's frame reader (never the language's own image decoder), fit it
      with fx = fy = 525, cx = 319.5, cy = 239.5, bandwidth 0.05, seed 16,
      1 thread, decimation 2; save, default options.
Participants: bindings/matrix/matrix.c (C API directly), matrix.py
(bindings/python), bindings/rust/sogmm/examples/matrix.rs, and
bindings/go/cmd/sogmm-matrix.

Since the four writers fit the same points with the same seed, the four
models are the same too: all 16 dumps must be byte-identical. That covers
"model written by X, read by Y" and "same seeds, same samples and
regressions in every language" at once. The table marks each (writer,
reader) cell with the check mark when its dump equals the C/C reference.

The frame stage fits the livingroom frame 00000 FILES (depth PNG, colour
JPEG) of --data-dir in every language; the C reader dumps the four models and
the dumps must be byte-identical (the same decoded bytes, the same model).
Without the data folder the stage is left out, with a message, and the exit
code is 77.

Languages whose toolchain (cargo, go) is missing are left out: the rest of
the matrix still runs, and the exit code is then 77 (ctest SKIP_RETURN_CODE)
with a message, unless a cell differs (exit 1).

    python3 bindings/matrix/run_matrix.py --build-dir build --markdown
"""
from __future__ import annotations

import argparse
import hashlib
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
SKIP = 77


def points_and_query(workdir: Path) -> tuple[Path, Path]:
    """Three blobs of 600 points (x, y, z, gray) and 64 query positions, seeded."""
    rng = np.random.default_rng(16)
    centres = np.array([[-0.3, 0.0, 1.0, 0.2], [0.3, 0.1, 1.2, 0.5], [0.0, -0.2, 1.5, 0.9]])
    scale = np.array([0.05, 0.05, 0.05, 0.03])
    pts = np.concatenate([c + scale * rng.standard_normal((600, 4)) for c in centres]).astype("<f4")
    query = rng.uniform([-0.4, -0.3, 0.9], [0.4, 0.2, 1.6], size=(64, 3)).astype("<f4")
    p, q = workdir / "points.f32", workdir / "query.f32"
    pts.tofile(p)
    query.tofile(q)
    return p, q


def frame_stage(langs: dict[str, list[str]], env: dict, workdir: Path, query: Path, room: Path) -> list[str]:
    """Each language fits the frame files; returns the languages whose model
    differs from C's (compared through the C reader's dump)."""
    depth, color = room / "depth" / "00000.png", room / "color" / "00000.jpg"
    dumps = {}
    for lang, cmd in langs.items():
        model = workdir / f"frame-by-{lang}.sogmm"
        run(cmd + ["frame", str(depth), str(color), str(model)], env)
        out = workdir / f"frame-{lang}-read-by-C.bin"
        run(langs["C"] + ["read", str(model), str(query), str(out)], env)
        dumps[lang] = out.read_bytes()
    # The dump is K weights, 4K means, 16K covariances (float32), then a fixed tail.
    tail = 4 * (4 * 256) + 2 * 4 * 64 + 8 * 64
    print("\nFrame stage: livingroom frame 00000 (depth PNG + colour JPEG) read by the library in each language")
    for lang, d in dumps.items():
        k = (len(d) - tail) // (4 * 21)
        print(f"  {lang:>6}: {k} components, {'same' if d == dumps['C'] else 'DIFF'} as C")
    return [lang for lang, d in dumps.items() if d != dumps["C"]]


def find_tool(name: str, given: str | None) -> str | None:
    if given is not None:
        return given or None  # "" = leave that language out
    return shutil.which(name) or shutil.which(str(Path.home() / ".cargo" / "bin" / name)) or (
        shutil.which(str(Path("/usr/local/go/bin") / name)))


def run(cmd: list[str], env: dict, cwd: Path | None = None) -> None:
    r = subprocess.run(cmd, env=env, cwd=cwd, capture_output=True, text=True)
    if r.returncode != 0:
        sys.exit(f"matrix: {' '.join(map(str, cmd))} failed ({r.returncode}):\n{r.stdout}{r.stderr}")


def participants(args, env: dict, workdir: Path) -> tuple[dict[str, list[str]], list[str]]:
    """Command prefix of each available participant, building Rust and Go ones."""
    found = {"C": [str(args.c_bin)], "Python": [sys.executable, str(Path(__file__).with_name("matrix.py"))]}
    missing = []
    cargo = find_tool("cargo", args.cargo)
    if cargo:
        manifest = ROOT / "bindings" / "rust" / "Cargo.toml"
        run([cargo, "build", "--quiet", "--locked", "--example", "matrix", "--manifest-path", str(manifest)], env)
        target = Path(env.get("CARGO_TARGET_DIR", ROOT / "bindings" / "rust" / "target"))
        found["Rust"] = [str(target / "debug" / "examples" / "matrix")]
    else:
        missing.append("Rust (cargo not found)")
    go = find_tool("go", args.go)
    if go:
        exe = workdir / "sogmm-matrix"
        run([go, "build", "-o", str(exe), "./cmd/sogmm-matrix"], env, cwd=ROOT / "bindings" / "go")
        found["Go"] = [str(exe)]
    else:
        missing.append("Go (go not found)")
    return found, missing


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--build-dir", type=Path, default=ROOT / "build", help="CMake build folder (libsogmm in capi/)")
    ap.add_argument("--lib-dir", type=Path, help="folder of libsogmm.so (default <build>/capi)")
    ap.add_argument("--c-bin", type=Path, help="C participant (default <build>/bindings/sogmm_matrix_c)")
    ap.add_argument("--cargo", help="cargo to use; '' leaves Rust out (default: PATH, ~/.cargo/bin)")
    ap.add_argument("--go", help="go to use; '' leaves Go out (default: PATH, /usr/local/go/bin)")
    ap.add_argument("--workdir", type=Path, help="scratch folder (default <build>/bindings/matrix)")
    ap.add_argument("--data-dir", type=Path, default=ROOT.parent / "shared" / "data",
                    help="folder holding rgbd/livingroom (default ../shared/data beside the project)")
    ap.add_argument("--markdown", action="store_true", help="print the table as Markdown (for the README)")
    args = ap.parse_args()
    build = args.build_dir.resolve()
    lib_dir = (args.lib_dir or build / "capi").resolve()
    args.c_bin = args.c_bin or build / "bindings" / "sogmm_matrix_c"
    workdir = (args.workdir or build / "bindings" / "matrix").resolve()
    workdir.mkdir(parents=True, exist_ok=True)

    env = dict(os.environ)
    env.update({
        "SOGMM_LIB_DIR": str(lib_dir),
        "SOGMM_LIBRARY_PATH": str(lib_dir / "libsogmm.so"),
        "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT / "bindings" / "python" / "src"), env.get("PYTHONPATH")])),
        "PYTHONDONTWRITEBYTECODE": "1",
        "CGO_LDFLAGS": f"-L{lib_dir} -Wl,-rpath,{lib_dir}",
        "GOFLAGS": "-buildvcs=false", "GOTOOLCHAIN": "local", "GOPROXY": "off",
    })
    env.setdefault("CARGO_BUILD_JOBS", "1")
    points, query = points_and_query(workdir)
    langs, missing = participants(args, env, workdir)

    for w, cmd in langs.items():
        run(cmd + ["write", str(points), str(workdir / f"by-{w}.sogmm")], env)
    digest: dict[tuple[str, str], str] = {}
    for w in langs:
        for r, cmd in langs.items():
            out = workdir / f"{w}-read-by-{r}.bin"
            run(cmd + ["read", str(workdir / f"by-{w}.sogmm"), str(query), str(out)], env)
            digest[w, r] = hashlib.sha256(out.read_bytes()).hexdigest()

    ref = digest["C", "C"]
    size = (workdir / "C-read-by-C.bin").stat().st_size
    names = list(langs)
    if args.markdown:
        print("| written by \\ read by | " + " | ".join(names) + " |")
        print("|---|" + "---|" * len(names))
        for w in names:
            print(f"| **{w}** | " + " | ".join("✓" if digest[w, r] == ref else "✗ differs" for r in names) + " |")
    else:
        print("writer \\ reader  " + "  ".join(f"{n:>7}" for n in names))
        for w in names:
            print(f"{w:>15}  " + "  ".join(f"{('same' if digest[w, r] == ref else 'DIFF'):>7}" for r in names))
    print(f"\n✓ = the reader's dump ({size} bytes: weights, means, covariances, 256 samples with seed 2024, "
          f"gray regression mean and variance and 3-D log-density at 64 points) is byte-identical to the "
          f"C-written, C-read one (sha256 {ref[:16]}).")
    bad = [k for k, v in digest.items() if v != ref]
    room = args.data_dir / "rgbd" / "livingroom"
    cells = len(digest)
    if room.is_dir():
        bad += [("frame", lang) for lang in frame_stage(langs, env, workdir, query, room)]
        cells += len(langs)
    else:
        missing.append(f"the frame stage ({room} is absent)")
    if bad:
        print(f"FAIL: {len(bad)} of {cells} cells differ: {bad}", file=sys.stderr)
        return 1
    print(f"{cells} passed, 0 failed")
    if missing:
        print("SKIP: matrix incomplete, left out: " + ", ".join(missing))
        return SKIP
    return 0


if __name__ == "__main__":
    sys.exit(main())
