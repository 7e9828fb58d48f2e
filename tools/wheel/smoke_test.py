"""Run by test_fresh_venv.sh inside the fresh venv: the installed wheel fits
(with the progress bar of its extra `progress`), saves, loads and samples, its
extra `examples` is installed, and its library loads the wheel's own libgomp.

Usage: python -I smoke_test.py VENV CHECKOUT
"""
import os
import subprocess
import sys

import numpy as np
import sogmm

venv, checkout = (os.path.realpath(p) for p in sys.argv[1:3])


def check(cond, what):
    if not cond:
        sys.exit(f"smoke_test: FAIL: {what}")


# The package and its library come from the venv, not from the checkout.
pkg = os.path.dirname(os.path.realpath(sogmm.__file__))
lib = os.path.join(pkg, "_lib", "libsogmm.so")
check(pkg.startswith(venv + os.sep), f"sogmm imported from {pkg}, not from the venv {venv}")
check(not os.getcwd().startswith(checkout + os.sep), "cwd is inside the checkout")
for var in ("LD_LIBRARY_PATH", "PYTHONPATH", "SOGMM_LIBRARY_PATH"):
    check(var not in os.environ, f"{var} is set")

# ldd: every dependency found; libgomp from the wheel's sogmm.libs/; libzstd
# is linked statically (no libzstd.so line at all).
ldd = subprocess.run(["ldd", lib], capture_output=True, text=True, check=True).stdout
libs_dir = os.path.join(os.path.dirname(pkg), "sogmm.libs") + os.sep
deps = {}
for line in ldd.splitlines():
    parts = line.split()
    if len(parts) >= 3 and parts[1] == "=>":
        deps[parts[0]] = parts[2]
check("not" not in deps.values(), f"unresolved dependency:\n{ldd}")
gomp = [p for n, p in deps.items() if n.startswith("libgomp")]
check(len(gomp) == 1 and os.path.realpath(gomp[0]).startswith(libs_dir),
      f"libgomp not resolved from {libs_dir}:\n{ldd}")
check(not any(n.startswith("libzstd") for n in deps), f"libzstd linked dynamically:\n{ldd}")

# Fit: two well-separated seeded clusters in (x, y, z, gray); the fitted
# means must be the cluster centres.
rng = np.random.default_rng(7)
centres = np.array([[0.0, 0.0, 1.0, 0.2], [1.0, 0.5, 2.0, 0.8]])
X = np.concatenate([c + 0.02 * rng.standard_normal((2000, 4)) for c in centres]).astype(np.float32)
# progress=True: the extra `progress` (tqdm) was installed with the wheel.
model = sogmm.SOGMM(n_components=2, seed=0).fit(X, progress=True)
check(model.n_components_ == 2, f"n_components_ = {model.n_components_}")
order = np.argsort(model.means_[:, 0])
check(np.allclose(model.means_[order], centres, atol=0.01), f"means {model.means_[order]} != {centres}")
check(np.allclose(model.weights_[order], [0.5, 0.5], atol=0.01), f"weights {model.weights_}")

# The extra `examples` (Pillow), with which the README's example reads frames.
try:
    from PIL import Image  # noqa: F401
except ImportError:
    sys.exit("smoke_test: FAIL: Pillow (extra `examples`) not installed with the wheel")

# Save (zstd-compressed), load: the arrays come back bitwise.
model.save("m.sogmm")
same = sogmm.load("m.sogmm")
for name in ("weights_", "means_", "covariances_"):
    a, b = getattr(model, name), getattr(same, name)
    check(a.dtype == b.dtype and np.array_equal(a, b), f"{name} changed by save/load")

# Sample: seeded, the same from the loaded model, around the centres.
s1 = model.sample(4000, seed=3)
s2 = same.sample(4000, seed=3)
check(s1.shape == (4000, 4) and np.array_equal(s1, s2), "samples differ between model and loaded model")
near = np.min(np.linalg.norm(s1[:, None, :] - centres[None], axis=2), axis=1)
check(np.all(near < 0.2), "a sample is far from both centres")
print(f"smoke_test: OK ({os.path.basename(os.path.dirname(pkg))}, libgomp {os.path.basename(gomp[0])})")
