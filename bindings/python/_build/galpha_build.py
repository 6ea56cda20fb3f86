"""A PEP 517 build backend for the galpha package, in the source tree.

Why not setuptools: pip builds in an isolated environment and would have to download
setuptools from PyPI, which Debian machines without network (or behind a mirror of Debian
only) cannot reach -- even with python3-setuptools installed. A wheel is a zip file with three
metadata files, so this backend writes it directly and needs nothing.

The wheel carries the C library (config setting or environment variable `library`,
GALPHA_WHEEL_LIBRARY):
  unset   -- libgalpha is built with CMake from the source tree around this package;
  PATH    -- that libgalpha.so.0 (a release build) is taken;
  none    -- no library: the pure-Python package, which uses an installed libgalpha.
The library's own dependencies outside what numpy brings (SuiteSparse, METIS, libgomp) go
into the wheel beside it; galpha/_bundled.py lists them in load order (galpha/_ffi.py)."""
import base64
import hashlib
import os
import re
import subprocess
import sys
import sysconfig
import tempfile
import zipfile

NAME = "galpha"
VERSION = "0.3.0"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE = os.path.dirname(os.path.dirname(ROOT))  # the galpha source tree, if this is in one
DIST_INFO = "%s-%s.dist-info" % (NAME, VERSION)
METADATA = """Metadata-Version: 2.1
Name: galpha
Version: %s
Summary: Generalized-alpha integrator for constrained mechanical systems (ctypes bindings to libgalpha)
License: BSD-3-Clause
Requires-Python: >=3.8
Requires-Dist: numpy
""" % VERSION
# What a machine with numpy has (numpy needs LAPACK and BLAS) and what every Linux has: not
# bundled. A library outside this list and the C/C++ runtime is.
SYSTEM = ("linux-vdso", "ld-linux", "libc.so", "libm.so", "libdl.so", "libpthread.so",
          "librt.so", "libstdc++.so", "libgcc_s.so", "liblapack.so", "libblas.so",
          "libgfortran.so", "libquadmath.so")
LIBS = NAME + "/_libs"


def _wheel_text(tag, purelib):
    return "Wheel-Version: 1.0\nGenerator: galpha_build\nRoot-Is-Purelib: %s\nTag: %s\n" % (
        "true" if purelib else "false", tag)


def get_requires_for_build_wheel(config_settings=None):
    return []


def get_requires_for_build_sdist(config_settings=None):
    return []


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    path = os.path.join(metadata_directory, DIST_INFO)
    os.makedirs(path, exist_ok=True)
    with open(os.path.join(path, "METADATA"), "w") as f:
        f.write(METADATA)
    with open(os.path.join(path, "WHEEL"), "w") as f:
        f.write(_wheel_text("py3-none-any", True))
    return DIST_INFO


def get_requires_for_build_editable(config_settings=None):
    return []


def prepare_metadata_for_build_editable(metadata_directory, config_settings=None):
    return prepare_metadata_for_build_wheel(metadata_directory, config_settings)


def _record_line(name, data):
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
    return "%s,sha256=%s,%d" % (name, digest, len(data))


def _package_files():
    files = []
    pkg = os.path.join(ROOT, NAME)
    for entry in sorted(os.listdir(pkg)):
        # _install.py and _bundled.py are written by cmake --install and by this backend
        if (entry.endswith(".py") or entry == "py.typed") and entry not in ("_install.py",
                                                                            "_bundled.py"):
            with open(os.path.join(pkg, entry), "rb") as f:
                files.append(("%s/%s" % (NAME, entry), f.read()))
    return files


def _setting(config_settings):
    value = (config_settings or {}).get("library") or os.environ.get("GALPHA_WHEEL_LIBRARY")
    return value or None


def _build_library(work):
    """libgalpha.so.0 built by CMake from the source tree, in work (release, no tests)."""
    if not os.path.isfile(os.path.join(SOURCE, "CMakeLists.txt")) or not os.path.isfile(
            os.path.join(SOURCE, "include", "galpha.h")):
        raise RuntimeError("galpha: no C library to put into the wheel -- not in galpha's "
                           "source tree (%s); pass --config-settings library=PATH to a built "
                           "libgalpha.so.0, or library=none for the pure-Python package"
                           % SOURCE)
    build = os.path.join(work, "build")
    jobs = str(os.cpu_count() or 2)
    for cmd in (["cmake", "-S", SOURCE, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                 "-DGALPHA_BUILD_TESTS=OFF", "-DGALPHA_BUILD_EXAMPLES=OFF",
                 "-DGALPHA_BUILD_BENCH=OFF", "-DGALPHA_FORTRAN=OFF"],
                ["cmake", "--build", build, "--target", "galpha", "-j", jobs]):
        done = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        if done.returncode != 0:
            sys.stderr.write(done.stdout)
            raise RuntimeError("galpha: building the C library failed (%s); the build needs "
                               "cmake, a C++ compiler, Eigen, LAPACK and SuiteSparse "
                               "(scripts/deps.sh lists Debian's packages)" % " ".join(cmd))
    return os.path.join(build, "libgalpha.so.0")


