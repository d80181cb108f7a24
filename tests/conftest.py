"""Shared fixtures: the paper's LQG setting and helpers."""

from __future__ import annotations

import numpy as np
import pytest

from rsmhp.experiments.lqg import LQGParams

PAPER = {"x0": 0.0, "a": 0.5, "r": 10.0, "target": 1.0, "sigma": 1.0}
PAPER_U = np.array([0.55, 0.17])


@pytest.fixture
def paper_params() -> LQGParams:
    return LQGParams(**PAPER)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)
