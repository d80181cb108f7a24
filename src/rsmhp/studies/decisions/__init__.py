"""The decisions study."""
