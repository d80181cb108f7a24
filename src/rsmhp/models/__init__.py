"""The two case studies' models: the LQG (``lqg``) and UAV target tracking (``uav``)."""
