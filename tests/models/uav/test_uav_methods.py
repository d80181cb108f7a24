"""The UAV method registry (rsmhp.models.uav.methods) and the weighted planner cost.

* weighted cost: the compiled kernel against the numpy kernel with random weights (1e-12
  relative), its gradient against complex-step derivatives of a dense reference and against
  linearity in the weights; equal weights give the unweighted kernel's bits;
* registry: names, specs and job keys round-trip; the job keys are those that seeded every
  published number (a change would redraw every hypothesis); the config schema comes from
  the family modules; clashes are refused.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from rsmhp.models.uav import fused, methods
from rsmhp.models.uav.kernel import objective
from rsmhp.models.uav.methods import Hypotheses
from rsmhp.models.uav.planner import Belief
from rsmhp.models.uav.sensor import SensorModel
from rsmhp.models.uav.simulation import UAVSetup
from rsmhp.pipeline.config import check_config, load_schema
from rsmhp.report.palette import method_colour
from tests.models.uav.test_uav_fused import MODEL, SENSOR, UAV, _case, complex_step_grad

ROOT = Path(__file__).resolve().parents[3]
CONFIG = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
FOOTPRINT = SensorModel(0.05, 0.10, 100.0, footprint_radius=250.0, footprint_width=20.0)


def _weights(rng, n):
    return rng.dirichlet(np.full(n, 0.7))


@pytest.mark.parametrize("sensor", [SENSOR, FOOTPRINT], ids=["paper", "footprint"])
def test_weighted_value_equals_numpy_kernel(rng, sensor):
    from rsmhp.models.uav import kinematics

    x, state, P0, txy = _case(rng, n_t=7)
    xs = np.vstack([x, rng.uniform(-1, 1, (5, x.size))])
    w = _weights(rng, 7)
    ours = fused.cost(xs, state, UAV, P0, txy, MODEL.dt, MODEL.Q, sensor, weights=w)
    H = x.size // 2
    controls = (xs * np.tile(UAV.control_scale, H)).reshape(len(xs), H, 2)
    uxy = kinematics.rollout(state, controls, UAV)[..., :2]
    ref = objective(P0, uxy, txy, MODEL.dt, MODEL.Q, sensor, weights=w)
    np.testing.assert_allclose(ours, ref, rtol=1e-12, atol=0)


@pytest.mark.parametrize("sensor", [SENSOR, FOOTPRINT], ids=["paper", "footprint"])
def test_weighted_gradient_is_the_weighted_sum_of_hypothesis_gradients(rng, sensor):
    x, state, P0, txy = _case(rng, n_t=6)
    w = _weights(rng, 6)
    args = (state, UAV, P0)
    tail = (MODEL.dt, MODEL.Q, sensor)
    c, g = fused.cost_and_grad(x, *args, txy, *tail, weights=w)
    parts = [fused.cost_and_grad(x, *args, txy[i : i + 1], *tail) for i in range(6)]
    assert c[0] == pytest.approx(
        sum(wi * p[0][0] for wi, p in zip(w, parts, strict=True)), rel=1e-12
    )
    ref = sum(wi * p[1][0] for wi, p in zip(w, parts, strict=True))
    np.testing.assert_allclose(g[0], ref, rtol=0, atol=1e-12 * np.abs(ref).max())


def test_weighted_gradient_equals_complex_step(rng):
    x, state, P0, txy = _case(rng, n_t=4)
    w = _weights(rng, 4)
    _, g = fused.cost_and_grad(x, state, UAV, P0, txy, MODEL.dt, MODEL.Q, SENSOR, weights=w)
    ref = sum(
        wi * complex_step_grad(x, state, UAV, P0, txy[i : i + 1], MODEL, SENSOR)
        for i, wi in enumerate(w)
    )
    np.testing.assert_allclose(g[0], ref, rtol=0, atol=1e-9 * np.abs(ref).max())


def test_equal_weights_give_the_unweighted_bits(rng):
    x, state, P0, txy = _case(rng, n_t=9)
    plain = fused.cost_and_grad(x, state, UAV, P0, txy, MODEL.dt, MODEL.Q, SENSOR)
    equal = fused.cost_and_grad(
        x, state, UAV, P0, txy, MODEL.dt, MODEL.Q, SENSOR, weights=np.full(9, 1 / 9)
    )
    np.testing.assert_array_equal(plain[0], equal[0])
    np.testing.assert_array_equal(plain[1], equal[1])


def test_bad_weights_are_refused(rng):
    x, state, P0, txy = _case(rng, n_t=3)
    args = (x, state, UAV, P0, txy, MODEL.dt, MODEL.Q, SENSOR)
    with pytest.raises(ValueError, match=r"weights must sum to 1"):
        fused.cost(*args, weights=np.array([0.5, 0.5, 0.5]))
    with pytest.raises(ValueError, match=r"weights must be >= 0"):
        fused.cost(*args, weights=np.array([1.5, -0.25, -0.25]))
    with pytest.raises(ValueError, match=r"weights must have shape \(3,\)"):
        fused.cost(*args, weights=np.array([0.5, 0.5]))
    with pytest.raises(ValueError, match=r"Hypotheses\.weights must be finite, >= 0"):
        Hypotheses(np.zeros((2, 3, 4)), np.array([0.9, 0.2]))
    with pytest.raises(ValueError, match=r"Hypotheses\.noise must have shape"):
        Hypotheses.equal(np.zeros((2, 3, 4)), np.zeros((2, 3, 4)))


# ---------------------------------------------------------------------------- registry


def _all_blocks():
    dec = CONFIG["decisions"]
    return {
        "uav.methods": CONFIG["uav"]["methods"],
        "decisions.uav.methods": dec["uav"]["methods"],
        "decisions.map.methods": dec["map"]["methods"],
    }


def test_families_and_the_published_job_keys():
    # this repository's families (an installed plugin package, e.g. the example, adds its own)
    assert [c.family for c in methods.families() if c.__module__.startswith("rsmhp.")] == [
        "nbo",
        "rsmhp",
        "rsmhp_per_step",
        "tree",
        "rqmc",
        "antithetic",
        "sigma",
        "dpw",
        "pursuit",
    ]
    assert methods.baseline().family == "nbo"
    got = methods.from_config(CONFIG["uav"]["methods"], "uav.methods")
    assert list(got) == ["nbo", "rsmhp_nt50", "rsmhp_nt100", "rsmhp_nt250", "tree_n8_m100"]
    # the random-stream keys of every published run (changing them redraws everything)
    assert got["nbo"].job_key() == {"method": "nbo", "N_T": 1, "N": None, "M": None}
    assert got["rsmhp_nt250"].job_key() == {
        "method": "rsmhp_nt250",
        "N_T": 250,
        "N": None,
        "M": None,
    }
    assert got["tree_n8_m100"].job_key() == {"method": "tree_n8_m100", "N_T": 100, "N": 8, "M": 100}
    assert got["tree_n8_m100"].columns() == {"N_T": 100, "N": 8, "M": 100}


@pytest.mark.parametrize("block", list(_all_blocks()))
def test_names_and_specs_round_trip(block):
    for name, m in methods.from_config(_all_blocks()[block], block).items():
        assert methods.from_name(name) == m
        assert methods.from_spec(m.spec()) == m
        assert m.label() and method_colour(m.name).startswith("#")


def test_schema_comes_from_the_family_modules():
    schema = load_schema()
    props = schema["$defs"]["uav_methods"]["properties"]
    assert set(props) == {c.config_key for c in methods.families()}
    assert props["rsmhp_nt"] is methods.from_name("rsmhp_nt5").schema
    raw = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    text = yaml.safe_dump(raw["$defs"])
    for c in methods.families():  # the schema file names no family
        assert f"{c.config_key}:" not in text


def test_unknown_family_key_is_a_config_error():
    from rsmhp.pipeline.config import ConfigError

    cfg = copy.deepcopy(CONFIG)
    cfg["uav"]["methods"]["qmc"] = [16]
    with pytest.raises(ConfigError, match=r"uav\.methods\.qmc: unknown key"):
        check_config(cfg)


def test_a_second_family_with_a_taken_key_is_refused():
    from rsmhp.models.uav.methods.monte_carlo import MonteCarlo

    class Clash(MonteCarlo):
        family = "clash"
        config_key = "rsmhp_nt"  # derived from family ("clash_nt") unless written

    with pytest.raises(ValueError, match=r"clashes with the registered MonteCarlo"):
        methods.register(Clash)


def test_every_family_draws_valid_hypotheses(rng):
    setup = UAVSetup.from_config(CONFIG["uav"])
    belief = Belief(np.array([0.0, 0.0, 20.0, 0.0]), np.array([300.0, 0, 5, 0]), setup.P0)
    H = setup.planner.horizon
    for m in methods.from_config(CONFIG["uav"]["methods"]).values():
        hyp = m.hypotheses(belief, setup, np.random.default_rng(3))
        assert hyp.states.shape == (m.n_traj, H, 4)
        assert math.isclose(hyp.weights.sum(), 1.0, rel_tol=1e-12)
        if hyp.noise is not None:  # the draws reproduce the states
            F = setup.target.F
            x = belief.x_hat + hyp.noise[:, 0]
            for j in range(H):
                x = x @ F.T + hyp.noise[:, j + 1]
                np.testing.assert_allclose(hyp.states[:, j], x, rtol=1e-12, atol=1e-9)


def test_monte_carlo_per_step_draws_k_h_independent_futures():
    """rsmhp_nt<k>h: N_T = k H hypotheses at every horizon, equal weights, the Monte-Carlo
    draw (same stream gives the same futures as rsmhp_nt<kH>), its own stream key."""
    from rsmhp.models.uav.methods.monte_carlo_per_step import MonteCarloPerStep

    m = methods.from_config({"rsmhp_nt_per_step": [3]}, "x")["rsmhp_nt3h"]
    assert isinstance(m, MonteCarloPerStep) and m.name == "rsmhp_nt3h"
    assert methods.from_name("rsmhp_nt3h") == m and methods.from_spec(m.spec()) == m
    assert methods.from_name("rsmhp_nt3").family == "rsmhp"  # the fixed-N_T family keeps its names
    assert m.columns() == {"N_T": 0, "N": 0, "M": 0}
    assert m.job_key()["per_step"] == 3 and m.job_key()["method"] == "rsmhp_nt3h"
    belief = Belief(np.array([0.0, 0.0, 20.0, 0.0]), np.array([300.0, 0, 5, 0]), np.eye(4))
    for H in (2, 5):
        cfg = copy.deepcopy(CONFIG["uav"])
        cfg["planner"]["horizon"] = H
        setup = UAVSetup.from_config(cfg)
        hyp = m.hypotheses(belief, setup, np.random.default_rng(7))
        assert hyp.states.shape == (3 * H, H, 4) and m.n_traj_at(H) == 3 * H
        np.testing.assert_array_equal(hyp.weights, np.full(3 * H, 1 / (3 * H)))
        fixed = methods.from_name(f"rsmhp_nt{3 * H}").hypotheses(
            belief, setup, np.random.default_rng(7)
        )
        np.testing.assert_array_equal(hyp.states, fixed.states)
    with pytest.raises(ValueError, match=r"x\.rsmhp_nt_per_step\[0\] must be >= 1, got 0"):
        methods.from_config({"rsmhp_nt_per_step": [0]}, "x")
    assert methods.sort_names(["rsmhp_nt3h", "rsmhp_nt500", "nbo"]) == [
        "nbo",
        "rsmhp_nt500",
        "rsmhp_nt3h",
    ]
