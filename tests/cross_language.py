"""The same scene in C, Fortran and Python gives the same numbers (to round-off), the
motor-driven slider-crank (first-order states) included; the impact scene (events and
restarts) in C and Python.

Usage: cross_language.py BIN_DIR PY_EXAMPLES_DIR  (ctest passes both)."""
import os
import subprocess
import sys

import numpy as np

bin_dir, py_dir = sys.argv[1], sys.argv[2]
# scene -> (language, command) pairs, C first; the chain is the sparse path (declared patterns)
SCENES = {
    "pendulum": [("C", [os.path.join(bin_dir, "pendulum_demo")]),
                 ("Fortran", [os.path.join(bin_dir, "pendulum_fortran")]),
                 ("Python", [sys.executable, os.path.join(py_dir, "pendulum.py")])],
    "slider_crank": [("C", [os.path.join(bin_dir, "slider_crank_demo")]),
                     ("Fortran", [os.path.join(bin_dir, "slider_crank_fortran")]),
                     ("Python", [sys.executable, os.path.join(py_dir, "slider_crank.py")])],
    "motor_crank": [("C", [os.path.join(bin_dir, "motor_crank_demo")]),
                    ("Fortran", [os.path.join(bin_dir, "motor_crank_fortran")]),
                    ("Python", [sys.executable, os.path.join(py_dir, "motor_crank.py")])],
    "impact": [("C", [os.path.join(bin_dir, "impact_demo")]),
               ("Python", [sys.executable, os.path.join(py_dir, "impact.py")])],
    "chain_200": [("C", [os.path.join(bin_dir, "chain_demo"), "200", "--print"]),
                  ("Fortran", [os.path.join(bin_dir, "chain_fortran"), "200"]),
                  ("Python", [sys.executable, os.path.join(py_dir, "chain.py"), "200",
                              "--print"])],
}


def final_state(cmd):
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    values = {}
    for line in out.splitlines():
        for key in ("final q =", "final lambda =", "final y ="):
            if line.startswith(key):
                values[key] = np.array([float(x) for x in line[len(key):].split()])
    return np.concatenate([values["final q ="], values["final lambda ="],
                           values.get("final y =", np.zeros(0))])


ok = True
for scene, runs in SCENES.items():
    results = [final_state(cmd) for _, cmd in runs]
    for (lang, _), r in zip(runs[1:], results[1:]):
        diff = np.max(np.abs(r - results[0]) / np.maximum(np.abs(results[0]), 1e-300))
        print("%-13s %-8s vs C: %d values, max relative difference %.1e" % (scene, lang, r.size,
                                                                          diff))
        ok = ok and r.size == results[0].size and diff <= 1e-12
sys.exit(0 if ok else 1)
