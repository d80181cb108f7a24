"""UAV model variants (sensor footprint with detection probability, quadratic noise growth):
the compiled kernel and its gradient against the numpy kernel, a complex-step dense
reference and filterpy; the truth simulation's missed detections; and the paper's model
unchanged by the variant code."""

from __future__ import annotations

import copy
import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from filterpy.kalman import KalmanFilter

from rsmhp.models.uav import fused, kinematics
from rsmhp.models.uav import methods as uav_methods
from rsmhp.models.uav.kernel import covariance_traces, objective
from rsmhp.models.uav.kinematics import UAVParams
from rsmhp.models.uav.sensor import SensorModel, detected, detection_probability
from rsmhp.models.uav.simulation import UAVSetup, simulate_run
from rsmhp.models.uav.target import TargetModel
from rsmhp.models.uav.tracker import MEASUREMENT_MATRIX

ROOT = Path(__file__).resolve().parents[3]
UAV = UAVParams(
    dt=1.0, g=9.81, accel_max=3.0, bank_max=math.pi / 4, speed_min=10, speed_max=35, altitude=100
)
MODEL = TargetModel(1.0, 1.0)
BASE = SensorModel(0.05, 0.10, 100.0)
VARIANTS = {
    "quadratic": dataclasses.replace(BASE, noise_growth="quadratic", reference_distance=150.0),
    "footprint": dataclasses.replace(BASE, footprint_radius=250.0, footprint_width=40.0),
    "both": dataclasses.replace(
        BASE, noise_growth="quadratic", footprint_radius=200.0, footprint_width=25.0
    ),
}


def dense_reference(x, state, P0, target_xy, sensor):
    """Planner cost with dense 4x4 algebra for any dtype (complex step): R from its
    definition with the variant's distance factor, expected update P - p_d K S K^T with the
    logistic p_d."""
    H = len(x) // 2
    F, Q, Hm = MODEL.F, MODEL.Q, MEASUREMENT_MATRIX
    px, py, s, psi = (state[k] + 0 * x[0] for k in range(4))
    positions = []
    for j in range(H):
        v = s + UAV.accel_max * x[2 * j] * UAV.dt
        v = (
            min(max(v.real, UAV.speed_min), UAV.speed_max) + 0 * v
            if not (UAV.speed_min < v.real < UAV.speed_max)
            else v
        )
        psi = psi + UAV.g * np.tan(UAV.bank_max * x[2 * j + 1]) / s * UAV.dt
        s = v
        px = px + s * UAV.dt * np.cos(psi)
        py = py + s * UAV.dt * np.sin(psi)
        positions.append((px, py))
    total = 0
    for i in range(target_xy.shape[0]):
        P = P0.astype(complex if np.iscomplexobj(x) else float)
        for j in range(H):
            dx = target_xy[i, j, 0] - positions[j][0]
            dy = target_xy[i, j, 1] - positions[j][1]
            rho = np.sqrt(dx * dx + dy * dy)
            c, sn = dx / rho, dy / rho
            d2 = rho * rho + sensor.altitude**2
            scale = (
                d2 * d2 / sensor.reference_distance**2 if sensor.noise_growth == "quadratic" else d2
            )
            G = np.array([[c, -sn], [sn, c]])
            R = G @ np.diag([sensor.sigma_r_per_m**2, sensor.sigma_c_per_m**2]) @ G.T * scale
            pd = 1.0
            if sensor.limited:
                pd = 1.0 / (1.0 + np.exp((rho - sensor.footprint_radius) / sensor.footprint_width))
            P = F @ P @ F.T + Q
            S = Hm @ P @ Hm.T + R
            P = P - pd * (P @ Hm.T @ np.linalg.solve(S, Hm @ P))
            total = total + np.trace(P)
    return total / target_xy.shape[0]


def _case(rng, n_t=4, H=5):
    A = rng.standard_normal((4, 4))
    P0 = np.diag([900.0, 900.0, 16.0, 16.0]) + 5 * A @ A.T
    state = np.array([*rng.uniform(-50, 50, 2), rng.uniform(12, 33), rng.uniform(-3, 3)])
    # hypotheses spread across the footprint edge (inside, on, outside)
    target_xy = rng.uniform(-320, 320, (n_t, H, 2))
    x = rng.uniform(-0.9, 0.9, 2 * H)
    return x, state, P0, target_xy


