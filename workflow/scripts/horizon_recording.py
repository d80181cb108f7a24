"""Rule horizon_recording: one closed-loop run at a long horizon, one member per family, every
planning step with the hypotheses' predicted tracks and the plan (rerun recording)."""

from rsmhp.contracts import read_checked
from rsmhp.experiments.horizon import closed_contract, horizon_setup, recording_members
from rsmhp.pipeline import rule_logging
from rsmhp.uav.recording import record_checked_run

with rule_logging(snakemake) as log:
    p = snakemake.params
    rec, cfg = p.recording, p.cfg
    model, H, run = rec["model"], int(rec["H"]), int(rec["run"])
    spec = next(m for m in p.models if m["name"] == model)
    setup = horizon_setup(p.uav, spec, H)
    methods = recording_members(cfg)
    closed = read_checked(snakemake.input.closed, closed_contract(cfg, model, H))
    note = (
        f"Run {run} of model '{model}' planned at horizon H = {H} (horizon.uav.recording; "
        "fixed in the config, not chosen by outcome): one member per family, each step with "
        f"up to {int(rec['max_hypotheses'])} of the hypotheses the planner averaged over "
        "(their predicted target tracks) and the planned UAV path. The tree search plans over "
        "simulated beliefs and has no hypotheses to show."
    )
    record_checked_run(
        snakemake.output[0],
        setup,
        methods,
        closed,
        seed=p.seed,
        run=run,
        max_hypotheses=int(rec["max_hypotheses"]),
        note=note,
        log=log,
    )
