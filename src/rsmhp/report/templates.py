"""Report prose as Markdown templates (Jinja2) beside each study's code.

A study's section text lives in ``src/rsmhp/studies/<study>/*.md``, filled with generated values
and tables by :func:`render`; no sentence of a section is split across Python string literals
(the claims' own texts, in the ledger, are still written in each study's ``claims`` module).
The templates are part of the code a rule depends on: :mod:`rsmhp.pipeline.code_digest` counts
a ``*.md`` file beside a module as code of the modules that name it (``render(...,
"section.md")``), so an edit of the prose reruns the rules that render it and no simulation (a
study's ``simulate`` modules render no template).

Template conventions: ``{{ value }}`` inserts a preformatted string (numbers are formatted in
Python with :mod:`rsmhp.report.markdown`, not in the template); ``{% if %}`` / ``{% for %}``
blocks sit on lines of their own (``trim_blocks`` and ``lstrip_blocks`` remove those lines);
an undefined name is an error, never an empty string.
"""

from __future__ import annotations

from functools import cache
from typing import Any

import jinja2

__all__ = ["render"]


@cache
def _environment(package: str) -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.PackageLoader(package, ""),
        undefined=jinja2.StrictUndefined,
        autoescape=False,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
    )


def render(package: str, template: str, /, **values: Any) -> str:
    """The template ``template`` (a file name, e.g. ``"section.md"``) of the package
    ``package`` (e.g. ``"rsmhp.studies.lqg"``), filled with ``values``. A name the template
    uses but ``values`` lacks raises :class:`jinja2.UndefinedError` naming it."""
    return _environment(package).get_template(template).render(**values)
