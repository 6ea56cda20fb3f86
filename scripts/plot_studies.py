#!/usr/bin/python3
"""Draws the charts of docs/paper from the CSV files that bench/paper_studies writes there.

Usage: plot_studies.py DIR   (scripts/studies.sh calls it)."""
import csv
import math
import os
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

DIR = sys.argv[1] if len(sys.argv) > 1 else "docs/paper"


def read(name):
    with open(os.path.join(DIR, name)) as f:
        rows = list(csv.DictReader(f))
    out = defaultdict(list)
    for r in rows:
        for k, v in r.items():
            try:
                out[k].append(float(v))
            except ValueError:
                out[k].append(v)
    return {k: (np.array(v) if isinstance(v[0], float) else v) for k, v in out.items()}


def save(fig, name):
    fig.tight_layout()
    fig.savefig(os.path.join(DIR, name), dpi=110)
    plt.close(fig)
    print("  wrote", os.path.join(DIR, name))


def slope(h, e):
    return np.polyfit(np.log(h), np.log(e), 1)[0]


# ---- trajectories (Figs. 2, 5-7) --------------------------------------------------------------
sc = read("slider_crank_trajectory.csv")
fig, ax = plt.subplots(1, 3, figsize=(13, 3.6))
ax[0].plot(sc["t"], sc["theta1"])
ax[0].set(xlabel="t [s]", ylabel="crank angle theta1 [rad]")
ax[1].plot(sc["t"], sc["x4"])
ax[1].set(xlabel="t [s]", ylabel="x4 [m]")
ax[2].plot(sc["t"], sc["lambda1"])
ax[2].set(xlabel="t [s]", ylabel="lambda1")
fig.suptitle("Slider-crank (paper Fig. 2), rho_inf = 0.7, h = 5e-3")
save(fig, "slider_crank_trajectory.png")

a = read("andrews_trajectory_rho0.7.csv")
ref = read("andrews_trajectory_reference.csv")
fig, ax = plt.subplots(2, 2, figsize=(11, 7))
ax[0, 0].plot(a["t"] * 1e3, a["xF"] * 1e3, label="x_F")
ax[0, 0].plot(a["t"] * 1e3, a["yF"] * 1e3, label="y_F")
ax[0, 0].set(xlabel="t [ms]", ylabel="position of F [mm]")
ax[0, 0].legend()
ax[0, 1].plot(a["t"] * 1e3, a["beta"])
ax[0, 1].set(xlabel="t [ms]", ylabel="beta [rad]")
ax[1, 0].plot(a["t"] * 1e3, a["axF"], label="a_x galpha")
ax[1, 0].plot(a["t"] * 1e3, a["ayF"], label="a_y galpha")
ax[1, 0].plot(ref["t"] * 1e3, ref["axF"], "k:", lw=1, label="reference")
ax[1, 0].plot(ref["t"] * 1e3, ref["ayF"], "k:", lw=1)
ax[1, 0].set(xlabel="t [ms]", ylabel="acceleration of F [m/s^2]")
ax[1, 0].legend(fontsize=8)
ax[1, 1].plot(a["t"] * 1e3, a["lambda_E_x"], label="lambda (E on triangle), x")
ax[1, 1].plot(a["t"] * 1e3, a["lambda_E_y"], label="lambda (E on triangle), y")
ax[1, 1].plot(ref["t"] * 1e3, ref["lambda_E_x"], "k:", lw=1, label="reference")
ax[1, 1].plot(ref["t"] * 1e3, ref["lambda_E_y"], "k:", lw=1)
ax[1, 1].set(xlabel="t [ms]", ylabel="multipliers [N]")
ax[1, 1].legend(fontsize=8)
fig.suptitle("Andrews' mechanism, 31 absolute coordinates (paper Figs. 6-7), rho_inf = 0.7, "
             "h = 3e-4; reference: RK4 on the index-1 form")
save(fig, "andrews_trajectory.png")

