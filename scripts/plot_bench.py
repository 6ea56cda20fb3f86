#!/usr/bin/python3
"""Charts of docs/perf from the CSV files scripts/bench.sh writes there, and the figures the
performance notes quote (printed). Usage: plot_bench.py DIR"""
import csv
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

DIR = sys.argv[1] if len(sys.argv) > 1 else "docs/perf"


def rows(name):
    path = os.path.join(DIR, name)
    if not os.path.exists(path):
        return []
    with open(path) as f:
        return list(csv.DictReader(f))


def num(x):
    try:
        return float(x)
    except ValueError:
        return math.nan


def save(fig, name):
    fig.tight_layout()
    fig.savefig(os.path.join(DIR, name), dpi=110)
    plt.close(fig)
    print("  wrote", os.path.join(DIR, name))


# ---- per-step cost against the unavoidable work ---------------------------------------------
sc = rows("step_cost.csv")
if sc:
    fig, ax = plt.subplots(figsize=(11, 4))
    labels, cost, limit = [], [], []
    for r in sc:
        labels.append("%s\n%s\ntol %s" % (r["scene"], r["backend"].replace("dense ", ""),
                                           r["newton_tol"]))
        cost.append(num(r["us_per_step"]))
        limit.append(num(r["limit_us"]))
        print("  step cost %-17s %-16s tol %-6s %7.2f us/step, limit %6.2f us, ratio %5.2f, "
              "%.2f Newton it/step, %.2f factorizations/step" % (
                  r["scene"], r["backend"], r["newton_tol"], cost[-1], limit[-1],
                  num(r["ratio"]), num(r["newton_per_step"]), num(r["factorizations_per_step"])))
    x = np.arange(len(labels))
    ax.bar(x - 0.2, cost, 0.4, label="mean cost per step")
    ax.bar(x + 0.2, limit, 0.4, label="limit: one residual + one solve")
    for i, r in enumerate(sc):
        ax.text(x[i] - 0.2, cost[i], "%.1fx" % num(r["ratio"]), ha="center", va="bottom",
                fontsize=7)
    ax.set_xticks(x)
    ax.set_xticklabels(labels, fontsize=6)
    ax.set_yscale("log")
    ax.set_ylabel("microseconds")
    ax.legend()
    ax.set_title("Cost per step against the unavoidable work (paper's scenes, fixed h)")
    save(fig, "step_cost.png")
for r in rows("step_instructions.csv"):
    print("  step instructions %-17s tol %-6s %8.0f per step, limit %7.0f, ratio %5.2f" % (
        r["scene"], r["newton_tol"], num(r["instructions_per_step"]),
        num(r["limit_instructions"]), num(r["ratio"])))

# ---- chain scaling ------------------------------------------------------------------------------
ch = rows("chain.csv")
if ch:
    N = np.array([num(r["links"]) for r in ch])
    us = np.array([num(r["us_per_step"]) for r in ch])
    later = np.array([num(r["later_us_per_step"]) for r in ch])
    nsteps = int(num(ch[0]["steps"]))
    lim = np.array([num(r["limit_us"]) for r in ch])
    mem = np.array([num(r["peak_rss_kib"]) for r in ch]) / 1024.0
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.2))
    ax[0].loglog(N, us, "o-", label="time per step (all %d steps)" % nsteps)
    ax[0].loglog(N, later, "^-", ms=4, label="steps 2-%d" % nsteps)
    ax[0].loglog(N, lim, "s--", label="limit (one residual + one solve)")
    ax[0].loglog(N, us[0] * N / N[0], "k:", lw=1, label="linear in N")
    ax[0].set(xlabel="links N (3N coordinates, 2N constraints)", ylabel="microseconds")
    ax[0].legend()
    ax[0].grid(True, which="both", lw=0.3)
    ax[1].loglog(N, mem, "o-", label="peak resident memory")
    ax[1].loglog(N, mem[-1] * N / N[-1], "k:", lw=1, label="linear in N")
    ax[1].set(xlabel="links N", ylabel="MiB")
    ax[1].legend()
    ax[1].grid(True, which="both", lw=0.3)
    fig.suptitle("N-link chain, sparse path, h = 1e-3, %d steps from rest" % nsteps)
    save(fig, "chain.png")
    i1, i2 = list(N).index(1000), list(N).index(100000)
    print("  chain: time per step %.3g us at N = 1000, %.3g us at N = 100000: %.0f-fold; peak "
          "memory %.1f MiB -> %.1f MiB" % (us[i1], us[i2], us[i2] / us[i1], mem[i1], mem[i2]))
    print("  chain: steps 2-%d %.3g us at N = 1000, %.3g us at N = 100000: %.0f-fold" % (
        nsteps, later[i1], later[i2], later[i2] / later[i1]))
    ins = {int(num(r["links"])): num(r["instructions_per_step"]) for r in rows("chain_instructions.csv")}
    if 1000 in ins and 100000 in ins:
        print("  chain: instructions per step %.3g at N = 1000, %.3g at N = 100000: %.0f-fold" % (
            ins[1000], ins[100000], ins[100000] / ins[1000]))

