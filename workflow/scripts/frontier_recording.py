"""Rule frontier_recording: one closed-loop run of a frontier model variant, NBO and
every family's budget member side by side, in the run chosen by frontier.recording.select
from the frontier's paired differences (Monte-Carlo budget member − NBO)."""

from rsmhp.models.uav.methods import baseline
from rsmhp.models.uav.methods.monte_carlo import MonteCarlo
from rsmhp.models.uav.recording import record_checked_run
from rsmhp.pipeline.contracts import read_checked
from rsmhp.pipeline.script import rule_logging
from rsmhp.studies.frontier.claims import budget_member
from rsmhp.studies.frontier.simulate import frontier_contracts, recording_setup
from rsmhp.studies.frontier.summarise import select_run

with rule_logging(snakemake) as log:
    p = snakemake.params
    rec, cfg = p.recording, p.cfg
    model = rec["model"]
    setup, methods = recording_setup(p.uav, p.models, cfg, model)
    runs = read_checked(snakemake.input.runs, frontier_contracts(cfg, model)[0])
    base = baseline()().name
    compare = budget_member(cfg["budget"]["members"], MonteCarlo) or methods[-1].name
    run, d = select_run(runs, model, compare, base, rec["select"])
    log.info("%s: run %d (%s of %s − %s: d = %+.3f m)", model, run, rec["select"], compare, base, d)
    note = (
        f"Run {run} of model '{model}', chosen by frontier.recording.select = "
        f"{rec['select']} on d_r = mean location error of {compare} − {base} over the "
        f"frontier's runs (this run: d = {d:+.3f} m)."
    )
    record_checked_run(
        snakemake.output[0],
        setup,
        methods,
        runs,
        seed=p.seed,
        run=run,
        max_hypotheses=int(rec["max_hypotheses"]),
        note=note,
        log=log,
    )
