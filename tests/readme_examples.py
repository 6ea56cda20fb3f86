"""Every program in README.md runs: the C, Python and Fortran code blocks are extracted,
built against this build tree and executed.

Usage: readme_examples.py README INCLUDE_DIR LIB_DIR FORTRAN_MOD_DIR WORK CC FC [FLAGS]"""
import os
import re
import subprocess
import sys

readme, include, libdir, moddir, work, cc, fc = sys.argv[1:8]
flags = sys.argv[8].split() if len(sys.argv) > 8 else []
os.makedirs(work, exist_ok=True)
text = open(readme).read()
blocks = re.findall(r"^```(\w+)\n(.*?)^```$", text, re.S | re.M)
assert {lang for lang, _ in blocks} >= {"c", "python"}, "README lost its examples"
env = dict(os.environ, GALPHA_LIBRARY=os.path.join(libdir, "libgalpha.so.0"),
           PYTHONPATH=os.path.join(os.path.dirname(readme), "bindings", "python"))
for k, (lang, code) in enumerate(blocks):
    src = os.path.join(work, "readme_%d.%s" % (k, {"c": "c", "python": "py", "fortran": "f90"}[lang]))
    with open(src, "w") as f:
        f.write(code)
    exe = os.path.join(work, "readme_%d" % k)
    link = ["-L" + libdir, "-lgalpha", "-Wl,-rpath," + libdir]
    if lang == "c":
        subprocess.run([cc, "-std=c99", "-Wall", "-Werror", *flags, src, "-I" + include, *link,
                        "-o", exe], check=True)
        cmd = [exe]
    elif lang == "fortran":
        if fc == "none":
            print("README block %d (fortran): no Fortran compiler, not built" % k)
            continue
        subprocess.run([fc, "-Wall", "-Wno-unused-dummy-argument", *flags, src, "-I" + moddir,
                        "-L" + libdir, "-lgalpha_fortran", *link, "-o", exe], check=True,
                       cwd=work)
        cmd = [exe]
    else:
        cmd = [sys.executable, src]
    # from the repository's root, as a reader would run them
    out = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env,
                         cwd=os.path.dirname(os.path.abspath(readme))).stdout
    print("README block %d (%s) ran:\n  %s" % (k, lang, out.strip().replace("\n", "\n  ")))
