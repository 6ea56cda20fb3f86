"""Bench figures quoted in README.md and docs/*.md against the CSV files behind them.

A quoted figure carries, right after it, a comment that says where it comes from:

    13.3<!-- fig %.1f csv("perf/python_overhead.csv", "us_per_step", binding="python_ctypes_zero_copy") --> us

FORMAT is a printf format; the expression after it, Python over csv(FILE, COLUMN, KEY=VALUE...)
(the COLUMN of the one row of docs/FILE whose KEY columns hold those values, as a number),
the work-precision readings of the bench's charts (scripts/plot_bench.py) --
cheapest(FILE, ERROR, KEY=VALUE...), the least cpu_seconds among the rows with error <= ERROR
(with of=COLUMN: that row's COLUMN),
and at_error(FILE, ERROR, KEY=VALUE...), cpu_seconds interpolated log-log between the two
rows whose errors bracket ERROR, largest and smallest(FILE, COLUMN, KEY=VALUE...) over the rows,
sweep(FILE, METHOD, AGAINST, KEY=VALUE...) -- for each row of METHOD (with upto=RTOL: whose
setting is at most RTOL), its cpu_seconds over AGAINST's at_error of that row's error, where
AGAINST's rows bracket it (the adaptive rows against the fixed step, as a list) -- and the
functions min, max, abs, round. The figure (the number just before the comment; digits
grouped with spaces or commas are read as one) must equal the expression as FORMAT prints it.

In README.md every figure of a measurement (a number followed by a unit of time, "times", "x",
"%", "runs/s", "instructions") must carry such a comment: a quoted bench figure cannot be
left unchecked there.

Usage: check_figures.py REPO_ROOT            -- exit 1 with every mismatch named
       check_figures.py REPO_ROOT --selftest -- the check fails on a copy whose CSV differs
"""
import csv
import glob
import math
import os
import re
import shutil
import sys
import tempfile

MARK = re.compile(r"(?P<figure>(?:(?<=[\s(])-)?(?:\d{1,3}(?:[ ,]\d{3})+|\d+)(?:\.\d+)?(?:e-?\d+)?)"
                  r"(?P<close>\)?)<!-- fig (?P<fmt>%[-+ #0-9.]*[a-zA-Z]) (?P<expr>.*?) -->",
                  re.S)
UNIT = re.compile(r"\b\d[\d.]*(?:e-?\d+)? ?(?:us|ms|s|times|x|%|runs/s|instructions)\b")


class Figures:
    def __init__(self, root):
        self.root = root
        self.cache = {}

    def csv(self, name, column, **keys):
        rows = self.rows(name, **keys)
        if len(rows) != 1:
            raise ValueError("%s: %d rows with %r" % (name, len(rows), keys))
        return float(rows[0][column])

    def rows(self, name, **keys):
        path = os.path.join(self.root, "docs", name)
        if path not in self.cache:
            with open(path, newline="") as f:
                self.cache[path] = list(csv.DictReader(f))
        rows = [r for r in self.cache[path]
                if all(r.get(k) == str(v) for k, v in keys.items())]
        if not rows:
            raise ValueError("%s: no rows with %r" % (name, keys))
        return rows

    def cheapest(self, name, error, of="cpu_seconds", **keys):
        ok = [r for r in self.rows(name, **keys) if float(r["error"]) <= error]
        if not ok:
            raise ValueError("%s: no row with %r reaches error %g" % (name, keys, error))
        return float(min(ok, key=lambda r: float(r["cpu_seconds"]))[of])

    def largest(self, name, column, **keys):
        return max(float(r[column]) for r in self.rows(name, **keys))

    def at_error(self, name, error, **keys):
        pts = sorted((float(r["error"]), float(r["cpu_seconds"]))
                     for r in self.rows(name, **keys))
        for (e1, c1), (e2, c2) in zip(pts, pts[1:]):
            if 0 < e1 <= error <= e2:
                w = (math.log(error) - math.log(e1)) / (math.log(e2) - math.log(e1))
                return math.exp(math.log(c1) + w * (math.log(c2) - math.log(c1)))
        raise ValueError("%s: the rows with %r do not bracket error %g" % (name, keys, error))

    def smallest(self, name, column, **keys):
        return min(float(r[column]) for r in self.rows(name, **keys))

    def sweep(self, name, method, against, upto=None, **keys):
        ratios = []
        for r in self.rows(name, method=method, **keys):
            if upto is not None and float(r["setting"]) > upto * (1 + 1e-9):
                continue
            try:
                fixed = self.at_error(name, float(r["error"]), method=against, **keys)
            except ValueError:  # outside the fixed steps' range
                continue
            ratios.append(float(r["cpu_seconds"]) / fixed)
        if not ratios:
            raise ValueError("%s: no row of %s within %s's range" % (name, method, against))
        return ratios

    def value(self, expr):
        names = {"csv": self.csv, "cheapest": self.cheapest, "at_error": self.at_error,
                 "largest": self.largest, "smallest": self.smallest, "sweep": self.sweep,
                 "min": min, "max": max, "abs": abs, "round": round}
        return eval(expr, {"__builtins__": {}}, names)


