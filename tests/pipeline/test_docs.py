"""The documentation stays navigable: the README is short, and every relative link of the README
and of docs/*.md (and config/README.md) points to a file that exists, and to a heading that
exists where the link names one of a Markdown file."""

from __future__ import annotations

import re
from pathlib import Path
from urllib.parse import unquote

ROOT = Path(__file__).resolve().parents[2]
DOCS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md")), ROOT / "config" / "README.md"]

#: ``[text](target)`` outside code; the target up to the first space or closing parenthesis
LINK = re.compile(r"(?<!!)\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
FENCE = re.compile(r"^```.*?^```", flags=re.M | re.S)
CODE = re.compile(r"`[^`\n]*`")


def _links(text: str) -> list[str]:
    """Link targets of Markdown ``text``; fenced blocks and code spans are not Markdown (a code
    span is replaced by a placeholder, so ``[`x`](y)`` stays a link and ``[a](b)`` inside a code
    span is none)."""
    return LINK.findall(CODE.sub("x", FENCE.sub("", text)))


def _slug(title: str) -> str:
    """GitHub's anchor of a heading: lower case, punctuation other than ``-`` and ``_`` dropped,
    each space a ``-``."""
    return re.sub(r"[^\w\- ]", "", title.lower()).replace(" ", "-")


def _anchors(path: Path) -> set[str]:
    """The anchors of the headings of a Markdown file."""
    text = FENCE.sub("", path.read_text(encoding="utf-8"))
    return {_slug(t) for t in re.findall(r"^#{1,6}\s+(.+?)\s*$", text, flags=re.M)}


def _is_relative(target: str) -> bool:
    return not re.match(r"^[a-z][a-z0-9+.-]*:", target, flags=re.I) and not target.startswith("/")


def test_readme_is_at_most_250_lines():
    lines = (ROOT / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 250, f"README.md: {len(lines)} lines (at most 250; move detail to docs/)"


def test_every_relative_link_of_the_docs_points_to_an_existing_file():
    assert (ROOT / "docs").is_dir() and len(DOCS) > 3
    broken = []
    for doc in DOCS:
        for target in _links(doc.read_text(encoding="utf-8")):
            if not _is_relative(target):
                continue
            file, _, anchor = target.partition("#")
            dest = (doc.parent / unquote(file)).resolve() if file else doc
            where = f"{doc.relative_to(ROOT)}: {target}"
            if not dest.exists():
                broken.append(f"{where} (no such file)")
            elif anchor and dest.suffix == ".md" and anchor not in _anchors(dest):
                broken.append(f"{where} (no heading #{anchor} in {dest.relative_to(ROOT)})")
    assert not broken, "\n".join(broken)


def test_the_link_checker_sees_links_and_anchors():
    """The checker's parts on known text: links outside code, GitHub's heading anchors."""
    text = "see [a](docs/a.md#b-c) and `[not](x.md)`, [`code`](y.md)\n```\n[no](z.md)\n```\n"
    assert _links(text) == ["docs/a.md#b-c", "y.md"]
    assert not _is_relative("https://example.org/x") and _is_relative("../x.md")
    assert _slug("Reproducibility and `make verify`") == "reproducibility-and-make-verify"
    assert _slug("Portability drill: `make portability`") == "portability-drill-make-portability"
    assert _slug("Tracked files: `make publish`") in _anchors(ROOT / "docs/outputs.md")