# ---- the chain against IDA with KLU -------------------------------------------------------------
ci = rows("chain_ida.csv")


def interpolated_cpu(pts, target):
    """CPU at `target` error, log-log between the two settings around it (None if not spanned)"""
    pts = sorted(pts)
    for (e1, c1), (e2, c2) in zip(pts, pts[1:]):
        if e1 <= target <= e2 and e1 > 0:
            w = (math.log(target) - math.log(e1)) / (math.log(e2) - math.log(e1))
            return math.exp(math.log(c1) + w * (math.log(c2) - math.log(c1)))
    return None


if ci:
    links = sorted({int(num(r["links"])) for r in ci})
    methods = (("galpha", "galpha, fixed h", "C0"), ("galpha_adaptive", "galpha, adaptive",
                                                        "C2"),
               ("ida", "SUNDIALS IDA + KLU (index 1, BDF)", "k"))
    fig, ax = plt.subplots(1, len(links) + 1, figsize=(4.2 * (len(links) + 1), 4.2))
    per_time = {m: ([], [], []) for m, _, _ in methods}
    for k, N in enumerate(links):
        for method, label, color in methods:
            pts = [(num(r["error"]), num(r["cpu_seconds"])) for r in ci
                   if int(num(r["links"])) == N and r["method"] == method]
            if not pts:
                continue
            e, c = zip(*sorted(pts, key=lambda p: p[1]))
            ax[k].loglog(c, e, "o-", color=color, ms=4, label=label)
            for j, target in enumerate((1e-3, 1e-5)):
                t = interpolated_cpu(pts, target)
                per_time[method][j].append((N, t / 0.2 if t else math.nan))
            mem = max(num(r["peak_rss_kib"]) for r in ci
                      if int(num(r["links"])) == N and r["method"] == method)
            per_time[method][2].append((N, mem))
        ax[k].set(title="%d links" % N, xlabel="CPU time [s]",
                  ylabel="max error at t = 0.2 s [m, rad]")
        ax[k].grid(True, which="both", lw=0.3)
        ax[k].legend(fontsize=7)
    for method, label, color in methods:
        for j, style in ((0, "o-"), (1, "s--")):
            pts = [p for p in per_time[method][j] if not math.isnan(p[1])]
            if pts:
                ax[-1].loglog(*zip(*pts), style, color=color, ms=4,
                              label="%s, error %s" % (label, ("1e-3", "1e-5")[j]))
    ax[-1].set(title="CPU per simulated second", xlabel="links N", ylabel="seconds")
    ax[-1].grid(True, which="both", lw=0.3)
    ax[-1].legend(fontsize=6)
    fig.suptitle("N-link chain falling from rest, sparse path: galpha against IDA with KLU")
    save(fig, "chain_ida.png")
    for N in links:
        for j, target in enumerate((1e-3, 1e-5)):
            t = {m: dict(per_time[m][j]).get(N) for m, _, _ in methods}
            if t["ida"] and t["galpha"]:
                print("  chain %d links, error %g: IDA %.3g s per simulated s, galpha fixed %.3g "
                      "(%.2fx less), adaptive %s" % (
                          N, target, t["ida"], t["galpha"], t["ida"] / t["galpha"],
                          "%.3g" % t["galpha_adaptive"] if t["galpha_adaptive"] else "-"))
        mem = {m: dict(per_time[m][2]).get(N) for m, _, _ in methods}
        print("  chain %d links: peak memory IDA %.0f MiB, galpha %.0f MiB" % (
            N, mem["ida"] / 1024, mem["galpha"] / 1024))

