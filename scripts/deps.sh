# Sourced by the README's commands: installs the Debian packages that are missing (as root),
# or says which command would (as another user).
ensure_packages() {
    local missing=()
    for p in "$@"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
            missing+=("$p")
    done
    [ ${#missing[@]} -eq 0 ] && return 0
    if [ "$(id -u)" -eq 0 ]; then
        echo "installing: ${missing[*]}"
        apt-get update -qq
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends \
            "${missing[@]}" >/dev/null
    else
        echo "missing Debian packages: ${missing[*]}" >&2
        echo "run: sudo apt-get install -y ${missing[*]}" >&2
        exit 1
    fi
}

BUILD_PACKAGES=(build-essential cmake pkg-config libeigen3-dev liblapack-dev libsuitesparse-dev)
TEST_PACKAGES=(libcmocka-dev gfortran python3 python3-numpy python3-pytest python3-venv python3-numba python3-tqdm
               python3-distributed python3-mpi4py openmpi-bin binutils
               valgrind abigail-tools)
# The documentation site and its browser check (scripts/docs.sh); not needed by the library.
DOCS_PACKAGES=(doxygen python3-sphinx python3-myst-parser python3-breathe chromium
               tesseract-ocr tesseract-ocr-eng)
# The other BLAS/LAPACK builds the deep tier runs the release suite under (scripts/test.sh).
BLAS_PACKAGES=(libopenblas0-pthread libopenblas0-serial libblis4-pthread)
JOBS=$(nproc 2>/dev/null || echo 2)
