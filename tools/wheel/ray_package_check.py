"""Run by test_fresh_venv.sh inside the fresh venv, where the sogmm wheel and
the sogmm-ray wheel are installed but Ray is not: the Ray application is its
own distribution, the two pin each other's version, and `python -m sogmm_ray`
without Ray says so in one line and exits with status 1.

Usage: python -I ray_package_check.py
"""
import importlib.metadata as md
import importlib.util
import subprocess
import sys


def check(cond, what):
    if not cond:
        sys.exit(f"ray_package_check: FAIL: {what}")


# The core distribution holds no Ray application (nor the module it used to be).
core_files = [str(f) for f in md.files("sogmm")]
check(not [f for f in core_files if f.startswith(("sogmm/distributed/", "sogmm_ray/"))],
      f"the sogmm wheel holds the Ray application: {core_files}")
check(importlib.util.find_spec("sogmm.distributed") is None, "sogmm.distributed is importable")
check(any(f.startswith("sogmm_ray/__main__.py") for f in map(str, md.files("sogmm-ray"))),
      "the sogmm-ray wheel has no sogmm_ray/__main__.py")

# The extra sogmm[ray] pulls exactly this sogmm-ray, which needs exactly this sogmm.
core_v, ray_v = md.version("sogmm"), md.version("sogmm-ray")
extra = [r for r in md.requires("sogmm") if 'extra == "ray"' in r]
check(extra == [f'sogmm-ray=={ray_v}; extra == "ray"'], f"sogmm's extra ray is {extra}, not sogmm-ray=={ray_v}")
check(f"sogmm=={core_v}" in md.requires("sogmm-ray"), f"sogmm-ray does not require sogmm=={core_v}")
check(importlib.util.find_spec("ray") is None, "Ray is installed in the venv: the check needs it absent")

p = subprocess.run([sys.executable, "-I", "-m", "sogmm_ray", "--sequence", "x", "--trajectory", "x.log", "-o", "m"],
                   capture_output=True, text=True, timeout=60)
check(p.returncode == 1, f"python -m sogmm_ray without Ray exited {p.returncode}: {p.stderr}")
check(p.stderr.count("\n") == 1 and p.stderr.startswith("sogmm_ray: Ray is not installed: pip install 'sogmm[ray]'"),
      f"python -m sogmm_ray without Ray did not print one line:\n{p.stderr}")
print(f"ray_package_check: OK (sogmm {core_v}, sogmm-ray {ray_v}; without Ray: {p.stderr.strip()})")
