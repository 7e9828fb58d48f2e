#!/usr/bin/env python3
"""Performance benchmark of SOGMM (issues 8 and 17): the issue 17 table.

Runs `sogmm-perf` (one fit and its queries, JSON) on livingroom frame 00000
and `sogmm-bench-warm` (frame 00001 warm-started from 00000's model moved by
the relative pose, against a cold fit of 00001) for every case, with 2 threads
(--runs times) and 1 thread (--runs times), and prints the issue's table of
medians: today's figures (a baseline build, e.g. main at d0d1d93 in its own
worktree, given by --baseline-root) and the new ones from the same run, the
runs of both builds interleaved so that machine load hits both alike. Then one
roofline line per stage: pairs per second achieved (N x M x iterations x pair
fraction for EM, N x M for regress and score) against the EM kernel's measured
peak (ten exact E+M passes from the fitted model, in the same process).
Then the thread-scaling sections: per row the 1- and 2-thread medians, their
ratio, and the serial share f measured in CPU time on one thread (the calling
thread's CPU outside the core's parallel loops, which load on the machine
hardly moves), with Amdahl's bound 1 / (f + (1 - f) / 2) on the two-thread
speed-up and the number of parallel loops (one OpenMP region each on two
threads); 1.8x needs f <= 0.111. Per fit also each stage's f. And where the
two-thread time goes: the Amdahl ideal and the losses on top of it (serial
growth, work inflation, imbalance, waking and joining the team), from the
team split of sogmm/loop_accounting.hpp, next to what two threads cost on
this machine whatever the code (sogmm-corun).

Usage (from the repository root, after tools/setup.sh):
    python3 tools/sogmm-perf/run_perf.py [--runs 5] [--baseline-root ../wt-base]
        [--cases d5s02,d5s01,d1s02,d1s02t20] [--no-warm] [--isa native,avx2] [--update-readme]
        [--new-fit-args "--truncate 20 --em-acceleration squarem --tol-standard-errors 0.5"]
The baseline root is a checkout whose build/tools/sogmm-perf/sogmm-perf exists.
--update-readme also writes the report into README.md (between its run_perf
markers), headed by the date, the machine and both commits.
--new-fit-args gives the new build's fits extra sogmm-perf options (a
candidate default, e.g. SQUAREM with the noise-aware stop), the baseline's fits
keep their defaults: the same-run ratio a change of defaults would give. Not
with --update-readme (the README's block is of the defaults).
"""
import argparse
import contextlib
import datetime
import io
import json
import os
import statistics
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DATA = os.path.join(ROOT, "..", "shared", "data", "rgbd", "livingroom")
CASES = {  # name: (decimation, bandwidth, truncation nats)
    "d5s02": (5, 0.02, 0), "d5s01": (5, 0.01, 0), "d1s02": (1, 0.02, 0), "d1s02t20": (1, 0.02, 20)}
# The authors' published code on frame 00000 (issue 17, same machine kind).
AUTHORS_S = {"d5s02": 9.57, "d5s01": 33.8}


def perf_bin(root):
    return os.path.join(root, "build", "tools", "sogmm-perf", "sogmm-perf")


def run_fit(binary, case, threads, extra=()):
    d, bw, trunc = CASES[case]
    cmd = [binary, "--depth", os.path.join(DATA, "depth", "00000.png"), "--color",
           os.path.join(DATA, "color", "00000.jpg"), "--intrinsics", os.path.join(DATA, "intrinsics.json"),
           "--decimate", str(d), "--bandwidth", str(bw), "--threads", str(threads)]
    if trunc:
        cmd += ["--truncate", str(trunc)]
    cmd += list(extra)
    return json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)


def run_corun():
    """sogmm-corun: the machine's own two-thread cost (co-run inflation of
    register, L2 and memory work; an empty region's cost)."""
    cmd = [os.path.join(ROOT, "build", "tools", "sogmm-perf", "sogmm-corun"), "--repeat", "7"]
    return json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)


def run_warm(threads, repeat, max_iter=None):
    """One sogmm-bench-warm run; max_iter None: the core's default warm pass limit (WarmStartOptions::max_iter)."""
    cap = [] if max_iter is None else ["--warm-max-iter", str(max_iter)]
    cmd = [os.path.join(ROOT, "build", "tools", "sogmm-perf", "sogmm-bench-warm"), "--sequence", DATA,
           "--trajectory", os.path.join(DATA, "trajectory.log"), "--from", "0", "--to", "1", "--decimate", "5",
           "--bandwidth", "0.02", "--threads", str(threads), "--repeat", str(repeat)] + cap
    return json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)


