"""The scenarios study."""
