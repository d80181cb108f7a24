"""The frontier study."""