# ---- damping (Fig. 8) -------------------------------------------------------------------------
a1 = read("andrews_trajectory_rho1.csv")
fig, ax = plt.subplots(1, 3, figsize=(15, 3.8))
for data, style, label in ((a1, "-", "rho_inf = 1"), (a, "-", "rho_inf = 0.7"),
                           (ref, "k:", "reference")):
    ax[0].plot(data["t"] * 1e3, data["axF"], style, lw=1, label=label)
    ax[1].plot(data["t"] * 1e3, data["lambda_F_x"], style, lw=1, label=label)
ax[0].set(xlabel="t [ms]", ylabel="x-acceleration of F [m/s^2]")
ax[1].set(xlabel="t [ms]", ylabel="lambda: x internal force in body 1 [N]")
ax[0].legend(fontsize=8)
ax[1].legend(fontsize=8)
d = read("damping.csv")
for h in sorted(set(d["h"]), reverse=True):
    idx = [i for i, (m, hh) in enumerate(zip(d["model"], d["h"])) if hh == h and m == "andrews7"]
    refi = [i for i, (m, hh) in enumerate(zip(d["model"], d["h"])) if hh == h and m == "reference"]
    rho = [float(d["rho_inf"][i]) for i in idx]
    tv = [d["lambda1_total_variation"][i] / d["lambda1_total_variation"][refi[0]] for i in idx]
    ax[2].plot(rho, tv, "o-", label="h = %g" % h)
ax[2].axhline(1.0, color="k", lw=0.5)
ax[2].set(xlabel="rho_inf", ylabel="total variation of lambda_1 / exact",
          title="multiplier oscillation (7 angles)")
ax[2].legend(fontsize=8)
fig.suptitle("Numerical damping is needed (paper Fig. 8): Andrews, h = 3e-4")
save(fig, "andrews_damping.png")

# ---- convergence (Figs. 3, 9) -----------------------------------------------------------------
c = read("convergence.csv")
fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
titles = {"slider_crank": "slider-crank, t = 1 (ref.: RK4)",
          "andrews7": "Andrews, 7 angles, t = 0.03 (published ref.)",
          "andrews31": "Andrews, 31 coordinates, t = 0.03 (published ref.)"}
for axis, scene in zip(ax, ("slider_crank", "andrews7", "andrews31")):
    for qty, marker in (("theta1", "o"), ("beta", "o"), ("lambda1", "s")):
        idx = [i for i in range(len(c["scene"])) if c["scene"][i] == scene and c["quantity"][i] == qty]
        if not idx:
            continue
        h = c["h"][idx]
        e = c["rel_error"][idx]
        axis.loglog(h, e, marker + "-", label="%s: slope %.2f" % (qty, slope(h, e)))
    hh = np.array([min(c["h"]), max(c["h"])])
    axis.set(xlabel="h [s]", ylabel="relative error at the final time", title=titles[scene])
    axis.grid(True, which="both", lw=0.3)
    axis.legend()
fig.suptitle("Second-order convergence in coordinates and multipliers (paper Figs. 3 and 9), "
             "rho_inf = 0.7")
save(fig, "convergence.png")

# ---- scaling: where methods fail --------------------------------------------------------------
s = read("scaling.csv")
fig, ax = plt.subplots(2, 3, figsize=(15, 7.5))
for row, scene in enumerate(("andrews7", "slider_crank")):
    for scaled, style, label in ((1, "o-", "scaled (eq. 10)"), (0, "s--", "unscaled")):
        idx = [i for i in range(len(s["scene"])) if s["scene"][i] == scene and s["scaled"][i] == scaled]
        ok = [i for i in idx if s["status"][i] == "ok"]
        bad = [i for i in idx if s["status"][i] != "ok"]
        ax[row, 0].loglog(s["h"][ok], s["max_condition"][ok], style, label=label)
        if bad:
            ax[row, 0].loglog(s["h"][bad], np.full(len(bad), 1 / np.finfo(float).eps), "rx",
                              ms=9, label="unscaled: singular (cond > 1/eps)")
        ax[row, 1].semilogx(s["h"][ok], s["newton_iters_per_step"][ok], style, label=label)
        ax[row, 2].loglog(s["h"][ok], s["lambda1_rel_error"][ok], style, label=label + ", lambda_1")
        if scaled:
            ax[row, 2].loglog(s["h"][ok], s["q_rel_error"][ok], "^:", label="scaled, q")
    ax[row, 0].set(xlabel="h", ylabel="condition number of S_t", title=scene)
    ax[row, 1].set(xlabel="h", ylabel="Newton iterations per step", title=scene)
    ax[row, 2].set(xlabel="h", ylabel="relative error after 50 steps", title=scene)
    for k in range(3):
        ax[row, k].grid(True, which="both", lw=0.3)
        ax[row, k].legend(fontsize=8)
