"""UAV target-tracking case study (paper Sec. III-B), one module per concept.

* :mod:`~rsmhp.models.uav.kinematics` - the UAV (bank-to-turn, speed-clipped) and its control box
* :mod:`~rsmhp.models.uav.target` - near-constant-velocity target, nominal and sampled hypotheses
* :mod:`~rsmhp.models.uav.sensor` - range/bearing-shaped position-measurement covariance R
* :mod:`~rsmhp.models.uav.tracker` - the simulation's Kalman filter (filterpy)
* :mod:`~rsmhp.models.uav.kernel` - the planner's batched covariance recursion (the objective)
* :mod:`~rsmhp.models.uav.planner` - receding-horizon optimisation (L-BFGS-B, batched gradient)
* :mod:`~rsmhp.models.uav.simulation` - one closed-loop Monte-Carlo run
* :mod:`~rsmhp.models.uav.recording` - rerun recordings of runs, every method side by side
"""
