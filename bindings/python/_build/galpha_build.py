"""A PEP 517 build backend for this pure-Python package, in the source tree.

Why not setuptools: pip builds in an isolated environment and would have to download
setuptools from PyPI, which Debian machines without network (or behind a mirror of Debian
only) cannot reach -- even with python3-setuptools installed. A pure-Python wheel is a zip
file with three metadata files, so this backend writes it directly and needs nothing."""
import base64
import hashlib
import os
import zipfile

NAME = "galpha"
VERSION = "0.2.0"
ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DIST_INFO = "%s-%s.dist-info" % (NAME, VERSION)
METADATA = """Metadata-Version: 2.1
Name: galpha
Version: %s
Summary: Generalized-alpha integrator for constrained mechanical systems (ctypes bindings to libgalpha)
License: BSD-3-Clause
Requires-Python: >=3.8
Requires-Dist: numpy
""" % VERSION
WHEEL = """Wheel-Version: 1.0
Generator: galpha_build
Root-Is-Purelib: true
Tag: py3-none-any
"""


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
        f.write(WHEEL)
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
        if (entry.endswith(".py") or entry == "py.typed") and entry != "_install.py":  # _install.py: cmake installs only
            with open(os.path.join(pkg, entry), "rb") as f:
                files.append(("%s/%s" % (NAME, entry), f.read()))
    return files


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    return _write_wheel(wheel_directory, _package_files())


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    # PEP 660: a .pth file puts this source tree on sys.path, so edits take effect at once
    # and the library is found in the build trees next to it
    return _write_wheel(wheel_directory, [("%s_editable.pth" % NAME, (ROOT + "\n").encode())])


def _write_wheel(wheel_directory, files):
    filename = "%s-%s-py3-none-any.whl" % (NAME, VERSION)
    files = list(files)
    files.append(("%s/METADATA" % DIST_INFO, METADATA.encode()))
    files.append(("%s/WHEEL" % DIST_INFO, WHEEL.encode()))
    record = [_record_line(n, d) for n, d in files] + ["%s/RECORD,," % DIST_INFO]
    files.append(("%s/RECORD" % DIST_INFO, ("\n".join(record) + "\n").encode()))
    with zipfile.ZipFile(os.path.join(wheel_directory, filename), "w",
                         zipfile.ZIP_DEFLATED) as z:
        for name, data in files:
            z.writestr(zipfile.ZipInfo(name, date_time=(2026, 1, 1, 0, 0, 0)), data)
    return filename


def build_sdist(sdist_directory, config_settings=None):
    import tarfile
    base = "%s-%s" % (NAME, VERSION)
    filename = base + ".tar.gz"
    with tarfile.open(os.path.join(sdist_directory, filename), "w:gz") as t:
        for rel in ["pyproject.toml", "README.md", "_build/galpha_build.py"] + [
                "%s/%s" % (NAME, e) for e in sorted(os.listdir(os.path.join(ROOT, NAME)))
                if e.endswith(".py") and e != "_install.py"]:
            t.add(os.path.join(ROOT, rel), arcname="%s/%s" % (base, rel))
        info = tarfile.TarInfo("%s/PKG-INFO" % base)
        data = METADATA.encode()
        info.size = len(data)
        import io
        t.addfile(info, io.BytesIO(data))
    return filename
