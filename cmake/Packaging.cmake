# CPack: a Debian package (cpack -G DEB, from a tree configured with CMAKE_INSTALL_PREFIX=/usr)
# and a source tarball (cpack --config CPackSourceConfig.cmake). scripts/package.sh makes both,
# installs the .deb, builds and runs the README's program against it, and removes it again.
set(CPACK_PACKAGE_NAME galpha)
set(CPACK_PACKAGE_VENDOR "the galpha developers")
set(CPACK_PACKAGE_CONTACT "the galpha developers <galpha@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "generalized-alpha integrator for constrained mechanical systems (C library)")
set(CPACK_PACKAGE_DESCRIPTION
    "galpha integrates index-3 DAEs of constrained mechanics, M(q) q'' = f - Phi_q^T lambda, \
Phi(q, t) = 0, with the generalized-alpha scheme of Arnold and Bruls, behind a flat C ABI: \
the shared and static library, the header, pkg-config and CMake files, the Fortran module, \
the Python package (ctypes), documentation and examples.")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_PACKAGE_HOMEPAGE_URL "${GALPHA_URL}")

set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION libdevel)
# the run-time libraries (LAPACK, SuiteSparse, libstdc++) from the ELF files, by dpkg-shlibdeps
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# shlibs and the ldconfig trigger: the library is found at once after dpkg -i
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS_POLICY ">=")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "pkg-config, python3-numpy")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "gfortran")

set(CPACK_SOURCE_GENERATOR TGZ)
set(CPACK_SOURCE_PACKAGE_FILE_NAME galpha-${PROJECT_VERSION})
set(CPACK_SOURCE_IGNORE_FILES "/\\\\.git/" "/\\\\.git$" "/build[^/]*/" "/__pycache__/"
    "\\\\.pyc$" "/\\\\.coverage$" "/docs/site/" "/dist/")
include(CPack)
