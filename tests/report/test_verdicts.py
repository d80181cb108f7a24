"""Verdict rules (rsmhp.report.verdicts): text and evaluation from one definition, boundaries."""

import pytest

from rsmhp.report.verdicts import Case, Rule, at_most, ci_side, non_inferior


def test_at_most_boundary_is_supported_and_text_names_the_limit():
    rule = at_most("max |z|", 2.5, limit_text="2.5 (Bonferroni)", basis="z per cell")
    assert rule.verdict({"max |z|": 2.5}) == "supported"
    assert rule.verdict({"max |z|": 2.5000001}) == "not supported"
    assert rule.verdict({"max |z|": -1.0}) == "supported"
    assert rule.text() == (
        "z per cell: supported if max |z| ≤ 2.5 (Bonferroni); not supported otherwise"
    )


@pytest.mark.parametrize(
    ("low", "high", "claimed", "verdict"),
    [
        (-2.0, -0.1, "below", "supported"),
        (-2.0, 0.0, "below", "inconclusive"),  # CI touching the null does not exclude it
        (0.0, 1.0, "below", "inconclusive"),
        (0.1, 1.0, "below", "not supported"),
        (0.1, 1.0, "above", "supported"),
        (-1.0, -0.1, "above", "not supported"),
        (-1.0, 1.0, "above", "inconclusive"),
    ],
)
def test_ci_side_on_and_off_the_null(low, high, claimed, verdict):
    rule = ci_side("d", 0.0, claimed=claimed)
    assert rule.verdict({"d_low": low, "d_high": high}) == verdict


def test_ci_side_text_lists_every_case_in_order():
    text = ci_side("d", 0.0, claimed="below", null_text="0 m", basis="paired d").text()
    assert text == (
        "paired d: supported if the 95% CI of d lies entirely below 0 m; not supported if it "
        "lies entirely above 0 m; inconclusive otherwise"
    )


def test_first_matching_case_wins_and_otherwise_applies():
    rule = Rule(
        cases=(
            Case("supported", "x > 1", lambda f: f["x"] > 1),
            Case("not supported", "x > 0", lambda f: f["x"] > 0),
        ),
        otherwise="inconclusive",
    )
    assert [rule.verdict({"x": v}) for v in (2, 1, 0)] == [
        "supported",
        "not supported",
        "inconclusive",
    ]
    assert rule.text().startswith("Supported if x > 1; not supported if x > 0")


def test_bad_definitions_are_refused():
    with pytest.raises(ValueError, match="verdict must be one of"):
        Case("maybe", "x", lambda f: True)
    with pytest.raises(ValueError, match="at least one Case"):
        Rule(cases=(), otherwise="inconclusive")
    with pytest.raises(ValueError, match="claimed must be"):
        ci_side("d", 0.0, claimed="sideways")


# --------------------------------------------------------------- equivalence margin


@pytest.mark.parametrize(
    ("low", "high", "verdict"),
    [
        (-0.1, 0.1, "equivalent"),  # inside ±0.25: any difference is below the margin
        (-0.2, -0.05, "equivalent"),  # significant but negligible: still not the effect
        (-0.25, 0.1, "inconclusive"),  # touches the margin: a difference of m is possible
        (-0.4, -0.3, "supported"),  # beyond the margin on the claimed side
        (-0.4, -0.01, "supported"),
        (0.05, 0.3, "not supported"),
        (-0.3, 0.3, "inconclusive"),
    ],
)
def test_ci_side_with_a_margin(low, high, verdict):
    rule = ci_side("d", 0.0, claimed="below", margin=0.25, margin_text="0.25 m")
    assert rule.verdict({"d_low": low, "d_high": high}) == verdict
    assert rule.verdicts == ("equivalent", "supported", "not supported", "inconclusive")
    assert rule.text().startswith("Equivalent if the 95% CI of d lies inside ±0.25 m;")


def test_ci_side_margin_around_a_nonzero_null_and_bad_margins():
    rule = ci_side("f", 1.0, claimed="above", margin=0.1)
    assert rule.verdict({"f_low": 0.95, "f_high": 1.05}) == "equivalent"
    assert rule.verdict({"f_low": 1.2, "f_high": 1.3}) == "supported"
    assert "inside 1 ± 0.1" in rule.text()
    for bad in (0.0, -1.0, "0.1"):
        with pytest.raises(ValueError, match="margin"):
            ci_side("f", 0.0, claimed="above", margin=bad)