def medians(runs):
    keys = [k for k in runs[0] if isinstance(runs[0][k], (int, float)) and not isinstance(runs[0][k], bool)]
    return {k: statistics.median(r[k] for r in runs) for k in keys}


def fmt(v, unit):
    if v is None:
        return "n/a"
    return f"{1000 * v:.0f} ms" if unit == "ms" else (f"{v:.3f} s" if unit == "s" else
                                                      (f"{100 * v:.0f}%" if unit == "%" else f"{v:.0f} MiB"))


def amdahl(f):
    """The best two-thread speed-up with serial fraction f."""
    return 1.0 / (f + (1.0 - f) / 2.0)


def print_scaling(rows, cases, get):
    """The thread-scaling section (new build): measured ratio against the
    Amdahl bound of the serial share measured in one-thread CPU time."""
    stage_of = {"s_total_fit": "fit", "s_regress": "regress", "s_score": "score",
                "s_regress_culled": "regress_culled", "s_score_culled": "score_culled"}
    print("\nThread scaling (new build): serial share f = one-thread CPU outside the parallel loops / one-thread CPU "
          "(medians); Amdahl bound 1 / (f + (1 - f) / 2); 1.8x needs f <= 11.1%")
    print("| case | 1 thread | 2 threads | 1 -> 2 threads | serial share f | Amdahl bound | parallel loops |")
    print("|---|---|---|---|---|---|---|")
    for label, _target, unit, value, _case in rows:
        if unit in ("%", "MiB"):
            continue
        one, two = value("new", 1), value("new", 2)
        f_txt = bound_txt = loops_txt = ""
        src = getattr(value, "source", None)
        if src:
            case, key = src
            if isinstance(case, dict):  # a warm row: sogmm-bench-warm's one-thread run
                one_run = case.get(1, {})
                cpu, serial, loops = one_run.get("cpu_warm"), one_run.get("serial_cpu_warm"), one_run.get("loops_warm")
            else:
                cpu, serial = get("new", case, f"cpu_{stage_of[key]}", 1), get("new", case, f"serial_cpu_{stage_of[key]}", 1)
                loops = get("new", case, f"loops_{stage_of[key]}", 1)
            if cpu:
                f = serial / cpu
                f_txt, bound_txt = f"{100 * f:.1f}%", f"{amdahl(f):.2f}x"
                loops_txt = f"{loops:.0f}"
        ratio = f"{one / two:.2f}x" if one and two else ""
        print(f"| {label} | {fmt(one, unit)} | {fmt(two, unit)} | {ratio} | {f_txt} | {bound_txt} | {loops_txt} |")
    for case in cases:
        parts = []
        for stage in ("mode_count", "seeding", "em"):
            cpu, serial = get("new", case, f"cpu_{stage}", 1), get("new", case, f"serial_cpu_{stage}", 1)
            if cpu:
                parts.append(f"{stage.replace('_', ' ')} {1000 * cpu:.1f} ms CPU, f {100 * serial / cpu:.1f}% "
                             f"({1000 * serial:.1f} ms), {get('new', case, f'loops_{stage}', 1):.0f} loops")
        if parts:
            print(f"- {case}, one thread: " + "; ".join(parts))


