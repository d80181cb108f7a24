"""The confirmatory run split in jobs of runs (config ``split.frontier_confirm``).

Rule ``frontier_confirm`` runs one chunk of the closed-loop runs of one model
(:func:`confirm_runs`: contiguous runs, every preregistered configuration) with
:func:`rsmhp.studies.frontier.simulate.run_configurations`, whose runs are keyed on the
configuration, the confirm stream and the run index, never on the chunk. Rule
``frontier_confirm_merge`` puts the chunks back together (:func:`merge_confirm`): the table
``results/frontier/confirm/<model>.csv`` the unsplit job wrote, row for row in its order
(configuration-major, runs ascending).
"""

from __future__ import annotations

from collections.abc import Sequence

import pandas as pd

from rsmhp.pipeline.protocol import Configuration
from rsmhp.pipeline.split import merge_run_chunks, n_chunks, run_chunk
from rsmhp.studies.frontier.simulate import config_runs_contract

__all__ = ["RULE", "confirm_chunks", "confirm_runs", "merge_confirm"]

#: the rule that simulates the chunks (and names the merged table's contract)
RULE = "frontier_confirm"


def confirm_chunks(n_runs: int, jobs: int) -> list[int]:
    """The chunk indices of a model with ``n_runs`` runs split in ``jobs`` jobs."""
    return list(range(n_chunks(n_runs, jobs)))


def confirm_runs(n_runs: int, jobs: int, k: int) -> list[int]:
    """The run indices of chunk ``k`` of runs ``0..n_runs-1`` split in ``jobs`` jobs."""
    return run_chunk(n_runs, jobs, k)


def merge_confirm(
    paths: Sequence[str],
    configs: Sequence[Configuration],
    n_runs: int,
    jobs: int,
    model: str,
) -> pd.DataFrame:
    """The confirmatory table of ``model`` from its chunk files ``paths`` (chunk 0, 1, ...):
    each checked against the rows its runs must hold, merged in the unsplit order
    (configuration as in ``configs``, then run) and checked as a whole."""
    whole = config_runs_contract(RULE, configs, range(int(n_runs)), model)
    return merge_run_chunks(
        paths,
        whole,
        n_runs,
        jobs,
        keys=("config", "run"),
        orders={"config": [c.name for c in configs]},
        what=f"results/frontier/confirm/{model}.csv (the chunks together)",
        caller="merge_confirm",
    )