# ---- the lattice against PETSc's TSALPHA2 -------------------------------------------------------
lp = rows("lattice_petsc.csv")
if lp:
    sizes = sorted({int(num(r["unknowns"])) for r in lp})
    methods = (("galpha", "galpha, fixed h", "C0", "o-"),
               ("galpha_adaptive", "galpha, adaptive", "C2", "o-"),
               ("petsc", "PETSc TSALPHA2, fixed h", "k", "s-"),
               ("petsc_lagged", "TSALPHA2, Jacobian lagged", "C7", "s--"),
               ("petsc_adaptive", "TSALPHA2, adaptive", "C3", "^-"),
               ("petsc_adaptive_lagged", "TSALPHA2, adaptive, lagged", "C1", "^--"))
    fig, ax = plt.subplots(1, len(sizes), figsize=(4.4 * len(sizes), 4.2), squeeze=False)
    for k, n in enumerate(sizes):
        for method, label, color, style in methods:
            pts = [(num(r["error"]), num(r["cpu_seconds"])) for r in lp
                   if int(num(r["unknowns"])) == n and r["method"] == method]
            if not pts:
                continue
            e, c = zip(*sorted(pts, key=lambda p: -p[0]))  # by accuracy: setup dominates CPU
            ax[0][k].loglog(c, e, style, color=color, ms=4, label=label)
        ax[0][k].set(title="%d unknowns" % n, xlabel="CPU time [s]",
                     ylabel="max displacement error at t = 0.2 s [m]")
        ax[0][k].grid(True, which="both", lw=0.3)
        ax[0][k].legend(fontsize=6)
    fig.suptitle("Two-material lattice, no constraints: galpha against PETSc TSALPHA2 (both KLU, "
                 "rho_inf 0.9)")
    save(fig, "lattice_petsc.png")
    for n in sizes:
        for target in (1e-4, 1e-5):
            t = {}
            for method, _, _, _ in methods:
                pts = [(num(r["error"]), num(r["cpu_seconds"])) for r in lp
                       if int(num(r["unknowns"])) == n and r["method"] == method]
                t[method] = interpolated_cpu(pts, target)
            print("  lattice %d unknowns, error %g: CPU per simulated s: %s" % (
                n, target, ", ".join("%s %.3g" % (m, v / 0.2) for m, v in t.items() if v)))


# ---- linear algebra -------------------------------------------------------------------------
la = rows("linear_algebra.csv")
if la:
    fig, ax = plt.subplots(1, 2, figsize=(13, 4.8))
    styles = (("unblocked", "d-"), ("eigen", "o-"), ("lapack", "s-"),
              ("klu", "^-", "sparse path (KLU's ordering, galpha's LU)"),
              ("eigen_sparselu", "v-"))
    for panel, matrix, title in ((0, "chain", "mechanism matrices: the chain (2-7 % nonzero)"),
                                 (1, "full", "saddle-point matrices without zeros")):
        for backend, style, *label in styles:
            pts = sorted((num(r["size"]), num(r["factorize_us"])) for r in la
                         if r["backend"] == backend and r["matrix"] == matrix)
            if pts:
                ax[panel].loglog(*zip(*pts), style, label=label[0] if label else backend)
        ax[panel].set(xlabel="unknowns n + m", ylabel="assembly + factorization [us]",
                      title=title)
        ax[panel].grid(True, which="both", lw=0.3)
    for r in la:  # the paper's scenes, dense
        if r["matrix"] not in ("chain", "full"):
            marker = {"unblocked": "d", "eigen": "o", "lapack": "s"}[r["backend"]]
            ax[0].loglog(num(r["size"]), num(r["factorize_us"]), marker, color="gray", ms=4)
            ax[0].annotate(r["matrix"], (num(r["size"]), num(r["factorize_us"])), fontsize=6)
    ax[0].legend(title="gray: paper's scenes, dense")
    ax[1].legend()
    fig.suptitle("LU of the iteration matrix: galpha's unblocked kernel, Eigen, reference "
                 "LAPACK (dense); galpha's sparse LU, Eigen SparseLU (sparse)")
    save(fig, "linear_algebra.png")


