"""The uav study."""