@pytest.mark.parametrize(
    ("low", "high", "verdict"),
    [
        (-0.5, -0.2, "supported"),  # better than the reference: no worse than m either
        (-0.05, 0.099, "supported"),
        (0.02, 0.08, "supported"),  # significantly worse, but by less than m
        (-0.05, 0.1, "inconclusive"),  # upper limit on the margin: not below it
        (0.05, 0.3, "inconclusive"),
        (0.1, 0.3, "inconclusive"),  # lower limit on the margin: not above it
        (0.11, 0.3, "not supported"),
    ],
)
def test_non_inferior_boundaries_at_the_margin(low, high, verdict):
    rule = non_inferior("d", 0.1, margin_text="0.1 pp")
    assert rule.verdict({"d_low": low, "d_high": high}) == verdict


def test_non_inferior_text_and_bad_margin():
    text = non_inferior("d", 0.1, margin_text="0.1 pp", basis="paired d").text()
    assert text == (
        "paired d: supported if the 95% CI of d lies entirely below +0.1 pp (at most 0.1 pp "
        "worse); not supported if it lies entirely above +0.1 pp; inconclusive otherwise"
    )
    for bad in (0.0, -1.0, "0.1", None):
        with pytest.raises(ValueError, match="margin must be a number > 0"):
            non_inferior("d", bad, margin_text="x")


# ------------------------------------------------------------ p-values and Holm's correction


def test_decisive_p_is_below_005_exactly_when_the_t_interval_excludes_the_boundary():
    import numpy as np
    from scipy import stats as st

    from rsmhp.report.verdicts import decisive_p

    rng = np.random.default_rng(3)
    for _ in range(300):
        est, se, df = rng.normal(0, 1), rng.uniform(0.05, 1), int(rng.integers(2, 60))
        half = st.t.ppf(0.975, df) * se
        lo, hi = est - half, est + half
        assert (decisive_p("supported", est, se, df, [(0.0, "above")]) < 0.05) == (lo > 0)
        assert (decisive_p("supported", est, se, df, [(0.0, "below")]) < 0.05) == (hi < 0)
        m = abs(rng.normal(0, 1))
        peq = decisive_p("equivalent", est, se, df, [(-m, "above"), (m, "below")])
        assert (peq < 0.05) == (-m < lo and hi < m)
    assert decisive_p("supported", 1.0, 0.0, 5, [(0.0, "above")]) == 0.0
    assert decisive_p("supported", 1.0, 0.0, 5, [(0.0, "below")]) == 1.0
    with pytest.raises(ValueError, match="boundaries"):
        decisive_p("supported", 1.0, 0.1, 5, [])


def _claim(cid: str, verdict: str, p: float | None):
    from rsmhp.report.ledger import Claim, KeyNumber

    key = KeyNumber("d", 1.0, 0.5, 1.5, reproducible="statistical", null=0.0, p_value=p)
    return Claim(cid, "c", "p", key, verdict, "rule text", part="beyond")


def test_holm_correct_downgrades_what_the_family_no_longer_rejects():
    from rsmhp.core.stats import holm
    from rsmhp.report.verdicts import holm_correct

    claims = [
        _claim("FR-1-a", "supported", 0.001),
        _claim("FR-2-a", "equivalent", 0.03),
        _claim("HZ-1-a", "not supported", 0.02),
        _claim("HZ-3-a", "inconclusive", 0.4),
        _claim("UAV-1", "supported", 0.04),  # outside the family: untouched
        _claim("FR-9-a", "supported", None),  # no p-value: untouched
    ]
    out = holm_correct(claims)
    adj = holm([0.001, 0.03, 0.02, 0.4])
    assert [c.key.p_holm for c in out[:4]] == pytest.approx(list(adj))
    kept = ["supported", "equivalent", "not supported"]
    want = [v if a < 0.05 else "inconclusive" for v, a in zip(kept, adj, strict=False)]
    want.append("inconclusive")
    assert [c.verdict for c in out[:4]] == want
    assert out[1].verdict == "inconclusive" and "becomes inconclusive" in out[1].rule
    assert out[4] == claims[4] and out[5] == claims[5]
    assert holm_correct([claims[4]]) == [claims[4]]


def test_holm_sections_corrects_across_sections_and_keeps_their_claims():
    from rsmhp.report.ledger import Section
    from rsmhp.report.verdicts import holm_correct, holm_sections

    a = Section(
        "a", "A", 1, "", [_claim("FR-1-x", "supported", 0.03), _claim("X-1", "supported", None)]
    )
    b = Section("b", "B", 2, "", [_claim("HZ-1-x", "supported", 0.04)])
    out = holm_sections([a, b])
    want = holm_correct([*a.claims, *b.claims])
    assert [c.id for c in out[0].claims] == ["FR-1-x", "X-1"] and out[0].title == "A"
    assert [*out[0].claims, *out[1].claims] == want
    assert out[1].claims[0].verdict == "inconclusive"  # 2 x 0.03 = 0.06, then max(0.06, 0.04)