def documents(root):
    return [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs",
                                                                             "*.md")))


def prose(text):
    """The text outside fenced code blocks."""
    return re.sub(r"^```.*?^```$", "", text, flags=re.S | re.M)


def check(root):
    figures, problems, count = Figures(root), [], 0
    for path in documents(root):
        text = open(path).read()
        name = os.path.relpath(path, root)
        for m in MARK.finditer(text):
            count += 1
            quoted = re.sub(r"[ ,]", "", m.group("figure"))
            line = text.count("\n", 0, m.start()) + 1
            try:
                expected = m.group("fmt") % figures.value(m.group("expr"))
            except Exception as e:  # a missing file, row or column is a problem too
                problems.append("%s:%d: %s: %s" % (name, line, m.group("expr"), e))
                continue
            expected = re.sub(r"e([-+]?)0*(\d)", lambda e: "e" + e.group(1).replace("+", "") +
                              e.group(2), expected)  # 1.5e-09 is written 1.5e-9
            if quoted != expected:
                problems.append("%s:%d: quotes %s, the CSV says %s (%s)" % (
                    name, line, m.group("figure").strip(), expected, m.group("expr")))
        if name == "README.md":
            bare = MARK.sub("", prose(text))
            bare = re.sub(r"<!--.*?-->", "", bare, flags=re.S)
            for m in UNIT.finditer(bare):
                line = bare.count("\n", 0, m.start()) + 1
                problems.append("README.md (prose line ~%d): '%s' is a measurement without "
                                "its source (<!-- fig ... -->)" % (line, m.group(0)))
    return count, problems


def selftest(root):
    """Each quoted figure's CSV cell changed in a copy must make the check fail."""
    with tempfile.TemporaryDirectory() as tmp:
        shutil.copy(os.path.join(root, "README.md"), tmp)
        shutil.copytree(os.path.join(root, "docs"), os.path.join(tmp, "docs"),
                        ignore=shutil.ignore_patterns("*.png", "_build", "site"))
        count, problems = check(tmp)
        assert count > 0 and not problems, problems
        target = os.path.join(tmp, "docs", "perf", "python_overhead.csv")
        text = open(target).read()
        open(target, "w").write(text.replace("13.329", "14.329"))
        _, problems = check(tmp)
        assert problems and all("python_overhead" in p for p in problems), problems
        print("selftest: a changed CSV cell fails the check:\n  " + "\n  ".join(problems))
        open(target, "w").write(text)
        readme = os.path.join(tmp, "README.md")
        text = open(readme).read()
        open(readme, "w").write(text + "\nIt is 3.5 times faster.\n")
        _, problems = check(tmp)
        assert any("without its source" in p for p in problems), problems
        print("selftest: an unsourced figure in the README fails the check")


def main():
    root = sys.argv[1]
    if "--selftest" in sys.argv:
        selftest(root)
        return 0
    count, problems = check(root)
    if problems:
        print("figures that differ from their CSV, or lack one:\n  " + "\n  ".join(problems))
        return 1
    print("%d quoted figures equal their CSV" % count)
    return 0


if __name__ == "__main__":
    sys.exit(main())
