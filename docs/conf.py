# Sphinx configuration of galpha's documentation site (scripts/docs.sh builds it).
# Why this generator: the pages are Markdown that GitHub and any editor show as they are, read
# by MyST; the API reference comes from the header's own Doxygen comments through Breathe; all
# three are Debian packages (python3-sphinx, python3-myst-parser, python3-breathe, doxygen).
import os
import re
import sys

here = os.path.dirname(os.path.abspath(__file__))
with open(os.path.join(here, "..", "CMakeLists.txt")) as f:
    release = re.search(r"project\(galpha VERSION ([0-9.]+)", f.read()).group(1)
version = release
project = "galpha"
author = "the galpha developers"
copyright = "2026, the galpha developers"

extensions = ["myst_parser", "breathe", "sphinx.ext.autodoc", "sphinx.ext.napoleon"]
source_suffix = {".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "site", "README.md"]
myst_heading_anchors = 3
breathe_projects = {"galpha": os.environ.get("GALPHA_DOXYGEN_XML", "_build/doxygen/xml")}
breathe_default_project = "galpha"
breathe_domain_by_extension = {"h": "c"}

html_theme = "alabaster"
html_title = "galpha %s" % release
html_theme_options = {"description": "generalized-alpha for constrained mechanical systems",
                      "page_width": "1100px", "sidebar_width": "230px"}
html_show_sourcelink = False
html_static_path = ["_static"]
# Pygments: the guides' code blocks are C, Fortran, Python and shell
highlight_language = "none"
# standard C types the header uses, which no page defines
nitpick_ignore = [("c:identifier", "size_t")]

# The Python reference (api-python.md) imports the package from the source tree; it loads
# libgalpha (GALPHA_LIBRARY: scripts/docs.sh points it at a build). The docstrings are
# numpy-style, read by napoleon.
sys.path.insert(0, os.path.join(here, "..", "bindings", "python"))
autodoc_member_order = "bysource"
napoleon_use_param = False  # the types as written, not cross-references
napoleon_use_rtype = False
autodoc_typehints = "none"  # numpy.typing.ArrayLike would print as its whole Union