def print_team_split(rows, get, corun):
    """Where the two-thread time goes (new build), per row: the Amdahl ideal
    (one-thread serial CPU + half the one-thread loop CPU) and the losses on
    top of it, from sogmm/loop_accounting.hpp's team split of the two-thread
    run. They add up to the two-thread wall time (up to taking medians):
    ideal + serial growth + inflation + imbalance + start + join."""
    stage_of = {"s_total_fit": "fit", "s_regress": "regress", "s_score": "score",
                "s_regress_culled": "regress_culled", "s_score_culled": "score_culled"}
    print("\nWhere the two-thread time goes (new build, medians, ms): ideal = one-thread serial CPU + one-thread loop "
          "CPU / 2; serial growth = two-thread time outside loops - one-thread serial CPU; inflation = members' mean "
          "busy time - one-thread loop CPU / 2; imbalance = last member's finish - mean finish; start + join = waking "
          "the team and the closing barrier; 1.8x budget = one-thread time / 1.8 - ideal, what the four losses may "
          "add up to for a 1.8x speed-up")
    print("| case | 2 threads | ideal | serial growth | inflation | imbalance | start + join | 1.8x budget | team loops |")
    print("|---|---|---|---|---|---|---|---|---|")
    for label, _target, unit, value, _case in rows:
        src = getattr(value, "source", None)
        if not src or unit in ("%", "MiB"):
            continue
        case, key = src

        def field(name, threads):
            if isinstance(case, dict):  # a warm row: sogmm-bench-warm's runs
                return case.get(threads, {}).get(f"{name}_warm")
            return get("new", case, f"{name}_{stage_of[key]}", threads)

        cpu1, serial1, wall2 = field("cpu", 1), field("serial_cpu", 1), field("wall", 2)
        team = {n: field(f"team_{n}", 2) for n in ("loops", "wall", "busy", "start", "imbalance", "join")}
        if None in (cpu1, serial1, wall2) or None in team.values():
            continue
        ideal = serial1 + (cpu1 - serial1) / 2
        growth = wall2 - team["wall"] - serial1
        inflation = team["busy"] - (cpu1 - serial1) / 2
        ms = lambda v: f"{1000 * v:.1f}"
        print(f"| {label} | {ms(wall2)} | {ms(ideal)} | {ms(growth)} | {ms(inflation)} | {ms(team['imbalance'])} | "
              f"{ms(team['start'] + team['join'])} | {ms(value('new', 1) / 1.8 - ideal)} | {team['loops']:.0f} |")
    if corun:
        infl = {k: 100 * (corun[f"{k}_2"] / corun[f"{k}_1"] - 1) for k in ("alu", "l2", "dram")}
        print(f"- The machine itself (sogmm-corun, same run): the same work on both cores at once instead of one "
              f"takes {infl['alu']:+.1f}% (registers), {infl['l2']:+.1f}% (L2) and {infl['dram']:+.1f}% (memory) "
              f"per thread; an empty two-thread region costs {corun['region_us']:.2f} us.")


README_BEGIN = "<!-- run_perf: begin (written by tools/sogmm-perf/run_perf.py --update-readme) -->"
README_END = "<!-- run_perf: end -->"


def print_quality(cases, get, today):
    """Per case and build (2 threads, medians): EM iterations, the training
    log-likelihood, the held-out log-likelihood and held-out pixel PSNR of
    `sogmm eval` (the d + 1 grid minus the fitting grid), so that a faster
    fit is seen to be as good on pixels it never saw. A build whose
    sogmm-perf predates the held-out keys shows a dash."""
    def cell(v, spec):
        return "-" if v is None else format(v, spec)
    print("\nFit quality (2 threads, medians; held-out = the d + 1 pixel grid minus the fitting grid):")
    print("| case | build | EM iterations | LL (nats/point) | held-out LL | held-out pixel PSNR (dB) |")
    print("|---|---|---|---|---|---|")
    for case in cases:
        for b, label in (("today", today), ("new", "new")):
            if get(b, case, "n") is None:
                continue
            print(f"| {case} | {label} | {cell(get(b, case, 'em_iterations'), '.0f')} | "
                  f"{cell(get(b, case, 'log_likelihood'), '.3f')} | {cell(get(b, case, 'log_likelihood_heldout'), '.3f')} | "
                  f"{cell(get(b, case, 'pixel_psnr_heldout'), '.2f')} |")


def git_head(root):
    return subprocess.run(["git", "-C", root, "rev-parse", "--short", "HEAD"], capture_output=True,
                          text=True).stdout.strip() or "unknown"


def cpu_model():
    if os.path.exists("/proc/cpuinfo"):
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return "unknown CPU"


def kernel_of(isa):
    """The EM/query kernel the runtime dispatch picks (core/src/em_dispatch.cpp)
    under SOGMM_ISA=isa ("native": no cap): the widest the CPU has, unless the
    cap lowers it."""
    flags = set()
    if os.path.exists("/proc/cpuinfo"):
        for line in open("/proc/cpuinfo"):
            if line.startswith("flags"):
                flags = set(line.split(":", 1)[1].split())
                break
    order = ["SSE2"]
    if {"avx2", "fma"} <= flags:
        order.append("AVX2")
        if {"avx512f", "avx512vl", "avx512dq", "avx512bw"} <= flags:
            order.append("AVX-512")
    cap = {"sse2": 0, "avx2": 1}.get(isa, len(order) - 1)
    return order[min(cap, len(order) - 1)]


