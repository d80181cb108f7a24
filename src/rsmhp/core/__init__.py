"""Model-independent core: random streams, samplers, noise designs, cost estimators, the
compiled box-constrained optimiser, statistics and argument checks. Imports nothing else of
rsmhp."""