fig.suptitle("Where methods fail: without scaling the iteration matrix becomes singular in double "
             "precision; with it, lambda is eventually lost to round-off amplified by 1/h^2")
save(fig, "scaling.png")

# ---- work-precision ---------------------------------------------------------------------------
w = read("work_precision.csv")
fig, ax = plt.subplots(1, 2, figsize=(12, 4.5))
for scene in ("slider_crank", "andrews7", "andrews31"):
    idx = [i for i in range(len(w["scene"])) if w["scene"][i] == scene]
    ax[0].loglog(w["cpu_seconds"][idx], w["rel_error"][idx], "o-", label=scene)
    ax[1].loglog(w["residuals"][idx], w["rel_error"][idx], "o-", label=scene)
ax[0].set(xlabel="CPU time [s]", ylabel="relative error at the final time")
ax[1].set(xlabel="residual evaluations", ylabel="relative error at the final time")
for k in range(2):
    ax[k].grid(True, which="both", lw=0.3)
    ax[k].legend()
fig.suptitle("Work against accuracy, fixed step sizes (error: crank angle; Andrews: 2-norm of "
             "the 7 angles)")
save(fig, "work_precision.png")

# ---- accuracy on demand: adaptive steps -------------------------------------------------------
ad = read("adaptive.csv")
fig, ax = plt.subplots(1, 3, figsize=(16, 4.3))
for form, color in (("index2", "C2"), ("index3", "C3")):
    idx = [i for i in range(len(ad["mode"])) if ad["mode"][i] == "adaptive" and
           ad["formulation"][i] == form and np.isfinite(ad["angle_error"][i])]
    rt, err, res = ad["setting"][idx], ad["angle_error"][idx], ad["residuals"][idx]
    ax[0].loglog(rt, err, "o-", color=color,
                 label="%s: slope %.2f" % (form, slope(rt, err)))
    ax[1].loglog(res, err, "o-", color=color, label="adaptive, " + form)
idx = [i for i in range(len(ad["mode"])) if ad["mode"][i] == "fixed"]
ax[1].loglog(ad["residuals"][idx], ad["angle_error"][idx], "s--", color="C0",
             label="fixed h = 3e-4 / 2^k")
ax[0].loglog([1e-7, 1e-2], [1e-7, 1e-2], "k:", lw=1, label="error = rtol")
ax[0].set(xlabel="rtol = atol", ylabel="relative angle error at t = 0.03",
          title="tolerance proportionality")
ax[1].set(xlabel="residual evaluations", ylabel="relative angle error at t = 0.03",
          title="work against accuracy")
hs = read("adaptive_steps.csv")
for form, color in (("index2", "C2"), ("index3", "C3")):
    idx = [i for i in range(len(hs["formulation"])) if hs["formulation"][i] == form]
    ax[2].semilogy(hs["t"][idx] * 1e3, hs["h"][idx], "-", color=color, label=form)
ax[2].set(xlabel="t [ms]", ylabel="step size h", title="step sizes, rtol = 1e-5")
for a in ax:
    a.grid(True, which="both", lw=0.3)
    a.legend(fontsize=8)
fig.suptitle("Andrews (7 angles), adaptive steps: error control on positions and velocities")
save(fig, "adaptive.png")
