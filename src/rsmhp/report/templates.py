"""Report prose as Markdown templates (Jinja2) beside each study's code.

A study's section text lives in ``src/rsmhp/studies/<study>/*.md``, filled with generated values
and tables by :func:`render`; no sentence of a section is split across Python string literals,
and a claim's texts in the ledger are macros of the study's ``claims*.md`` (:class:`Words`,
:mod:`rsmhp.report.claimspec`).
The templates are part of the code a rule depends on: :mod:`rsmhp.pipeline.code_digest` counts
a ``*.md`` file beside a module as code of the modules that name it (``render(...,
"section.md")``), so an edit of the prose reruns the rules that render it and no simulation (a
study's ``simulate`` modules render no template).

Template conventions: a line ending in a backslash continues on the next line (the
backslash, the line break and the next line's leading blanks become one space), so that a long
paragraph is written on short lines a diff can show and still renders as one line; ``{{ value
}}`` inserts a preformatted string (numbers are formatted in Python with
:mod:`rsmhp.report.markdown`, not in the template); ``{% if %}`` / ``{% for %}`` blocks sit on
lines of their own (``trim_blocks`` and ``lstrip_blocks`` remove those lines); an undefined
name is an error, never an empty string. A claim's sentences are macros of a ``claims.md``
template (:class:`Words`, :mod:`rsmhp.report.claimspec`).
"""

from __future__ import annotations

import re
from functools import cache
from typing import Any

import jinja2
import jinja2.ext

__all__ = ["CONTINUATION", "Words", "render"]

#: a line continuation in a template: a backslash at the end of a line (before the line
#: break), the line break and the next line's leading blanks; it renders as one space
CONTINUATION = re.compile(r"[ \t]*\\\n[ \t]*")


class _Continuation(jinja2.ext.Extension):
    """Join continued lines (:data:`CONTINUATION`) before Jinja parses the template."""

    def preprocess(self, source: str, name: str | None, filename: str | None = None) -> str:
        return CONTINUATION.sub(" ", source)


@cache
def _environment(package: str) -> jinja2.Environment:
    return jinja2.Environment(
        loader=jinja2.PackageLoader(package, ""),
        undefined=jinja2.StrictUndefined,
        autoescape=False,
        keep_trailing_newline=True,
        trim_blocks=True,
        lstrip_blocks=True,
        extensions=[_Continuation],
    )


def render(package: str, template: str, /, **values: Any) -> str:
    """The template ``template`` (a file name, e.g. ``"section.md"``) of the package
    ``package`` (e.g. ``"rsmhp.studies.lqg"``), filled with ``values``. A name the template
    uses but ``values`` lacks raises :class:`jinja2.UndefinedError` naming it."""
    return _environment(package).get_template(template).render(**values)


class Words:
    """The sentences of a study's claims: the Jinja macros of one template file beside the
    study's code (e.g. ``src/rsmhp/studies/lqg/claims.md``), one macro per text, called with the
    preformatted values it names::

        {% macro lqg_1_claim(P) %}
        In the oven LQG at P = {{ P }}, \\
        NBO's error is ...
        {% endmacro %}

    ``Words("rsmhp.studies.lqg", "claims.md")("lqg_1_claim", P="100")`` gives the macro's text
    on one line: its trailing line break is dropped, continued lines are joined
    (:data:`CONTINUATION`), and any other line break is an error (a claim's texts are single
    lines in the ledger). A macro the template lacks, or a value it uses but is not given,
    raises an error naming it."""

    def __init__(self, package: str, template: str) -> None:
        self.package = package
        self.template = template

    @property
    def _module(self) -> Any:
        return _environment(self.package).get_template(self.template).module

    def __contains__(self, name: str) -> bool:
        return callable(getattr(self._module, name, None))

    def __call__(self, name: str, /, **values: Any) -> str:
        macro = getattr(self._module, name, None)
        if not callable(macro):
            raise KeyError(f"{self.package}/{self.template}: no macro {name!r}")
        unknown = sorted(set(values) - set(macro.arguments))
        if unknown and not macro.catch_kwargs:
            raise TypeError(
                f"{self.package}/{self.template}: macro {name!r} takes "
                f"{list(macro.arguments)}, not {unknown}"
            )
        try:
            text = str(macro(**values))
        except jinja2.UndefinedError as exc:
            raise KeyError(f"{self.package}/{self.template}: macro {name!r}: {exc}") from exc
        text = text.removesuffix("\n")
        if "\n" in text:
            raise ValueError(
                f"{self.package}/{self.template}: macro {name!r} gives more than one line; "
                "end a line with a backslash to continue it"
            )
        return text