@pytest.mark.parametrize("name", list(VARIANTS))
def test_value_equals_numpy_kernel_and_dense_reference(name):
    rng = np.random.default_rng(hash(name) % 2**32)
    sensor = VARIANTS[name]
    x, state, P0, txy = _case(rng)
    xs = np.vstack([x, rng.uniform(-1, 1, (5, x.size))])
    ours = fused.cost(xs, state, UAV, P0, txy, MODEL.dt, MODEL.Q, sensor)
    H = x.size // 2
    controls = (xs * np.tile(UAV.control_scale, H)).reshape(len(xs), H, 2)
    states = kinematics.rollout(state, controls, UAV)
    ref = objective(P0, states[..., :2], txy, MODEL.dt, MODEL.Q, sensor)
    np.testing.assert_allclose(ours, ref, rtol=1e-12, atol=0)
    assert ours[0] == pytest.approx(dense_reference(x, state, P0, txy, sensor), rel=1e-10)
    uav_xy = rng.uniform(-300, 300, (3, H, 2))
    np.testing.assert_allclose(
        fused.covariance_traces(P0, uav_xy, txy, MODEL.dt, MODEL.Q, sensor),
        covariance_traces(P0, uav_xy, txy, MODEL.dt, MODEL.Q, sensor),
        rtol=1e-12,
    )
    # the variant changes the cost (the comparison is not vacuous)
    assert not np.allclose(ours, fused.cost(xs, state, UAV, P0, txy, MODEL.dt, MODEL.Q, BASE))


@pytest.mark.parametrize("name", list(VARIANTS))
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_gradient_equals_complex_step(name, seed):
    rng = np.random.default_rng(100 * seed + len(name))
    sensor = VARIANTS[name]
    x, state, P0, txy = _case(rng)
    _, grad = fused.cost_and_grad(x, state, UAV, P0, txy, MODEL.dt, MODEL.Q, sensor)
    ref = np.empty(x.size)
    for k in range(x.size):
        xc = x.astype(complex)
        xc[k] += 1e-30j
        ref[k] = dense_reference(xc, state, P0, txy, sensor).imag / 1e-30
    np.testing.assert_allclose(grad[0], ref, rtol=1e-7, atol=1e-9 * np.abs(ref).max())


def test_detection_probability_limits():
    s = VARIANTS["footprint"]
    uav = np.zeros(2)
    assert detection_probability(uav, np.array([0.0, 0.0]), s) == pytest.approx(
        1 / (1 + math.exp(-250 / 40))
    )
    assert detection_probability(uav, np.array([250.0, 0.0]), s) == pytest.approx(0.5)
    assert detection_probability(uav, np.array([1e6, 0.0]), s) == 0.0  # no overflow warning
    assert detection_probability(uav, np.array([1e6, 0.0]), BASE) == 1.0
    assert detected(uav, np.array([249.0, 0.0]), s, 0.99)  # hard: inside the radius
    assert not detected(uav, np.array([251.0, 0.0]), s, 0.0)
    logistic = dataclasses.replace(s, detection="logistic")
    assert detected(uav, np.array([251.0, 0.0]), logistic, 0.3)  # u < p_d ~ 0.49
    assert not detected(uav, np.array([251.0, 0.0]), logistic, 0.6)


def test_far_outside_the_footprint_is_prediction_only_filterpy():
    """p_d = 0 (target far outside a sharp footprint): the kernel's covariances are
    filterpy's predict-only recursion."""
    sensor = dataclasses.replace(BASE, footprint_radius=50.0, footprint_width=1.0)
    rng = np.random.default_rng(5)
    A = rng.standard_normal((4, 4))
    P0 = np.diag([400.0, 400.0, 9.0, 9.0]) + A @ A.T
    H = 6
    txy = np.full((1, H, 2), 5000.0)
    uav_xy = np.zeros((1, H, 2))
    traces = fused.covariance_traces(P0, uav_xy, txy, MODEL.dt, MODEL.Q, sensor)[0, 0]
    kf = KalmanFilter(dim_x=4, dim_z=2)
    kf.F, kf.Q, kf.P = MODEL.F, MODEL.Q, P0.copy()
    expected = []
    for _ in range(H):
        kf.predict()
        expected.append(np.trace(kf.P))
    np.testing.assert_allclose(traces, expected, rtol=1e-12)
    # and inside the footprint (p_d ~ 1) it is a full Kalman update, as without a footprint
    txy_in = np.zeros((1, H, 2)) + 1.0
    np.testing.assert_allclose(
        fused.covariance_traces(P0, uav_xy, txy_in, MODEL.dt, MODEL.Q, sensor),
        fused.covariance_traces(P0, uav_xy, txy_in, MODEL.dt, MODEL.Q, BASE),
        rtol=1e-12,
    )


