"""rsmhp: Monte-Carlo cost approximation (RS-MHP) versus nominal belief-state optimization (NBO).

Reference implementation and replication pipeline for Ragi & Mittelmann, "Random-Sampling
Monte-Carlo Tree Search Methods for Cost Approximation in Long-Horizon Optimal Control",
IEEE Control Systems Letters 5(5), 2021.

Sub-modules
-----------
Core (model-independent)
  seeding           stable, order-independent random streams (SeedSequence keyed on job ids)
  sampling          tree / pruned-tree / non-overlapping trajectory sampling with likeliness
  samplers          fixed-budget noise samplers: MC, antithetic, Sobol', cubature, Gauss-Hermite
  estimators        uniform and likeliness-weighted averages, NBO
  linear_quadratic  linear-Gaussian systems with quadratic cost and their exact oracles
  stats             confidence intervals (mean, RMSE, binomial) and log-log slope fits
  guards            argument checks of the public entry points (ValueError / TypeError naming
                    the argument, the value and what is allowed)
Models
  lqg               the scalar "oven" LQG case study and all its closed forms
  uav               UAV target tracking: kinematics, target, sensor, tracker (filterpy),
                    kernel (numpy oracle), fused (compiled cost + exact gradient), planner,
                    simulation, recording
Stages of the pipeline (one module per model and stage)
  experiments       lqg, estimators, uav, decisions_lqg, decisions_uav: config -> tidy tables
  analysis          lqg, estimators, uav, decisions: tables -> summaries, claims, sections
  figures           lqg, estimators, uav, decisions: seaborn figures (PNG + PDF)
  recording         rerun recordings of sampled trajectory trees
  report            claims (key number, CI, verdict rule), the ledger, main text and appendix
  verify            a run's claims against the committed reference (``make verify``)
  palette           one colour and label per method, for every figure and recording
Workflow support
  config            config files and schema checks (``python -m rsmhp.config FILE``)
  resources         memory estimate of each simulation rule from the config
  contracts         what each intermediate file must hold, checked before aggregation
  io                atomic, umask-honouring writers and checked readers
  parallel          joblib fan-out that honours a thread budget without oversubscribing BLAS
  pipeline          logging of rule scripts
"""

__version__ = "0.1.0"
