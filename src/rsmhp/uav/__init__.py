"""UAV target-tracking case study (paper Sec. III-B), one module per concept.

* :mod:`~rsmhp.uav.kinematics` - the UAV (bank-to-turn, speed-clipped) and its control box
* :mod:`~rsmhp.uav.target` - near-constant-velocity target, nominal and sampled hypotheses
* :mod:`~rsmhp.uav.sensor` - range/bearing-shaped position-measurement covariance R
* :mod:`~rsmhp.uav.tracker` - the simulation's Kalman filter (filterpy)
* :mod:`~rsmhp.uav.kernel` - the planner's batched covariance recursion (the objective)
* :mod:`~rsmhp.uav.planner` - receding-horizon optimisation (L-BFGS-B, batched gradient)
* :mod:`~rsmhp.uav.simulation` - one closed-loop Monte-Carlo run
* :mod:`~rsmhp.uav.recording` - rerun recordings of runs, every method side by side
"""
