"""rsmhp: Monte-Carlo cost approximation (RS-MHP) versus nominal belief-state optimization (NBO).

Reference implementation and replication pipeline for Ragi & Mittelmann, "Random-Sampling
Monte-Carlo Tree Search Methods for Cost Approximation in Long-Horizon Optimal Control",
IEEE Control Systems Letters 5(5), 2021.

The package is layered: ``core`` below ``models``, ``pipeline`` and ``report`` beside them, and
one package per study on top. A study builds on the layers below and never on another study;
inside a study, ``simulate`` never imports its ``claims``, ``section`` or ``figures``
(tests/pipeline/test_layout.py checks both on the import graph).

Sub-packages
------------
  core              model-independent: seeding (stable, order-independent random streams),
                    sampling (tree / pruned-tree / non-overlapping trajectories, likeliness),
                    designs (fixed-budget noise designs: MC, antithetic, Sobol', cubature,
                    Gauss-Hermite), cost_estimators (uniform and likeliness-weighted averages,
                    NBO), boxqn (compiled projected L-BFGS over [-1, 1]^n), stats (intervals,
                    paired differences, slopes, Holm, t-test power, probability of
                    improvement), guards (argument checks), numba_cache (drops a compiled
                    module's cache when a module it inlines changed), clock (a cycle counter
                    compiled code can read)
  models            the case studies' models. models.lqg: oven (the scalar oven LQG and its
                    closed forms), linear_quadratic (linear-Gaussian problems with quadratic
                    cost and their exact oracles), ablation (the estimator ablation and its
                    per-cell summary), regret and regret_summary (open-loop regret),
                    recording (rerun trees).
                    models.uav: kinematics, target, sensor, tracker (filterpy, the reference),
                    stepper (compiled closed-loop step), kernel (numpy oracle), fused (compiled
                    weighted cost + exact gradient), planner (Planner and Optimiser
                    protocols), methods (registry, one module per planning family), dpw
                    (compiled tree search), simulation, loop (the compiled closed loop and
                    which families take it), runs (closed-loop runs through the
                    run store: their key, shared by the studies), scoring (open-loop scoring
                    of belief states, shared by the studies), recording
  pipeline          workflow support: config (config files and schema checks, the shared
                    sections' and, found by package, every study's, ``python -m
                    rsmhp.pipeline.config FILE``), config_layout (keys that moved, the view
                    of a config its hash is taken of), contracts (what each intermediate holds),
                    io (atomic writers, checked readers), code_digest (the code each rule
                    depends on, per method family where a rule runs some), runstore (the
                    content-addressed store of computed runs, shared by the rules), parallel
                    (joblib within a thread budget), resources (memory estimates), cluster (SLURM
                    pre-flight), protocol (seed streams, planner configurations, tuning rule,
                    preregistration), power_design (a preregistration's power, recomputed
                    under each claim's rule), split (jobs split into chunks and merged
                    again), script (logging and code checks of rule scripts), warm
                    (compiles every numba kernel once per machine, ``python -m
                    rsmhp.pipeline.warm``)
  report            ledger (KeyNumber, Claim, Section), verdicts (verdict rules as objects),
                    statements (the paper's statements judged on its setups and on variants),
                    findings (the main claims, "What we found"), power (runs at 80% power),
                    naming (a tree search named by its measured plan depth), disclosures
                    (choices made after their data, beside the verdicts they touch),
                    history (earlier verdicts, fragility), render (main text, appendix,
                    glance table), html (the HTML report's landing page), templates (Jinja2;
                    Words, a study's claim sentences as macros), claimspec (a claim as
                    data: id, setup, rule, evidence function, words),
                    markdown (number formatting, tables), palette (one colour and label per
                    method), figures (theme, save_figure), provenance, readme (``make
                    publish``), verify (``make verify``), portability (``make portability``)
  studies           one package per study, each with simulate (config -> tidy tables),
                    summarise (tables -> statistics), claims (key numbers and verdicts),
                    figures, section (the report section, prose in Markdown templates),
                    checks (its config checks and memory estimates; the pipeline asks every
                    study's):
                    lqg (Fig. 3), estimators (the estimator ablation), uav (Figs. 4-5),
                    decisions (LQG and UAV regret, the sensitivity map), frontier (equal
                    compute: exploratory frontier, tuning, confirmatory run, the published
                    reference and the comparison of new planners with it), horizon (long
                    horizons, LQG and UAV, and the optimiser split; closed_forms, the oven
                    LQG's long-horizon limits), scenarios (the best
                    method per cell and the probability of beating NBO across scenarios)
  testing           check_method: the conformance check of a planning-method family (run it
                    first on a new one, in this repository or a plugin package)
"""

__version__ = "0.1.0"
