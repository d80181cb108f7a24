"""The run store in the workflow (tiny config): every rule that simulates closed-loop runs
goes through it and logs its counts, each distinct run is simulated once, and the runs that
rules share are read, as many as the keys of the runs each rule asks for predict.

Oracle: the keys (rsmhp.models.uav.runs.closed_loop_key) of every run each rule asks for,
computed here from the config without simulating anything."""

from __future__ import annotations

import re
from collections import Counter
from pathlib import Path

import pytest
import yaml

from rsmhp.models.uav import methods
from rsmhp.models.uav.runs import closed_loop_key
from rsmhp.models.uav.scoring import map_cells, merge_variant, variant
from rsmhp.models.uav.simulation import UAVSetup
from rsmhp.pipeline.config import merge
from rsmhp.pipeline.protocol import Configuration, confirm_plan, stream_seed
from rsmhp.pipeline.runstore import key_digest
from rsmhp.studies.horizon.simulate_uav import horizon_setup
from tests.pipeline.test_workflow import TINY

pytestmark = pytest.mark.workflow

ROOT = Path(__file__).resolve().parents[2]
RULES = ("uav_simulate", "decisions_map_cell", "horizon_uav_closed", "frontier_explore",
         "frontier_confirm")  # fmt: skip
LINE = re.compile(r"run store: (\d+) computed, (\d+) reused, (\d+) waited \(results/store\)")


def requested(cfg: dict) -> dict[str, list[str]]:
    """Per rule, the key digest of every closed-loop run it asks for."""
    seed, uav = cfg["seed"], cfg["uav"]
    models = cfg["uav_models"]
    out: dict[str, list[str]] = {r: [] for r in RULES}

    def add(rule, setup, method, s, r):
        out[rule].append(key_digest(closed_loop_key(setup, method, s, r)))

    setup = UAVSetup.from_config(uav)
    for m in methods.from_config(uav["methods"]).values():
        for r in range(uav["runs"]):
            add("uav_simulate", setup, m, seed, r)
    mp = cfg["decisions"]["map"]
    for cell in map_cells(mp):
        s = UAVSetup.from_config(merge_variant(uav, cell.variant))
        for m in methods.from_config(mp["methods"]).values():
            for r in range(mp["runs"]):
                add("decisions_map_cell", s, m, seed, r)
    hz = cfg["horizon"]["uav"]
    hz_seed = stream_seed(seed, cfg["horizon"]["stream"])
    for model in hz["models"]:
        for H in hz["H"]:
            s = horizon_setup(uav, variant(models, model), H)
            for m in methods.from_config(hz["methods"]).values():
                for r in range(hz["closed_runs"]):
                    add("horizon_uav_closed", s, m, hz_seed, r)
    fr = cfg["frontier"]
    if fr["exploratory"]:
        for model in fr["models"]:
            s = UAVSetup.from_config(merge_variant(uav, variant(models, model)))
            for m in methods.from_config(fr["methods"]).values():
                for r in range(fr["runs"]):
                    add("frontier_explore", s, m, seed, r)
    conf = confirm_plan(ROOT, fr)
    for model in conf["models"] if conf else []:
        base = UAVSetup.from_config(merge_variant(uav, variant(models, model)))
        for spec in conf["plans"][model]:
            c = Configuration.from_spec(spec)
            for r in range(int(conf["runs"][model])):
                add(
                    "frontier_confirm",
                    c.setup(base),
                    c.method,
                    stream_seed(seed, conf["stream"]),
                    r,
                )
    return out


def test_rules_share_their_runs_through_the_store(run_j2):
    # the session's whole tiny workflow (-j2, from an empty results/): no run of its own
    tmp_path = run_j2
    cfg = merge(yaml.safe_load((ROOT / "config/config.yaml").read_text()),
                yaml.safe_load(TINY.read_text()))  # fmt: skip
    want = requested(cfg)
    every = [d for digests in want.values() for d in digests]
    shared = sum(n - 1 for n in Counter(every).values())
    assert shared > 0  # the tiny config has runs that two rules need
    counts = {r: [0, 0, 0] for r in RULES}
    for rule in RULES:
        logs = sorted((tmp_path / "results/logs" / rule).glob("*.log"))
        assert logs, rule
        for log in logs:
            lines = LINE.findall(log.read_text())
            assert len(lines) == 1, (log, lines)  # one line per job
            counts[rule] = [a + int(b) for a, b in zip(counts[rule], lines[0], strict=True)]
        computed, reused, waited = counts[rule]
        assert computed + reused + waited == len(set(want[rule])), rule
    total = [sum(c[i] for c in counts.values()) for i in range(3)]
    entries = list((tmp_path / "results/store").rglob("*.run"))
    assert total[0] == len(set(every)) == len(entries)  # each distinct run simulated once
    assert total[1] + total[2] == shared  # and read by every other rule that needs it
    assert not list((tmp_path / "results/store").rglob("*.lock"))
    assert {p.stem for p in entries} == set(every)
