"""A template rsmhp method plugin: one planning-method family, RS-MHP with
Latin-hypercube-stratified hypotheses (:mod:`rsmhp_plugin_example.stratified`, family ``lhs``,
config key ``lhs_nt``).

rsmhp imports :mod:`rsmhp_plugin_example.stratified` through this distribution's entry point
(group ``rsmhp.methods``) when it builds its method registry; this package itself imports
nothing, so importing it never loads the registry twice.
"""

__version__ = "0.1.0"
