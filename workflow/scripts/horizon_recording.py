"""Rule horizon_recording: one closed-loop run at a long horizon, one member per family, every
planning step with the hypotheses' predicted tracks and the plan (rerun recording); the run is
chosen by horizon.uav.recording.select from the closed-loop runs' paired differences
(claims.monte_carlo − NBO) at that horizon."""

from rsmhp.models.uav.methods import baseline
from rsmhp.models.uav.recording import record_checked_run
from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.summarise import select_run
from rsmhp.studies.horizon.simulate_uav import closed_contract, horizon_setup, recording_members

with rule_logging(snakemake) as log:
    p = snakemake.params
    rec, cfg = p.recording, p.cfg
    model, H = rec["model"], int(rec["H"])
    spec = next(m for m in p.models if m["name"] == model)
    setup = horizon_setup(p.uav, spec, H)
    methods = recording_members(cfg)
    closed = read_checked(snakemake.input.closed, closed_contract(cfg, model, H))
    base, mc = baseline()().name, cfg["claims"]["monte_carlo"]
    run, d = select_run(closed, model, mc, base, rec["select"], "horizon.uav.recording.select")
    log.info("%s, H = %d: run %d (%s of %s − %s: d = %+.3f m)", model, H, run, rec["select"],
             mc, base, d)  # fmt: skip
    note = (
        f"Run {run} of model '{model}' planned at horizon H = {H}, chosen by "
        f"horizon.uav.recording.select = {rec['select']} on d_r = mean location error of {mc} "
        f"− {base} over the study's closed-loop runs at this H (this run: d = {d:+.3f} m). One "
        f"member per family; each step shows up to {int(rec['max_hypotheses'])} of the "
        "hypotheses the planner averaged over (their predicted target tracks) and the planned "
        "UAV path. The tree search plans over simulated beliefs and has no hypotheses to show."
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
