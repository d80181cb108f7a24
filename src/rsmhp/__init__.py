"""rsmhp: Monte-Carlo cost approximation (RS-MHP) versus nominal belief-state optimization (NBO).

Reference implementation and replication pipeline for Ragi & Mittelmann, "Random-Sampling
Monte-Carlo Tree Search Methods for Cost Approximation in Long-Horizon Optimal Control",
IEEE Control Systems Letters 5(5), 2021.

Sub-modules
-----------
Core (model-independent)
  seeding           stable, order-independent random streams (SeedSequence keyed on job ids)
  sampling          tree / pruned-tree / non-overlapping trajectory sampling with likeliness
  designs           fixed-budget noise designs: MC, antithetic, Sobol', cubature, Gauss-Hermite
  cost_estimators   uniform and likeliness-weighted averages, NBO
  boxqn             compiled projected L-BFGS over [-1, 1]^n (scipy's budgets and tolerances)
  linear_quadratic  linear-Gaussian systems with quadratic cost and their exact oracles
  stats             confidence intervals (mean, RMSE, binomial; cluster-t and bootstrap-t
                    over few clusters), log-log slope fits, Holm's correction, t-test power
  guards            argument checks of the public entry points (ValueError / TypeError naming
                    the argument, the value and what is allowed)
Models
  lqg               the scalar "oven" LQG case study and all its closed forms
  lqg_horizon       the oven LQG at long horizons: limits in H, the horizon at which the
                    optimal first control stops depending on H (closed forms)
  uav               UAV target tracking: kinematics, target, sensor, tracker (filterpy, the
                    reference), stepper (compiled closed-loop step: aircraft, target,
                    tracker), kernel (numpy oracle), fused (compiled weighted cost + exact
                    gradient, vectorised over hypotheses; the compiled planning step),
                    planner (Planner and Optimiser protocols: boxqn, scipy's L-BFGS-B),
                    methods (registry of planning methods, one module per family),
                    dpw (compiled tree search with double progressive widening),
                    simulation, recording
Stages of the pipeline (one module per model and stage)
  experiments       lqg, estimators, uav, decisions_lqg, decisions_uav, frontier, horizon,
                    horizon_lqg, optimiser_split: config -> tidy tables
  analysis          lqg, estimators, uav, decisions_lqg, decisions_uav, frontier, horizon,
                    horizon_lqg, optimiser_split: tables -> statistics; scenarios: every
                    method's probability of beating NBO across map cells and horizons
  protocol          the comparison protocol: seed streams (exploratory, tune, confirm,
                    confirm2), planner configurations, the tuning rule, the preregistration
  figures           lqg, estimators, uav, decisions, frontier, horizon, optimiser_split,
                    scenarios: seaborn figures (PNG + PDF)
  recording         rerun recordings of sampled trajectory trees
  claims            per study: the claims (key number + verdict rule) from the statistics;
                    claims.paper: the paper's statements, each with its evidence and verdict
  narrative         per study: the report section's prose, tables and appendix (Markdown)
  ledger            the claims data model: KeyNumber, Claim, Section
  verdicts          verdict rules as objects (Rule, Case, at_most, ci_side, non_inferior):
                    text + evaluation
  markdown          number formatting and Markdown tables
  provenance        commit, config hash, package versions, BLAS and CPU of a run
  report            renders the main text, appendix, claims and glance table from the sections
  readme            splices the glance table into README.md (``make publish``)
  verify            a run's claims against the committed reference (``make verify``)
  portability       the portability drill: a run on an emulated other machine against the
                    native run and the reference (``make portability``)
  palette           one colour and label per method, for every figure and recording
Workflow support
  config            config files and schema checks (``python -m rsmhp.pipeline.config FILE``)
  resources         memory estimate of each simulation rule from the config
  contracts         what each intermediate file must hold, checked before aggregation
  io                atomic, umask-honouring writers and checked readers
  parallel          joblib fan-out that honours a thread budget without oversubscribing BLAS
  pipeline          logging of rule scripts
  code_digest       content digest of the package code each rule imports (reruns never stale)
  cluster           SLURM pre-flight: every job fits a node of its partition (sinfo)
  numba_cache       drops numba's cache of a module when a module it inlines changed
"""

__version__ = "0.1.0"