def _short_cfg(**sensor):
    cfg = copy.deepcopy(yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["uav"])
    cfg["scenario"]["steps"] = 8
    cfg["planner"].update(horizon=4, maxiter=5, maxfun=10)
    cfg["methods"] = {"nbo": True, "rsmhp_nt": [10], "tree": []}
    cfg["sensor"].update(sensor)
    return cfg


def test_a_footprint_that_never_binds_reproduces_the_paper_model_bit_for_bit():
    """Radius 1e9 m: p_d = 1 exactly and every truth step measures, so the variant code path
    (expected update, detection draws, extra adjoint terms) gives the paper model's numbers
    bit for bit; only the variant's extra columns are added."""
    base = UAVSetup.from_config(_short_cfg())
    wide = UAVSetup.from_config(_short_cfg(footprint_radius=1e9))
    assert not base.sensor.limited and wide.sensor.limited
    for name, spec in uav_methods.from_config(_short_cfg()["methods"]).items():
        s0, r0 = simulate_run(base, spec, 3, 1)
        s1, r1 = simulate_run(wide, spec, 3, 1)
        assert s1.pop("detect_rate") == 1.0
        s0.pop("plan_seconds"), s1.pop("plan_seconds")
        assert s0 == s1, name
        assert all(r.pop("detected") for r in r1)
        assert r0 == r1, name


def test_missed_detections_in_the_truth_simulation():
    """A footprint smaller than any distance the UAV reaches: no step measures, and the
    tracker's covariance is filterpy's predict-only recursion from P0."""
    cfg = _short_cfg(footprint_radius=1.0, footprint_width=0.5)
    setup = UAVSetup.from_config(cfg)
    spec = uav_methods.from_config(cfg["methods"])["nbo"]
    summary, rows = simulate_run(setup, spec, 3, 2)
    assert summary["detect_rate"] == 0.0 and not any(r["detected"] for r in rows)
    kf = KalmanFilter(dim_x=4, dim_z=2)
    kf.F, kf.Q, kf.P = setup.target.F, setup.target.Q, setup.P0.copy()
    for row in rows:
        kf.predict()
        assert row["trace"] == pytest.approx(np.trace(kf.P), rel=1e-12)


def test_sensor_model_refuses_bad_values():
    with pytest.raises(ValueError, match="noise_growth"):
        dataclasses.replace(BASE, noise_growth="cubic")
    with pytest.raises(ValueError, match="footprint_radius"):
        dataclasses.replace(BASE, footprint_radius=-1.0)
    with pytest.raises(ValueError, match="footprint_width"):
        dataclasses.replace(BASE, footprint_width=0.0)
    with pytest.raises(ValueError, match="detection"):
        dataclasses.replace(BASE, detection="soft")


def test_recording_draws_the_footprint(tmp_path):
    from rerun.chunk import RrdReader

    from rsmhp.models.uav.recording import record_uav_run

    cfg = _short_cfg(footprint_radius=150.0)
    setup = UAVSetup.from_config(cfg)
    specs = list(uav_methods.from_config(cfg["methods"]).values())
    rows, summaries = record_uav_run(tmp_path / "fp.rrd", setup, specs, 3, 0, max_hypotheses=3)
    for spec in specs:
        assert rows[f"{spec.name}/map/footprint"] == setup.steps
    counts: dict[str, int] = {}
    for chunk in RrdReader(tmp_path / "fp.rrd").store().stream():
        counts[chunk.entity_path] = counts.get(chunk.entity_path, 0) + chunk.num_rows
    assert counts["/nbo/map/footprint"] == setup.steps
    # the recorded runs are the study's runs
    s, _ = simulate_run(setup, specs[0], 3, 0)
    assert summaries[0]["mean_error"] == s["mean_error"]
    # no footprint, no footprint entity
    rows, _ = record_uav_run(
        tmp_path / "plain.rrd", UAVSetup.from_config(_short_cfg()), specs, 3, 0
    )
    assert not any(k.endswith("/footprint") for k in rows)