# ---- work-precision against IDA ---------------------------------------------------------------
def curve(data, method):
    pts = sorted((num(r["error"]), num(r["cpu_seconds"]), num(r["residuals"])) for r in data
                 if r["method"] == method and not math.isnan(num(r["error"])))
    return pts


def cheapest_within(pts, target):
    ok = [p for p in pts if p[0] <= target]
    return min(ok, key=lambda p: p[1]) if ok else None


for name, target in (("wp_andrews.csv", 1e-3), ("wp_slider_crank.csv", 1e-3)):
    data = rows(name)
    if not data:
        continue
    scene = data[0]["scene"]
    fig, ax = plt.subplots(1, 3, figsize=(17, 4.5))
    methods = [("ida", "SUNDIALS IDA (index 1, BDF, rtol = atol swept)", "k"),
               ("galpha", "galpha fixed h (full Newton)", "C0"),
               ("galpha_simplified", "galpha fixed h (tangents neglected)", "C1"),
               ("galpha_adaptive", "galpha adaptive (index 2)", "C2"),
               ("galpha_adaptive_index3", "galpha adaptive (index 3)", "C3")]
    best = {}
    for method, label, color in methods:
        pts = curve(data, method)
        if not pts:
            continue
        e, cpu, res = zip(*pts)
        ax[0].loglog(cpu, e, "o-", color=color, label=label, ms=4)
        ax[1].loglog(res, e, "o-", color=color, label=label, ms=4)
        best[method] = cheapest_within(pts, target)
        lam = sorted(((num(r["lambda_error"]), num(r["lambda_step_error"]),
                       num(r["cpu_seconds"])) for r in data
                      if r["method"] == method and num(r["lambda_error"]) > 0),
                     key=lambda x: x[2])
        if lam and method != "galpha_simplified":
            le, ls, lc = zip(*lam)
            ax[2].loglog(lc, le, "o-", color=color, ms=4,
                         label=label if method == "ida" else label + ", consistent lambda")
            if method != "ida":
                ax[2].loglog(lc, ls, "x:", color=color, ms=4, label=label + ", the step's lambda")
    for a in ax:
        a.axhline(target, color="gray", lw=0.5)
        a.grid(True, which="both", lw=0.3)
        a.legend(fontsize=7)
    ax[0].set(xlabel="CPU time [s]", ylabel="max relative error at the final time")
    ax[1].set(xlabel="residual evaluations (IDA: with its difference-quotient Jacobian)")
    ax[2].set(xlabel="CPU time [s]", ylabel="relative error of the multipliers (max-norm)")
    ida = best.get("ida")
    lines = []
    for method, _, _ in methods[1:]:
        b = best.get(method)
        if ida and b:
            lines.append("%s: %.2fx less CPU, %.2fx fewer residuals than IDA at error <= %g" % (
                method, ida[1] / b[1], ida[2] / b[2], target))
    fig.suptitle("%s: work against accuracy, measured in the same run\n%s" % (
        scene, "; ".join(lines[:2])), fontsize=9)
    for line in lines:
        print("  %s: %s" % (scene, line))
    save(fig, name.replace(".csv", ".png"))

po = rows("python_overhead.csv")
for r in po:
    print("  python overhead: %s %.2f us/step (%s x C)" % (r["binding"], num(r["us_per_step"]),
                                                         r["ratio_to_c"]))
