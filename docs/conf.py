# The gssm manual (Sphinx). Built by scripts/docs into build/docs/html from
# this folder, the generated pages under _generated/ (the INI reference,
# the figures, the C++ reference) and the Python module built in build/.
import os
import sys

project = "gssm"
author = "the gssm developers"
copyright = "2026, the gssm developers"
extensions = ["myst_parser", "sphinx.ext.autodoc", "sphinx.ext.napoleon"]
source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "_generated/ini-reference.md", "_generated/cpp-html"]
myst_heading_anchors = 3
myst_enable_extensions = ["dollarmath"]
html_theme = "sphinx_rtd_theme"
html_title = "gssm manual"
html_extra_path = ["_generated/cpp-html"] if os.path.isdir(os.path.join(os.path.dirname(__file__), "_generated/cpp-html")) else []
autodoc_member_order = "bysource"
autodoc_default_options = {"members": True, "undoc-members": True, "imported-members": True}
# The module under documentation is the one the build made (scripts/docs sets
# GSSM_PYTHON_DIR): autodoc reads its docstrings, never a copy.
if os.environ.get("GSSM_PYTHON_DIR"):
    sys.path.insert(0, os.environ["GSSM_PYTHON_DIR"])
suppress_warnings = ["myst.xref_missing"] if os.environ.get("GSSM_DOCS_LENIENT") else []