def update_readme(report, baseline_root, runs, kernels):
    """Replaces the README's measured block (between the run_perf markers)
    with this run's report, headed by when, where and on which commits it
    was measured, so the figures are never copied by hand."""
    path = os.path.join(ROOT, "README.md")
    text = open(path).read()
    if README_BEGIN not in text or README_END not in text:
        sys.exit(f"run_perf: {path} has no run_perf markers")
    cpu = cpu_model()
    dirty = subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()
    head = git_head(ROOT) + (" with uncommitted changes" if dirty else "")
    base = f'"today" is {git_head(baseline_root)}' if baseline_root else "no baseline build"
    header = (f"Measured {datetime.date.today().isoformat()} on {os.cpu_count()} cores of {cpu} ({kernels}), "
              f"medians of {runs} runs: {base}, \"new\" is {head}.\n\n")
    before, rest = text.split(README_BEGIN, 1)
    after = rest.split(README_END, 1)[1]
    with open(path + ".tmp", "w") as f:
        f.write(before + README_BEGIN + "\n" + header + report.strip() + "\n" + README_END + after)
    os.replace(path + ".tmp", path)


def sourced(fn, case, key):
    """fn with the (case, JSON key) it reads attached, for print_scaling (case:
    a case name, or a warm row's results by thread count)."""
    fn.source = (case, key)
    return fn


def measure(a, builds, cases):
    """Runs every case on every build, 2 and 1 threads, interleaved, under
    the kernel SOGMM_ISA selects in this process's environment."""
    corun = run_corun()
    res = {}  # (build, case, threads) -> medians
    for case in cases:
        runs = {(b, t): [] for b in builds for t in (2, 1)}
        # Interleaved: both builds and both thread counts see the same load
        # and the same drift of the machine's speed.
        for _ in range(a.runs):
            for threads in (2, 1):
                for b, binary in builds.items():
                    extra = a.new_fit_args.split() if b == "new" else ()
                    runs[(b, threads)].append(run_fit(binary, case, threads, extra))
        for (b, threads), r in runs.items():
            res[(b, case, threads)] = medians(r)
        print(f"{case}: done", file=sys.stderr)
    warm, warm_tol = {}, {}
    if not a.no_warm:
        for threads in (2, 1):
            warm[threads] = run_warm(threads, a.runs)
            warm_tol[threads] = run_warm(threads, a.runs, 0)
        print("warm: done", file=sys.stderr)

    return res, warm, warm_tol, corun


