"""Sphinx configuration for granular's documentation: `make docs` builds it into build/docs/html.

The pages are Markdown (MyST), so docs/engine.md and docs/performance.md are the same files
GitHub shows; the API reference is generated from the numpydoc docstrings (api.md).
"""

import os

import granular

os.environ.setdefault("MPLBACKEND", "Agg")  # autodoc imports granular.plot

project = "granular"
author = "the granular developers"
copyright = "2026, the granular developers"
release = granular.__version__
version = release

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.mathjax",
    "numpydoc",
    # MathJax copied into _static, so equations render without a network (sphinx-mathjax-offline
    # sets mathjax_path to its bundled copy); the module's name has hyphens, hence no import
    "sphinx-mathjax-offline",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build"]
templates_path = ["_templates"]

# --- MyST: $...$ and $$...$$ math, ::: fences, headings as link targets --------------------
myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence", "deflist"]
myst_heading_anchors = 3
# every cross-reference must resolve (a renamed function breaks the build, not a link)
nitpicky = True

# --- API reference -------------------------------------------------------------------------
autosummary_generate = True
autosummary_imported_members = False
autodoc_member_order = "bysource"
autodoc_typehints = "none"  # numpydoc's Parameters sections carry the types, once
autodoc_default_options: dict = {}  # the templates say what each page documents
numpydoc_show_class_members = False  # members are documented on the class's own page
numpydoc_class_members_toctree = False
numpydoc_xref_param_type = False


def _skip_namedtuple_fields(app, what, name, obj, skip, options):
    # a NamedTuple's fields are documented in its Attributes section; the properties
    # namedtuple makes for them only say "Alias for field number k"
    if (getattr(obj, "__doc__", None) or "").startswith("Alias for field number"):
        return True
    return None


def setup(app):
    app.connect("autodoc-skip-member", _skip_namedtuple_fields)


# --- HTML ----------------------------------------------------------------------------------
html_theme = "furo"
html_title = f"granular {release}"
html_static_path = []
html_show_sourcelink = False
