"""Every code sample of the README and of the documentation site (docs/*.md) runs: each block
fenced as c, fortran or python is a whole program, built against this build tree and executed
from the repository's root, as a reader would run it; it must exit with 0. (Blocks fenced
otherwise, or indented, are commands and text: the shell commands that install and build are
run by scripts/package.sh on the packages themselves.)

Usage: doc_samples.py REPO INCLUDE_DIR LIB_DIR FORTRAN_MOD_DIR WORK CC FC [FLAGS]"""
import glob
import os
import re
import subprocess
import sys

root, include, libdir, moddir, work, cc, fc = sys.argv[1:8]
flags = sys.argv[8].split() if len(sys.argv) > 8 else []
os.makedirs(work, exist_ok=True)
env = dict(os.environ, GALPHA_LIBRARY=os.path.join(libdir, "libgalpha.so.0"),
           PYTHONPATH=os.path.join(root, "bindings", "python"))
pages = [os.path.join(root, "README.md")] + sorted(glob.glob(os.path.join(root, "docs", "*.md")))
langs = {"c": "c", "python": "py", "fortran": "f90"}
count = 0
for page in pages:
    text = open(page).read()
    name = os.path.relpath(page, root)
    for k, (lang, code) in enumerate(re.findall(r"^```(\w+)\n(.*?)^```$", text, re.S | re.M)):
        if lang not in langs:
            raise SystemExit("%s: a block fenced as %r: samples are c, fortran or python "
                             "(commands are indented)" % (name, lang))
        stem = "%s_%d" % (re.sub(r"\W", "_", name), k)
        src = os.path.join(work, stem + "." + langs[lang])
        with open(src, "w") as f:
            f.write(code)
        exe = os.path.join(work, stem)
        link = ["-L" + libdir, "-lgalpha", "-Wl,-rpath," + libdir]
        if lang == "c":
            subprocess.run([cc, "-std=c99", "-Wall", "-Werror", *flags, src, "-I" + include,
                            *link, "-lm", "-o", exe], check=True)
            cmd = [exe]
        elif lang == "fortran":
            if fc == "none":
                print("%s block %d (fortran): no Fortran compiler, not built" % (name, k))
                continue
            subprocess.run([fc, "-Wall", "-Wno-unused-dummy-argument", *flags, src,
                            "-I" + moddir, "-L" + libdir, "-lgalpha_fortran", *link, "-o", exe],
                           check=True, cwd=work)
            cmd = [exe]
        else:
            cmd = [sys.executable, src]
        out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env,
                             cwd=root).stdout
        count += 1
        print("%s block %d (%s) ran:\n  %s" % (name, k, lang,
                                              out.strip().replace("\n", "\n  ")))
if count < 5:
    raise SystemExit("only %d samples found: the pages lost their programs" % count)
print("%d samples ran" % count)
