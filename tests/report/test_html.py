"""The HTML report's landing page (rsmhp.report.html)."""

from __future__ import annotations

import base64

import pytest

from rsmhp.report.html import inline_markdown, summary_fragment

PNG = base64.b64decode(
    "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJggg=="
)


def test_inline_markdown_escapes_and_drops_appendix_links():
    assert inline_markdown("**S1** is <b> [UAV-1](appendix.md#uav-1) & more") == (
        "<b>S1</b> is &lt;b&gt; UAV-1 &amp; more"
    )


def test_fragment_has_the_sentences_and_the_figure(tmp_path):
    fig = tmp_path / "f.png"
    fig.write_bytes(PNG)
    out = summary_fragment("1. First [A-1](appendix.md#a-1).\n\n2. **Second**.", fig, "cap")
    assert out.count("<li>") == 2 and "<li>First A-1.</li>" in out and "<b>Second</b>" in out
    assert f"data:image/png;base64,{base64.b64encode(PNG).decode()}" in out
    assert "<html" not in out and "<style" not in out and "<i>cap</i>" in out
    assert "<img" not in summary_fragment("1. Only text.", None)
    with pytest.raises(ValueError, match="no numbered sentence"):
        summary_fragment("no list here", None)
