"""Experiment drivers: each turns a validated config section into a tidy pandas table.

Every row is computed from its own random stream (:func:`rsmhp.seeding.job_rng`) keyed on the
row's identifying parameters, so tables are identical for any worker count or chunking.
"""
