"""rsmhp: Monte-Carlo cost approximation (RS-MHP) versus nominal belief-state optimization (NBO).

Reference implementation and replication pipeline for Ragi & Mittelmann, "Random-Sampling
Monte-Carlo Tree Search Methods for Cost Approximation in Long-Horizon Optimal Control",
IEEE Control Systems Letters 5(5), 2021.

Sub-modules
-----------
seeding     stable, order-independent random streams (numpy SeedSequence keyed on job ids)
sampling    tree / pruned-tree / non-overlapping trajectory sampling with likeliness
estimators  uniform and likeliness-weighted averages, NBO
lqg         the scalar "oven" LQG case study and all its closed forms
parallel    joblib fan-out that honours a thread budget without oversubscribing BLAS
guards      argument checks of the public entry points (ValueError / TypeError naming the
            argument, the value and what is allowed)
"""

__version__ = "0.1.0"
