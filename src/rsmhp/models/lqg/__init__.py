"""The LQG case study's model: the scalar oven and its closed forms (``oven``), general
linear-quadratic problems (``linear_quadratic``), long-horizon limits (``horizon``), the
estimator ablation shared by the estimator and long-horizon studies (``ablation``), the
open-loop regret experiment and its summaries (``regret``, ``regret_summary``) and tree
recordings (``recording``)."""
