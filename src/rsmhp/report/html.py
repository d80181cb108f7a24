"""The landing page of the HTML report (``snakemake --report``): "What we found" and the summary
figure as one HTML fragment, the same text the main text opens with.

Snakemake's report opens on the text of the global ``report:`` file
(``workflow/report/workflow.rst``), which pulls this fragment in with ``.. raw:: html`` and
``:file:``. It must be a fragment (no ``<html>``/``<head>``/``<style>`` of its own: those would
restyle the whole report) with the figure as a data URI (the report's own image embedding does
not run on that page), and the base64 text must not pass through the reStructuredText parser
(its 10,000-character line limit), which ``:file:`` avoids.
"""

from __future__ import annotations

import base64
import html
import os
import re
from pathlib import Path

__all__ = ["inline_markdown", "summary_fragment"]

_LINK = re.compile(r"\[([^\]]+)\]\([^)]+\)")
_BOLD = re.compile(r"\*\*(.+?)\*\*")
_ITEM = re.compile(r"^\d+\.\s+")


def inline_markdown(text: str) -> str:
    """HTML of one line of the report's Markdown: escaped, ``**bold**`` in ``<b>``, links to
    the Markdown appendix reduced to their text (the appendix is not part of the HTML
    report)."""
    out = html.escape(text, quote=False)
    out = _LINK.sub(r"\1", out)
    return _BOLD.sub(r"<b>\1</b>", out)


def summary_fragment(
    findings: str, figure: str | os.PathLike | None, caption: str = "", title: str = ""
) -> str:
    """The landing page's fragment: ``title``, "What we found" (``findings``: the numbered
    Markdown sentences of the main text) as an ordered list, and the PNG ``figure`` (if
    given) as a data URI with its ``caption``."""
    items = [_ITEM.sub("", line).strip() for line in findings.splitlines() if _ITEM.match(line)]
    if not items:
        raise ValueError("findings: no numbered sentence ('1. ...') to show")
    parts = ['<div style="font-family:sans-serif;line-height:1.45">']
    if title:
        parts.append(f"<h1>{html.escape(title)}</h1>")
    parts.append("<h2>What we found</h2>")
    parts.append("<ol>" + "".join(f"<li>{inline_markdown(i)}</li>" for i in items) + "</ol>")
    if figure is not None:
        data = base64.b64encode(Path(figure).read_bytes()).decode("ascii")
        parts.append(
            f'<img style="max-width:100%" alt="summary figure" src="data:image/png;base64,{data}">'
        )
        if caption:
            parts.append(f"<p><i>{inline_markdown(caption)}</i></p>")
    parts.append("</div>")
    return "\n".join(parts) + "\n"
