"""Claims as data (rsmhp.report.claimspec) and the words of templates (rsmhp.report.templates)."""

from __future__ import annotations

import pytest

from rsmhp.report.claimspec import ClaimSpec, Evidence
from rsmhp.report.ledger import KeyNumber
from rsmhp.report.templates import CONTINUATION, Words
from rsmhp.report.verdicts import at_most

WORDS = Words("tests.report", "claims_fixture.md")
RULE = at_most("mean", 1.0, limit_text="1")


def _evidence(mean: float, model: str = "paper") -> Evidence:
    return Evidence(
        key=KeyNumber("mean", mean),
        facts={"mean": mean},
        values={"mean": f"{mean:.2f}", "n": "12", "model": model},
    )


def test_continuation_joins_lines_with_one_space() -> None:
    assert CONTINUATION.sub(" ", "a \\\n    b\\\nc\nd") == "a b c\nd"


def test_words_one_line_per_macro() -> None:
    assert WORDS("demo_1_claim", model="M") == "The demo mean is below one on M"
    assert WORDS("demo_1_measured", mean="0.5", n="3") == "mean 0.5 m over 3 runs"
    assert "demo_1_paper" in WORDS and "demo_2_paper" not in WORDS


def test_words_errors_name_the_macro() -> None:
    with pytest.raises(KeyError, match="demo_9_claim"):
        WORDS("demo_9_claim")
    with pytest.raises(ValueError, match="two_lines"):
        WORDS("two_lines")
    with pytest.raises(TypeError, match="colour"):
        WORDS("demo_1_paper", colour="red")
    # a value the macro uses but is not given is an error, never an empty string
    with pytest.raises(KeyError, match="model"):
        WORDS("demo_1_claim")


@pytest.mark.parametrize(
    ("mean", "verdict"), [(0.5, "supported"), (1.0, "supported"), (1.5, "not supported")]
)
def test_spec_builds_the_claim(mean: float, verdict: str) -> None:
    spec = ClaimSpec(id="DEMO-1", setup="demo model", evidence=_evidence, words=WORDS, rule=RULE)
    claim = spec.build(mean, model="variant")
    assert claim.id == "DEMO-1"
    assert claim.verdict == verdict
    assert claim.rule == RULE.text()
    assert claim.claim == "The demo mean is below one on variant"
    assert claim.paper == "Sec. 0: the mean is small"
    assert claim.measured == f"mean {mean:.2f} m over 12 runs"
    assert claim.dropped == "" and claim.contrary == ""  # no macro: the default


def test_spec_with_fields_fills_id_and_setup() -> None:
    spec = ClaimSpec(
        id="DEMO-1-{model}",
        setup="demo {model}",
        evidence=_evidence,
        words=WORDS,
        rule=RULE,
        texts="demo_1",
    )
    claim = spec.build(0.2, model="wide")
    assert (claim.id, claim.setup) == ("DEMO-1-wide", "demo wide")
    with pytest.raises(ValueError, match="texts"):
        ClaimSpec(id="DEMO-1-{model}", setup="s", evidence=_evidence, words=WORDS, rule=RULE)


def test_spec_without_rule_is_refused() -> None:
    spec = ClaimSpec(id="DEMO-1", setup="s", evidence=_evidence, words=WORDS)
    with pytest.raises(ValueError, match="rule"):
        spec.build(0.5)
    ev = _evidence(0.5)
    ev2 = Evidence(key=ev.key, facts=ev.facts, values=ev.values, rule=RULE)
    assert spec.claim(ev2).verdict == "supported"


def test_missing_value_names_it() -> None:
    def bare(mean: float) -> Evidence:
        return Evidence(key=KeyNumber("mean", mean), facts={"mean": mean}, values={"model": "x"})

    spec = ClaimSpec(id="DEMO-1", setup="s", evidence=bare, words=WORDS, rule=RULE)
    with pytest.raises(KeyError, match="mean"):
        spec.build(0.5)
