"""Shared fixtures: the paper's LQG setting and helpers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from rsmhp.models.lqg.oven import LQGModel

PAPER = {"x0": 0.0, "a": 0.5, "r": 10.0, "target": 1.0, "sigma": 1.0}
PAPER_U = np.array([0.55, 0.17])


@pytest.fixture
def paper_params() -> LQGModel:
    return LQGModel(**PAPER)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)


@pytest.fixture(scope="session")
def run_j2(tmp_path_factory) -> Path:
    """The whole workflow (LQG, UAV, report) on the tiny config with -j2, run once per session."""
    from tests.pipeline.test_workflow import snakemake

    wd = tmp_path_factory.mktemp("wf_j2")
    res = snakemake(wd, "-j2")
    assert res.returncode == 0, res.stderr[-3000:]
    return wd


@pytest.fixture(scope="session")
def tiny() -> dict:
    """The tiny workflow config (tests/config/tiny.yaml) as a dict."""
    import yaml

    from tests.pipeline.test_workflow import TINY

    return yaml.safe_load(TINY.read_text())
