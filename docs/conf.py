"""Sphinx configuration: the Markdown pages (MyST), the API reference from the docstrings
(autodoc, Google style through napoleon), the demos rendered as pages and the citations from
``references.bib``. Everything comes from Debian's packages; nothing is downloaded while
building (MathJax loads in the reader's browser).

    make docs        # -> build/docs/html/index.html
"""

from __future__ import annotations

import pathlib
import re
import sys

DOCS = pathlib.Path(__file__).resolve().parent
ROOT = DOCS.parent
sys.path.insert(0, str(ROOT))  # the package from this checkout, installed or not

project = "fenicsfriction"
author = "the fenicsfriction authors"
copyright = "the fenicsfriction authors, MIT licence"

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinxcontrib.bibtex",
]
source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "**/.ipynb_checkpoints"]
nitpicky = False

myst_enable_extensions = ["dollarmath", "amsmath", "colon_fence"]
myst_heading_anchors = 3

bibtex_bibfiles = ["references.bib"]
bibtex_default_style = "plain"
bibtex_reference_style = "author_year"

autodoc_member_order = "bysource"
autodoc_typehints = "description"
autodoc_preserve_defaults = True
autodoc_default_options = {"show-inheritance": True}
napoleon_google_docstring = True
napoleon_numpy_docstring = False
napoleon_use_rtype = False

html_theme = "alabaster"
html_title = "fenicsfriction"
html_theme_options = {"description": "Dynamic friction made computable with FEniCSx",
                      "fixed_sidebar": True}
html_sidebars = {"**": ["about.html", "navigation.html", "searchbox.html"]}


# ---- the demos as pages ------------------------------------------------------------------
# demos/demo_*.py are jupytext percent-format scripts: `# %% [markdown]` cells hold Markdown
# behind `# `, `# %%` cells hold code. Each becomes a MyST page under _generated/demos/.

def demo_page(script: pathlib.Path) -> str:
    """The MyST page of a percent-format script: Markdown cells as they are, code fenced."""
    text = script.read_text(encoding="utf-8")
    text = re.sub(r"\A# ---\n(?:#.*\n)*?# ---\n", "", text)  # jupytext's header
    cells = re.split(r"^# %%(.*)\n", text, flags=re.MULTILINE)
    parts = []
    for marker, body in zip(cells[1::2], cells[2::2], strict=True):
        if "[markdown]" in marker:
            parts.append("\n".join(re.sub(r"^# ?", "", line) for line in body.strip().splitlines()))
        elif body.strip():
            parts.append(f"````python\n{body.strip()}\n````")  # a cell may hold ```
    source = script.relative_to(ROOT).as_posix()
    parts.insert(1, f"*This page is the script `{source}`: run it with `python3 {source}` or "
                    f"`mpirun -n 2 python3 {source}`.*")
    return "\n\n".join(parts) + "\n"


def write_demo_pages() -> None:
    out = DOCS / "_generated" / "demos"
    out.mkdir(parents=True, exist_ok=True)
    for script in sorted((ROOT / "demos").glob("demo_*.py")):
        page = out / f"{script.stem}.md"
        text = demo_page(script)
        if not page.exists() or page.read_text(encoding="utf-8") != text:
            page.write_text(text, encoding="utf-8")  # unchanged pages keep their timestamps


write_demo_pages()


# ---- |x| in docstrings -------------------------------------------------------------------
# The docstrings write an absolute value or a norm as plain text, |λ| or |u̇_T − U_T|, which
# reStructuredText reads as a substitution reference. The project defines no substitutions, so
# an undefined one is put back as the text it was, before docutils reports it as missing.

from docutils import nodes  # noqa: E402
from sphinx.application import Sphinx  # noqa: E402
from sphinx.transforms import SphinxTransform  # noqa: E402


class AbsoluteValueBars(SphinxTransform):
    """An undefined ``|...|`` substitution reference is the plain text ``|...|``."""

    default_priority = 210  # before docutils resolves substitutions (220)

    def apply(self, **kwargs: object) -> None:
        defined = self.document.substitution_defs
        for ref in list(self.document.findall(nodes.substitution_reference)):
            if ref["refname"] not in defined and ref.astext() not in defined:
                ref.replace_self(nodes.Text(f"|{ref.astext()}|"))


def setup(app: Sphinx) -> None:
    app.add_transform(AbsoluteValueBars)
