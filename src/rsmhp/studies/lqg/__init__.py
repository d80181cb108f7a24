"""The lqg study."""