def _needed(path):
    """{soname: file} of everything the dynamic linker loads for path (ldd)."""
    out = subprocess.run(["ldd", path], check=True, stdout=subprocess.PIPE, text=True).stdout
    found = {}
    for line in out.splitlines():
        m = re.match(r"\s*(\S+)\s+=>\s+(\S+)\s+\(", line)
        if m:
            found[m.group(1)] = m.group(2)
        elif "not found" in line:
            raise RuntimeError("galpha: %s needs %s, which is not installed" % (path, line))
    return found


def _bundle(library):
    """[(name in the wheel, bytes)] of the library and its dependencies outside SYSTEM, and
    the _bundled.py that lists them in load order (dependencies before what needs them)."""
    library = os.path.realpath(library)
    needed = _needed(library)
    if any("asan" in name or "ubsan" in name for name in needed):
        raise RuntimeError("galpha: %s is a sanitizer build; a wheel takes a release build"
                           % library)
    bundled = {so: path for so, path in needed.items()
               if not any(so.startswith(prefix) for prefix in SYSTEM)}
    # a library's dependencies are a strict subset of those of what needs it
    depth = {so: len(set(_needed(path)) & set(bundled)) for so, path in bundled.items()}
    order = sorted(bundled, key=lambda so: (depth[so], so))
    files = []
    for so in order:
        with open(os.path.realpath(bundled[so]), "rb") as f:
            files.append(("%s/%s" % (LIBS, so), f.read()))
    with open(library, "rb") as f:
        files.append(("%s/libgalpha.so.0" % LIBS, f.read()))
    listing = ("# written by the wheel's build backend: the C library and what it needs, in load"
               " order\nLIBRARIES = %r\n" % (order + ["libgalpha.so.0"]))
    files.append(("%s/_bundled.py" % NAME, listing.encode()))
    return files


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    setting = _setting(config_settings)
    if setting == "none":
        return _write_wheel(wheel_directory, _package_files(), "py3-none-any", True)
    with tempfile.TemporaryDirectory() as work:
        library = setting if setting else _build_library(work)
        if not os.path.isfile(library):
            raise RuntimeError("galpha: library=%s: no such file" % library)
        platform = re.sub(r"[-.]", "_", sysconfig.get_platform())
        return _write_wheel(wheel_directory, _package_files() + _bundle(library),
                            "py3-none-" + platform, False)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    # PEP 660: a .pth file puts this source tree on sys.path, so edits take effect at once
    # and the library is found in the build trees next to it
    return _write_wheel(wheel_directory, [("%s_editable.pth" % NAME, (ROOT + "\n").encode())],
                        "py3-none-any", True)


def _write_wheel(wheel_directory, files, tag, purelib):
    filename = "%s-%s-%s.whl" % (NAME, VERSION, tag)
    files = list(files)
    files.append(("%s/METADATA" % DIST_INFO, METADATA.encode()))
    files.append(("%s/WHEEL" % DIST_INFO, _wheel_text(tag, purelib).encode()))
    record = [_record_line(n, d) for n, d in files] + ["%s/RECORD,," % DIST_INFO]
    files.append(("%s/RECORD" % DIST_INFO, ("\n".join(record) + "\n").encode()))
    with zipfile.ZipFile(os.path.join(wheel_directory, filename), "w",
                         zipfile.ZIP_DEFLATED) as z:
        for name, data in files:
            info = zipfile.ZipInfo(name, date_time=(2026, 1, 1, 0, 0, 0))
            info.external_attr = (0o755 if name.startswith(LIBS) else 0o644) << 16
            info.compress_type = zipfile.ZIP_DEFLATED
            z.writestr(info, data)
    return filename


def build_sdist(sdist_directory, config_settings=None):
    import io
    import tarfile
    base = "%s-%s" % (NAME, VERSION)
    filename = base + ".tar.gz"
    with tarfile.open(os.path.join(sdist_directory, filename), "w:gz") as t:
        for rel in ["pyproject.toml", "README.md", "_build/galpha_build.py"] + [
                "%s/%s" % (NAME, e) for e in sorted(os.listdir(os.path.join(ROOT, NAME)))
                if (e.endswith(".py") or e == "py.typed") and e not in ("_install.py",
                                                                        "_bundled.py")]:
            t.add(os.path.join(ROOT, rel), arcname="%s/%s" % (base, rel))
        info = tarfile.TarInfo("%s/PKG-INFO" % base)
        data = METADATA.encode()
        info.size = len(data)
        t.addfile(info, io.BytesIO(data))
    return filename