def print_report(a, cases, res, warm, warm_tol, corun):
    """The issue's tables for one kernel's measurements (to stdout)."""
    if a.new_fit_args:
        print(f"The new build's fits ran with `{a.new_fit_args}` (the baseline's with its defaults).\n")

    def get(b, case, key, threads=2):
        r = res.get((b, case, threads))
        return None if r is None or key not in r else r[key]

    def share(b, case, threads=2):
        s = get(b, case, "s_seeding", threads)
        return None if s is None else s / get(b, case, "s_total_fit", threads)

    # (label, target text, target value, unit, value(build, threads))
    rows = []
    for case, label, target in (("d5s02", "d=5, bandwidth 0.02, cold fit", 0.08),
                                ("d5s01", "d=5, bandwidth 0.01, cold fit", 0.2),
                                ("d1s02t20", "d=1 full frame, truncated E-step", 1.5),
                                ("d1s02", "d=1 full frame, exact", 3.5)):
        if case in cases:
            rows.append((label, target, "s", sourced(lambda b, t, c=case: get(b, c, "s_total_fit", t), case, "s_total_fit"),
                         case))
    if warm:
        rows.insert(2, ("d=5, bandwidth 0.02, next frame warm-started (00000 -> 00001), default pass cap", 0.033, "s",
                        sourced(lambda b, t: warm[t]["s_warm"] if b == "new" else None, warm, "warm"), None))
        rows.insert(3, ("same, warm EM run to tol (--warm-max-iter 0)", 0.033, "s",
                        sourced(lambda b, t: warm_tol[t]["s_warm"] if b == "new" else None, warm_tol, "warm"), None))
    if "d1s02" in cases:
        rows.append(("d=1 regress all points (exact fit)", 0.2, "s",
                     sourced(lambda b, t: get(b, "d1s02", "s_regress", t), "d1s02", "s_regress"), None))
        rows.append(("same, culled at 20 nats", 0.2, "s",
                     sourced(lambda b, t: get(b, "d1s02", "s_regress_culled", t), "d1s02", "s_regress_culled"), None))
    if "d1s02t20" in cases:
        rows.append(("d=1 regress all points (truncated fit)", 0.2, "s",
                     sourced(lambda b, t: get(b, "d1s02t20", "s_regress", t), "d1s02t20", "s_regress"), None))
    if "d5s02" in cases:
        n, m = int(get("new", "d5s02", "n")), int(get("new", "d5s02", "m"))
        rows.append((f"regress gray {n} points, {m} components", 0.02, "ms",
                     sourced(lambda b, t: get(b, "d5s02", "s_regress", t), "d5s02", "s_regress"), None))
        rows.append(("score_samples, same", 0.02, "ms",
                     sourced(lambda b, t: get(b, "d5s02", "s_score", t), "d5s02", "s_score"), None))
        rows.append(("regress gray, culled at 20 nats", 0.02, "ms",
                     sourced(lambda b, t: get(b, "d5s02", "s_regress_culled", t), "d5s02", "s_regress_culled"), None))
        rows.append(("score_samples, culled at 20 nats", 0.02, "ms",
                     sourced(lambda b, t: get(b, "d5s02", "s_score_culled", t), "d5s02", "s_score_culled"), None))
        rows.append(("seeding share of a fit (bw 0.02)", 0.10, "%", lambda b, t: share(b, "d5s02", t), None))
    if "d5s01" in cases:
        rows.append(("seeding share of a fit (bw 0.01)", 0.10, "%", lambda b, t: share(b, "d5s01", t), None))
    if "d1s02" in cases:
        rows.append(("peak RSS, d=1", 100, "MiB", lambda b, t: get(b, "d1s02", "peak_rss_mib", t), None))

    today = f"today ({git_head(a.baseline_root)})" if a.baseline_root else "today"
    print(f"| case | {today} | new | target | met | new, 1 thread | 1 -> 2 threads | authors' code |")
    print("|---|---|---|---|---|---|---|---|")
    for label, target, unit, value, case in rows:
        now, new, one = value("today", 2), value("new", 2), value("new", 1)
        met = "" if new is None else ("yes" if new <= target else "no")
        scal = "" if unit in ("%", "MiB") or not new or not one else f"{one / new:.2f}x"
        authors = ""
        if case in AUTHORS_S and new:
            authors = f"{AUTHORS_S[case]} s ({AUTHORS_S[case] / new:.0f}x)"
        one_txt = fmt(one, unit) if unit not in ("MiB",) else ""
        print(f"| {label} | {fmt(now, unit)} | {fmt(new, unit)} | <= {fmt(target, unit)} | {met} | {one_txt} | "
              f"{scal} | {authors} |")
    # The sparse-EM issue's lines are same-run ratios against its frozen
    # baseline (absolute times depend on the CPU's kernel).
    if a.baseline_root:
        print("\nSame-run speed-up against today (2 threads, medians; the sparse-EM issue's lines):")
        print("| case | today | new | speed-up | target | met |")
        print("|---|---|---|---|---|---|")
        for case, label, target in (("d5s02", "d=5, bandwidth 0.02, cold fit", 2.5),
                                    ("d5s01", "d=5, bandwidth 0.01, cold fit", 2.4),
                                    ("d1s02t20", "d=1 full frame, truncated E-step", 2.0)):
            now, new = get("today", case, "s_total_fit"), get("new", case, "s_total_fit")
            if now and new:
                print(f"| {label} | {fmt(now, 's')} | {fmt(new, 's')} | {now / new:.2f}x | >= {target}x | "
                      f"{'yes' if now / new >= target else 'no'} |")
    for name, w in ((", default pass cap", warm.get(2)), (", EM run to tol", warm_tol.get(2))):
        if w:
            print(f"\nWarm start quality{name} (00001, same run): mean log-likelihood warm {w['ll_warm']:.3f} vs "
                  f"cold {w['ll_cold']:.3f} nats/point; PSNR warm {w['psnr_warm']:.2f} vs cold {w['psnr_cold']:.2f} "
                  f"dB; M {w['m_warm']} vs {w['m_cold']} (kept {w['kept']}, removed {w['removed']}, added "
                  f"{w['added']}); EM iterations {w['iter_warm']} vs {w['iter_cold']}; cold fit of 00001 "
                  f"{w['s_cold']:.3f} s, warm/cold time {w['s_warm'] / w['s_cold']:.2f} (the issue's line: <= 0.40 "
                  f"with likelihood and PSNR no worse than cold: "
                  f"{'met' if w['s_warm'] <= 0.4 * w['s_cold'] and w['ll_warm'] >= w['ll_cold'] and w['psnr_warm'] >= w['psnr_cold'] else 'not met'}).")

    print_quality(cases, get, today)
    print_scaling(rows, cases, get)
    print_team_split(rows, get, corun)

    print("\nRoofline (new build, 2 threads): pairs/s achieved against the EM kernel's measured peak")
    for case in cases:
        peak = get("new", case, "peak_pairs_per_s")
        n, m = get("new", case, "n"), get("new", case, "m")
        em_pairs = n * m * get("new", case, "em_iterations") * get("new", case, "pair_fraction")
        parts = [f"EM {em_pairs / get('new', case, 's_em'):.3g} ({100 * em_pairs / get('new', case, 's_em') / peak:.0f}%)",
                 f"regress {n * m / get('new', case, 's_regress'):.3g} ({100 * n * m / get('new', case, 's_regress') / peak:.0f}%)",
                 f"score {n * m / get('new', case, 's_score'):.3g} ({100 * n * m / get('new', case, 's_score') / peak:.0f}%)"]
        total = get("new", case, "s_total_fit")
        print(f"- {case} (N {int(n)}, M {int(m)}): peak {peak:.3g} pairs/s; " + ", ".join(parts) +
              f"; mode count {100 * get('new', case, 's_mode_count') / total:.0f}% and seeding "
              f"{100 * get('new', case, 's_seeding') / total:.0f}% of the fit (not pair work)")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--baseline-root", default=None, help="checkout with today's build (e.g. main at d0d1d93)")
    ap.add_argument("--no-warm", action="store_true")
    ap.add_argument("--isa", default="",
                    help="kernels to measure, one full run each, e.g. native,avx2 (SOGMM_ISA values; native = "
                         "no cap, the widest the CPU has); default: this environment's SOGMM_ISA")
    ap.add_argument("--update-readme", action="store_true",
                    help="also write the report into README.md between its run_perf markers")
    ap.add_argument("--new-fit-args", default="",
                    help="extra sogmm-perf options for the new build's fits only (e.g. a candidate default); "
                         "not with --update-readme")
    a = ap.parse_args()
    if a.new_fit_args and a.update_readme:
        ap.error("--new-fit-args measures a candidate, not the defaults: not with --update-readme")
    if not os.path.isdir(DATA):
        sys.exit(f"run_perf: {DATA} not found (the real frames live in ../shared/data)")
    builds = {"new": perf_bin(ROOT)}
    if a.baseline_root:
        builds["today"] = perf_bin(a.baseline_root)
    for b in builds.values():
        if not os.path.exists(b):
            sys.exit(f"run_perf: {b} not built (cmake --build build --target sogmm_perf)")
    cases = a.cases.split(",")
    for bad in set(a.isa.split(",") if a.isa else []) - {"native", "sse2", "avx2", "avx512"}:
        sys.exit(f"run_perf: --isa {bad!r} is not one of native, sse2, avx2, avx512")
    isas = a.isa.split(",") if a.isa else [os.environ.get("SOGMM_ISA", "native") or "native"]
    kernel_list = ", ".join(f"{kernel_of(i)} kernel" for i in isas)
    full = io.StringIO()  # every kernel's report, for stdout and the README
    for isa in isas:
        # The runtime dispatch of every process started from here reads it.
        if isa == "native":
            os.environ.pop("SOGMM_ISA", None)
        else:
            os.environ["SOGMM_ISA"] = isa
        measured = measure(a, builds, cases)
        report = io.StringIO()
        with contextlib.redirect_stdout(report):
            print_report(a, cases, *measured)
        if len(isas) > 1:
            full.write(f"\n#### {kernel_of(isa)} kernel (SOGMM_ISA={isa})\n\n")
        full.write(report.getvalue())
        print(f"{kernel_of(isa)} kernel: done", file=sys.stderr)
    sys.stdout.write(full.getvalue())
    if a.update_readme:
        update_readme(full.getvalue(), a.baseline_root, a.runs, kernel_list)

if __name__ == "__main__":
    main()
